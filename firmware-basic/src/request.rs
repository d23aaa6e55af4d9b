//! Who asked for a request to the Atom, and so where its reply goes: the host links' ids
//! ([`LinkId`]), one client on one link (`Client`), a request with its origin (`Request`,
//! `Origin`) and what became of a reply for a client (`Delivery`).
//!
//! These are the words the router (which hands out requests and delivers replies) and the
//! forwarder (which carries one request at a time over the bus) share; neither depends on the
//! other.

use protocol_core::Frame;
use protocol_core::dialect::Answer;

/// Most host links open at once, the USB link included: the USB serial and seven network
/// clients. An ESP32's network stack serves about ten sockets (one listens); every link costs
/// about 2.5 KiB of RAM (its listener, request queue and output queue: a `Basic` is 20 KiB).
pub const MAX_HOST_LINKS: usize = 8;

/// One of the Basic's host links: an index into its table of [`MAX_HOST_LINKS`] links.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash, PartialOrd, Ord)]
pub struct LinkId(u8);

impl LinkId {
    /// The USB serial: always open, [`LinkKind::Serial`](crate::host_link::LinkKind::Serial).
    pub const USB: Self = Self(0);

    /// The link at `index` in the table, if there is such a slot.
    pub const fn from_index(index: usize) -> Option<Self> {
        if index < MAX_HOST_LINKS {
            // Cannot truncate: index < MAX_HOST_LINKS <= 255.
            Some(Self(index as u8))
        } else {
            None
        }
    }

    /// The link's index in the table, below [`MAX_HOST_LINKS`].
    pub const fn index(self) -> usize {
        self.0 as usize
    }
}

/// Who asked for a request: one client on one link. A link's id is reused by later clients;
/// the session tells them apart.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub(crate) struct Client {
    pub(crate) link: LinkId,
    session: u16,
}

impl Client {
    /// The client of `session` on `link` (the router counts a link's sessions).
    pub(crate) const fn new(link: LinkId, session: u16) -> Self {
        Self { link, session }
    }

    /// Which client on its link this is.
    pub(crate) const fn session(self) -> u16 {
        self.session
    }
}

/// What became of a reply for a client.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub(crate) enum Delivery {
    /// Queued for the client.
    Queued,
    /// The client's output queue was full: dropped.
    NoRoom,
    /// The client has gone: dropped.
    Gone,
}

/// Who asked for a request, and so where its reply goes.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub(crate) enum Origin {
    /// A client on a host link: the reply goes to that client.
    Host(Client),
    /// The Basic's boot power-on (0x10): the reply is consumed.
    PowerOn,
    /// The Basic's liveness probe (0x12): the reply is consumed.
    Probe,
}

/// A request to the Atom.
#[derive(Clone, Debug, PartialEq, Eq)]
pub(crate) struct Request {
    pub(crate) frame: Frame,
    pub(crate) origin: Origin,
    /// What the client gets for the reply (its dialect's answer; the Basic's own requests:
    /// as it is).
    pub(crate) answer: Answer,
    /// When it arrived (or was made), in microseconds.
    pub(crate) queued_us: u64,
    /// Its reply may be passed on to the client as it arrives on the bus (cut-through): a
    /// client on a serial link, in pymycobot's dialect, getting the reply as it is.
    pub(crate) cut_through: bool,
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn ids_are_indexes_into_the_table() {
        assert_eq!(LinkId::from_index(3).map(LinkId::index), Some(3));
        assert_eq!(LinkId::from_index(MAX_HOST_LINKS), None);
    }

    #[test]
    fn a_client_is_its_link_and_its_session() {
        let first = Client::new(LinkId::USB, 0);
        assert_eq!(first.link, LinkId::USB);
        assert_eq!(first.session(), 0);
        assert_ne!(
            first,
            Client::new(LinkId::USB, 1),
            "a later client on the same link"
        );
    }
}
