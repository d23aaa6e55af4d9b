//! The host links of the Basic, and whose turn it is on the bus.
//!
//! The Basic serves several host links at once: the USB serial, and on a board with Wi-Fi one
//! link per TCP client. Each link is a slot with a [`LinkId`] and its own everything: a
//! listener with its own quiet-gap rule ([`LinkKind`]), its own queue of requests for the Atom
//! and its own output queue. A client's garbage, half frame or flood therefore stays its own:
//! it can delay only that client's requests.
//!
//! The bus carries one request at a time. The router hands the forwarder the next request
//! round robin: one request per link in turn, from the link after the one that went last, so
//! four busy clients get a quarter of the bus each whatever their pace. The request remembers
//! who asked (the link and which client on it: [`LinkId`]s are reused), and its reply goes to
//! that client only; a reply for a client that has gone is dropped, never given to the next
//! client on the same slot.
//!
//! How links come and go: the USB link ([`LinkId::USB`]) is always open. A transport that
//! accepts clients (the Basic's Wi-Fi server, the virtual robot's TCP server) opens a link per
//! client with `Basic::open_link` and closes it when the client leaves with
//! `Basic::close_link`. At most [`MAX_HOST_LINKS`] links are open; `open_link` refuses the
//! next with [`LinksFull`], and the transport then turns the client away (the TCP servers
//! close the connection at once, see `docs/protocol.md` section 16).
//!
//! The board's ports are lent to `Basic::poll` as one [`HostPorts`], which reaches each
//! link's port by its id. Any single [`BytePort`] is a [`HostPorts`] whose only link is the
//! USB one, so a board with one UART passes just that.

use heapless::{Deque, Vec};
use protocol_core::dialect::{Answer, Dialect};
use protocol_core::{BytePort, Frame};

use crate::host_link::{HostFrames, HostLink, LinkKind};
use crate::request::{Client, Delivery, LinkId, MAX_HOST_LINKS, Origin, Request};
use crate::wifi::{Captured, SetTextCapture, SetTextEnd};

/// Requests one link may have waiting for the bus. pymycobot sends one request at a time and
/// waits for its reply; 16 absorb a client that pipelines a burst (at 115200 a request arrives
/// every 0.43 ms, an exchange with the Atom takes about 0.5 ms, a reply 1.5 ms to leave), so
/// fifty pipelined `get_angles` are all answered. Staleness is bounded by the client's
/// deadline ([`LinkKind::client_deadline_us`]), not by the depth.
pub const LINK_QUEUE_DEPTH: usize = 16;

/// `Basic::open_link` found every link in use ([`MAX_HOST_LINKS`]); the client is turned away.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct LinksFull;

/// The ports of a board's host links, each reached by its [`LinkId`]: what `Basic::poll` reads
/// from and writes to. The USB UART, TCP sockets: whatever the transport has.
///
/// The same rules as for a [`BytePort`]: nothing blocks, and the Basic writes to a link only
/// when [`HostPorts::tx_idle_on`] says so, at most [`crate::host_link::HOST_WRITE_CHUNK`] bytes at
/// a time. A link the transport has no port for reads nothing and discards what is written.
pub trait HostPorts {
    /// Takes the next byte received on `link`, if one has arrived. Never blocks.
    fn read_from(&mut self, link: LinkId) -> Option<u8>;

    /// Queues `bytes` for transmission on `link`, in order.
    fn write_to(&mut self, link: LinkId, bytes: &[u8]);

    /// True once `link` can take another write without waiting.
    fn tx_idle_on(&self, link: LinkId) -> bool;
}

/// A single byte port is a board with one host link, the USB serial ([`LinkId::USB`]).
impl<P: BytePort> HostPorts for P {
    fn read_from(&mut self, link: LinkId) -> Option<u8> {
        if link == LinkId::USB {
            self.read_byte()
        } else {
            None
        }
    }

    fn write_to(&mut self, link: LinkId, bytes: &[u8]) {
        if link == LinkId::USB {
            self.write(bytes);
        }
    }

    fn tx_idle_on(&self, link: LinkId) -> bool {
        link != LinkId::USB || self.tx_idle()
    }
}

/// A request waiting for its turn on the bus.
#[derive(Debug)]
struct Waiting {
    frame: Frame,
    answer: Answer,
    /// When it arrived, in microseconds.
    arrived_us: u64,
}

/// One link's slot.
#[derive(Debug)]
struct Slot {
    /// Open (a client is there).
    open: bool,
    /// Which client on this slot; changes whenever the slot is opened or closed.
    session: u16,
    link: HostLink,
    waiting: Deque<Waiting, LINK_QUEUE_DEPTH>,
    /// The bare 0xB0 text this link's client sends after the announcing frame: its bytes go
    /// here instead of to the framer until the capture ends.
    capture: Option<SetTextCapture>,
}

impl Slot {
    const fn new(kind: LinkKind, open: bool) -> Self {
        Self {
            open,
            session: 0,
            link: HostLink::new(kind),
            waiting: Deque::new(),
            capture: None,
        }
    }

    /// Starts a new client of `kind` on this slot, with nothing heard, waiting or queued.
    fn restart(&mut self, kind: LinkKind, open: bool) {
        let session = self.session.wrapping_add(1);
        *self = Self::new(kind, open);
        self.session = session;
    }
}

/// The Basic's host links and the turn on the bus. See the [module doc](self).
#[derive(Debug)]
pub(crate) struct Router {
    slots: [Slot; MAX_HOST_LINKS],
    /// The index of the link whose request goes next, if it has one.
    turn: usize,
    /// The dialect every link is to speak (each adopts it between frames).
    dialect: Dialect,
}

impl Router {
    /// The USB link open, no other.
    pub(crate) fn new() -> Self {
        Self {
            slots: core::array::from_fn(|i| Slot::new(LinkKind::Serial, i == LinkId::USB.index())),
            turn: 0,
            dialect: Dialect::Pymycobot,
        }
    }

    /// Every link is to speak `dialect`: each adopts it once no frame of its is in progress
    /// ([`Self::adopt_dialect`]), at once if none is.
    pub(crate) fn set_dialect(&mut self, dialect: Dialect) {
        self.dialect = dialect;
        for slot in &mut self.slots {
            slot.link.adopt(dialect);
        }
    }

    /// `link` adopts the dialect every link is to speak, if it has no frame in progress.
    pub(crate) fn adopt_dialect(&mut self, link: LinkId) {
        let dialect = self.dialect;
        if let Some(host_link) = self.host_link(link) {
            host_link.adopt(dialect);
        }
    }

    /// The dialect `link`'s frames are read in now.
    pub(crate) fn link_dialect(&self, link: LinkId) -> Dialect {
        self.slots
            .get(link.index())
            .map_or(self.dialect, |slot| slot.link.dialect())
    }

    /// Opens a link for a new client of `kind`.
    pub(crate) fn open(&mut self, kind: LinkKind) -> Result<LinkId, LinksFull> {
        let (index, slot) = self
            .slots
            .iter_mut()
            .enumerate()
            .find(|(_, slot)| !slot.open)
            .ok_or(LinksFull)?;
        slot.restart(kind, true);
        slot.link.adopt(self.dialect);
        LinkId::from_index(index).ok_or(LinksFull)
    }

    /// Closes `link`: what its client sent and what was queued for it is forgotten, and a
    /// reply still coming for it will be dropped. The USB link stays open: it starts afresh.
    pub(crate) fn close(&mut self, link: LinkId) {
        if let Some(slot) = self.slots.get_mut(link.index()) {
            let kind = slot.link.kind();
            slot.restart(kind, link == LinkId::USB);
            slot.link.adopt(self.dialect);
        }
    }

    /// True if `link` is open (the tests' view; the Basic asks for [`Self::client`]).
    #[cfg(test)]
    pub(crate) fn is_open(&self, link: LinkId) -> bool {
        self.slots.get(link.index()).is_some_and(|s| s.open)
    }

    /// The open links, in id order.
    pub(crate) fn open_links(&self) -> Vec<LinkId, MAX_HOST_LINKS> {
        self.slots
            .iter()
            .enumerate()
            .filter(|(_, slot)| slot.open)
            .filter_map(|(index, _)| LinkId::from_index(index))
            .collect()
    }

    /// The client now on `link`, if it is open.
    pub(crate) fn client(&self, link: LinkId) -> Option<Client> {
        let slot = self.slots.get(link.index()).filter(|s| s.open)?;
        Some(Client::new(link, slot.session))
    }

    /// The open link of `client`, if the client is still there.
    fn link_of(&mut self, client: Client) -> Option<&mut HostLink> {
        self.slots
            .get_mut(client.link.index())
            .filter(|s| s.open && s.session == client.session())
            .map(|s| &mut s.link)
    }

    fn host_link(&mut self, link: LinkId) -> Option<&mut HostLink> {
        self.slots
            .get_mut(link.index())
            .filter(|s| s.open)
            .map(|s| &mut s.link)
    }

    /// Takes one byte from `link`'s port at `now_us`; the frames it completes go into
    /// `frames`. `None` if nothing has arrived (or the link is closed). While the link captures
    /// a 0xB0 text ([`Self::start_capture`]) the byte goes to the capture instead, unless it
    /// cannot begin the text (then the capture is over and the framer hears it).
    pub(crate) fn read_byte<H: HostPorts>(
        &mut self,
        now_us: u64,
        ports: &mut H,
        link: LinkId,
        frames: &mut HostFrames,
    ) -> Option<u8> {
        let slot = self.slots.get_mut(link.index()).filter(|s| s.open)?;
        let byte = ports.read_from(link)?;
        if let Some(capture) = slot.capture.as_mut() {
            match capture.push(now_us, byte) {
                Captured::Taken => return Some(byte),
                Captured::NotText => slot.capture = None,
            }
        }
        slot.link.hear(now_us, byte, frames);
        Some(byte)
    }

    /// `link`'s next bytes are the bare 0xB0 text (its announcing frame was answered at
    /// `now_us`): they go to a [`SetTextCapture`] until the link has been quiet for its
    /// [`LinkKind::text_gap_us`].
    pub(crate) fn start_capture(&mut self, now_us: u64, link: LinkId) {
        if let Some(slot) = self.slots.get_mut(link.index()).filter(|s| s.open) {
            slot.capture = Some(SetTextCapture::new(now_us, slot.link.kind().text_gap_us()));
        }
    }

    /// How `link`'s 0xB0 text capture ended, once it has (at `now_us`); the link is framed
    /// again then.
    pub(crate) fn poll_capture(&mut self, now_us: u64, link: LinkId) -> Option<SetTextEnd> {
        let slot = self.slots.get_mut(link.index()).filter(|s| s.open)?;
        let end = slot.capture.as_mut()?.poll(now_us)?;
        slot.capture = None;
        Some(end)
    }

    /// Lets time pass on `link`: a partial frame cut short by the link's gap is dropped, and
    /// frames uncovered by the rescan go into `frames`.
    pub(crate) fn check_gap(&mut self, now_us: u64, link: LinkId, frames: &mut HostFrames) {
        if let Some(host_link) = self.host_link(link) {
            host_link.check_gap(now_us, frames);
        }
    }

    /// Microseconds since `link` last received a byte.
    pub(crate) fn quiet_for_us(&mut self, now_us: u64, link: LinkId) -> u64 {
        self.host_link(link)
            .map_or(u64::MAX, |l| l.quiet_for_us(now_us))
    }

    /// Forgets `link`'s partial frame (its meaning changes with the mode).
    pub(crate) fn reset_framer(&mut self, link: LinkId) {
        if let Some(host_link) = self.host_link(link) {
            host_link.reset_framer();
        }
    }

    /// Queues `frame` from `client` for the Atom, arrived at `now_us`; gives it back if the
    /// client's queue is full (or the client has gone).
    pub(crate) fn push(
        &mut self,
        client: Client,
        frame: Frame,
        answer: Answer,
        now_us: u64,
    ) -> Result<(), Frame> {
        match self
            .slots
            .get_mut(client.link.index())
            .filter(|s| s.open && s.session == client.session())
        {
            Some(slot) => slot
                .waiting
                .push_back(Waiting {
                    frame,
                    answer,
                    arrived_us: now_us,
                })
                .map_err(|w| w.frame),
            None => Err(frame),
        }
    }

    /// True if a request for the Atom seems to be arriving on some link, soon to be in
    /// ([`HostLink::request_coming`]); a link capturing a 0xB0 text is not sending a frame.
    pub(crate) fn request_coming(&self, now_us: u64) -> bool {
        self.slots
            .iter()
            .any(|s| s.open && s.capture.is_none() && s.link.request_coming(now_us))
    }

    /// True if any link has a request waiting.
    pub(crate) fn has_requests(&self) -> bool {
        self.slots.iter().any(|s| s.open && !s.waiting.is_empty())
    }

    /// Drops every waiting request of every link.
    pub(crate) fn clear_requests(&mut self) {
        for slot in &mut self.slots {
            slot.waiting.clear();
        }
    }

    /// The next request for the bus at `now_us`: the first waiting one from the links in turn,
    /// starting after the link that went last, skipping links that could not take a reply of
    /// any size now. Requests older than their client's deadline are dropped unsent and given
    /// to `on_expired`.
    pub(crate) fn next_request(
        &mut self,
        now_us: u64,
        mut on_expired: impl FnMut(Request),
    ) -> Option<Request> {
        for step in 0..MAX_HOST_LINKS {
            let index = (self.turn + step) % MAX_HOST_LINKS;
            let (Some(slot), Some(link)) = (self.slots.get_mut(index), LinkId::from_index(index))
            else {
                continue;
            };
            if !slot.open {
                continue;
            }
            let client = Client::new(link, slot.session);
            // A serial client reading pymycobot's frames gets its reply as it arrives, when it
            // gets it as it is.
            let serial =
                slot.link.kind() == LinkKind::Serial && slot.link.dialect() == Dialect::Pymycobot;
            let request = |waiting: Waiting| Request {
                frame: waiting.frame,
                origin: Origin::Host(client),
                cut_through: serial && waiting.answer == Answer::AsIs,
                answer: waiting.answer,
                queued_us: waiting.arrived_us,
            };
            // Expired requests go even while the link's output is full, so they do not hold
            // up the Basic's own requests (which wait for every link to be idle).
            let deadline_us = slot.link.kind().client_deadline_us();
            while let Some(waiting) = slot
                .waiting
                .pop_front_if(|w| now_us.saturating_sub(w.arrived_us) > deadline_us)
            {
                on_expired(request(waiting));
            }
            if !slot.link.has_room_for_frame() {
                continue;
            }
            if let Some(waiting) = slot.waiting.pop_front() {
                self.turn = (index + 1) % MAX_HOST_LINKS;
                return Some(request(waiting));
            }
        }
        None
    }

    /// Delivers the Atom's `reply` to a request from `origin`: a client's goes to that client
    /// ([`Self::send_reply`]); the Basic's own requests' replies go to nobody (`None`).
    pub(crate) fn deliver(&mut self, origin: Origin, reply: &Frame) -> Option<Delivery> {
        match origin {
            Origin::Host(client) => Some(self.send_reply(client, reply)),
            Origin::PowerOn | Origin::Probe => None,
        }
    }

    /// Queues `reply` for `client`, whole or not at all; a reply being passed on as it
    /// arrived ([`Self::stream_open`]) is completed with it instead, if it is that reply.
    pub(crate) fn send_reply(&mut self, client: Client, reply: &Frame) -> Delivery {
        match self
            .link_of(client)
            .map(|link| link.stream_finish(reply) || link.send_frame(reply))
        {
            None => Delivery::Gone,
            Some(true) => Delivery::Queued,
            Some(false) => Delivery::NoRoom,
        }
    }

    /// Starts passing `client`'s reply on as it arrives: its first bytes `head`, its whole
    /// length `len` reserved ([`HostLink::stream_open`]). False if that cannot be (the client
    /// has gone, no room, not a serial link): the reply then goes whole when it is complete.
    pub(crate) fn stream_open(&mut self, client: Client, head: &[u8], len: usize) -> bool {
        self.link_of(client)
            .is_some_and(|link| link.stream_open(head, len))
    }

    /// The next bytes of `client`'s reply being passed on ([`HostLink::stream_more`]).
    pub(crate) fn stream_more(&mut self, client: Client, bytes: &[u8]) {
        if let Some(link) = self.link_of(client) {
            link.stream_more(bytes);
        }
    }

    /// `client`'s reply being passed on will not complete ([`HostLink::stream_cut`]).
    pub(crate) fn stream_cut(&mut self, client: Client) {
        if let Some(link) = self.link_of(client) {
            link.stream_cut();
        }
    }

    /// Queues `bytes` for `link`, all or none; false if there was no room (or no link).
    pub(crate) fn send_bytes(&mut self, link: LinkId, bytes: &[u8]) -> bool {
        self.host_link(link).is_some_and(|l| l.send_bytes(bytes))
    }

    /// Queues `frame` for `link`, whole or not at all; false if there was no room.
    pub(crate) fn send_frame(&mut self, link: LinkId, frame: &Frame) -> bool {
        self.host_link(link).is_some_and(|l| l.send_frame(frame))
    }

    /// Queues one raw byte for `link` (transparent mode), dropping its oldest queued byte if
    /// its queue is full; false if a byte was dropped. A closed link takes nothing and loses
    /// nothing: the byte goes nowhere and this is true.
    pub(crate) fn send_raw(&mut self, link: LinkId, byte: u8) -> bool {
        self.host_link(link).is_none_or(|l| l.send_raw(byte))
    }

    /// Forgets every byte queued for `link`.
    pub(crate) fn clear_tx(&mut self, link: LinkId) {
        if let Some(host_link) = self.host_link(link) {
            host_link.clear_tx();
        }
    }

    /// Hands each open link's queued bytes to its port, a chunk at a time for as long as the
    /// port's transmitter is idle (a UART is busy after one chunk; a network client's buffer
    /// takes a whole reply, so it leaves in one piece: pymycobot's socket client takes one
    /// `recv` as the whole answer).
    pub(crate) fn flush<H: HostPorts>(&mut self, ports: &mut H) {
        for (index, slot) in self.slots.iter_mut().enumerate() {
            let Some(link) = LinkId::from_index(index).filter(|_| slot.open) else {
                continue;
            };
            while let Some(chunk) = slot.link.next_chunk(ports.tx_idle_on(link)) {
                ports.write_to(link, &chunk);
            }
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn frame(cmd: u8) -> Frame {
        Frame::new(cmd, &[]).unwrap()
    }

    fn cmds_in_turn(router: &mut Router, now_us: u64) -> std::vec::Vec<(usize, u8)> {
        core::iter::from_fn(|| router.next_request(now_us, |_| {}))
            .map(|r| match r.origin {
                Origin::Host(c) => (c.link.index(), r.frame.cmd()),
                _ => (usize::MAX, r.frame.cmd()),
            })
            .collect()
    }

    #[test]
    fn links_take_turns_one_request_each() {
        let mut router = Router::new();
        let a = router.open(LinkKind::Network).unwrap();
        let b = router.open(LinkKind::Network).unwrap();
        for cmd in [0x20, 0x21, 0x22] {
            let usb = router.client(LinkId::USB).unwrap();
            router.push(usb, frame(cmd), Answer::AsIs, 0).unwrap();
        }
        router
            .push(router.client(a).unwrap(), frame(0x30), Answer::AsIs, 0)
            .unwrap();
        router
            .push(router.client(b).unwrap(), frame(0x40), Answer::AsIs, 0)
            .unwrap();
        router
            .push(router.client(b).unwrap(), frame(0x41), Answer::AsIs, 0)
            .unwrap();
        assert_eq!(
            cmds_in_turn(&mut router, 1),
            [
                (0, 0x20),
                (1, 0x30),
                (2, 0x40),
                (0, 0x21),
                (2, 0x41),
                (0, 0x22)
            ]
        );
    }

    #[test]
    fn the_link_limit_refuses_the_next_client_and_a_closed_slot_is_reused() {
        let mut router = Router::new();
        let opened: std::vec::Vec<LinkId> = (1..MAX_HOST_LINKS)
            .map(|_| router.open(LinkKind::Network).unwrap())
            .collect();
        assert_eq!(router.open(LinkKind::Network), Err(LinksFull));
        let third = opened[2];
        let old = router.client(third).unwrap();
        router.close(third);
        assert!(!router.is_open(third));
        assert_eq!(router.open(LinkKind::Network), Ok(third));
        let new = router.client(third).unwrap();
        assert_ne!(old, new, "a new client on the same slot");
        assert_eq!(router.send_reply(old, &frame(0x20)), Delivery::Gone);
        assert_eq!(router.send_reply(new, &frame(0x20)), Delivery::Queued);
    }

    #[test]
    fn the_usb_link_is_always_open() {
        let mut router = Router::new();
        let usb = router.client(LinkId::USB).unwrap();
        router.close(LinkId::USB);
        assert!(router.is_open(LinkId::USB));
        assert_eq!(router.send_reply(usb, &frame(0x20)), Delivery::Gone);
        assert_eq!(router.open_links(), [LinkId::USB]);
    }

    #[test]
    fn requests_older_than_their_clients_deadline_expire_unsent() {
        let mut router = Router::new();
        let net = router.open(LinkKind::Network).unwrap();
        router
            .push(router.client(net).unwrap(), frame(0x30), Answer::AsIs, 0)
            .unwrap();
        let usb = router.client(LinkId::USB).unwrap();
        router.push(usb, frame(0x20), Answer::AsIs, 0).unwrap();
        let mut expired = std::vec::Vec::new();
        let now = LinkKind::Network.client_deadline_us() + 1;
        let sent: std::vec::Vec<u8> =
            core::iter::from_fn(|| router.next_request(now, |r| expired.push(r.frame.cmd())))
                .map(|r| r.frame.cmd())
                .collect();
        assert_eq!(sent, [0x20], "0.3 s for a socket, 0.5 s for USB");
        assert_eq!(expired, [0x30]);
    }

    #[test]
    fn a_link_that_cannot_take_a_reply_waits_but_its_stale_requests_still_go() {
        let mut router = Router::new();
        let net = router.open(LinkKind::Network).unwrap();
        // The client does not read: its output queue is nearly full.
        assert!(router.send_bytes(net, &[0; 500]));
        router
            .push(router.client(net).unwrap(), frame(0x30), Answer::AsIs, 0)
            .unwrap();
        assert!(
            router.next_request(1, |_| {}).is_none(),
            "no room for its reply"
        );
        assert!(router.has_requests());
        let mut expired = 0;
        let late = LinkKind::Network.client_deadline_us() + 1;
        assert!(router.next_request(late, |_| expired += 1).is_none());
        assert_eq!(expired, 1);
        assert!(
            !router.has_requests(),
            "the Basic's own requests are not held up"
        );
    }
}
