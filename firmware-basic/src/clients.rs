//! The Basic's network clients (TCP), the part that is the same on the board and in the virtual
//! robot: who is let in, a host link each, and bounded buffers between the sockets and the
//! Basic. The transport (the board's smoltcp sockets, the virtual robot's `TcpStream`s) only
//! moves bytes:
//!
//! 1. a connection is established: [`NetworkClients::connect`] opens a host link for it
//!    ([`Basic::open_link`], [`LinkKind::Network`]) and gives its [`NetClient`] handle; `None`
//!    means turn it away (every link is in use: [`MAX_NETWORK_CLIENTS`] besides the USB one),
//!    and the transport closes it at once;
//! 2. what the client sends: [`NetworkClients::receive`], at most [`NetworkClients::room`]
//!    bytes (the rest waits in the socket: TCP flow control slows the client);
//! 3. the Basic is polled with [`NetworkClients::ports`]: the USB port and every client's
//!    buffers as one [`HostPorts`] (each reply goes to the client that asked, a client's
//!    garbage stays its own: the router's doing);
//! 4. what the Basic sent the client: [`NetworkClients::transmit`] into the socket;
//! 5. the client has gone (closed, reset, timed out, the network went down):
//!    [`NetworkClients::disconnect`] closes its link; what was queued for it is dropped, and a
//!    reply still coming for it is never given to the next client.
//!
//! A handle is never reused (a client that has gone reaches nobody, not its successor on the
//! same link), also across [`NetworkClients::clear`] (the Basic restarted).

use heapless::Deque;
use protocol_core::BytePort;

use crate::basic::Basic;
use crate::host_link::{HOST_WRITE_CHUNK, LinkKind};
use crate::io::BasicIo;
use crate::request::{LinkId, MAX_HOST_LINKS};
use crate::router::HostPorts;

/// Network clients served at once: every host link but the USB one.
pub const MAX_NETWORK_CLIENTS: usize = MAX_HOST_LINKS - 1;

/// Bytes from one client waiting for the Basic (more wait in the socket). pymycobot sends one
/// request (at most 68 bytes) and waits for its reply; the Basic takes 64 bytes per link per
/// poll, so 512 bytes are several polls' worth. Seven clients' buffers both ways are 7 KiB, on
/// the board's loop stack next to the `Basic`.
pub const CLIENT_RX_BYTES: usize = 512;

/// Bytes for one client waiting for its socket: a reply of any size (the 0xB1 text, 113
/// bytes, is the longest) leaves in one piece, and the socket takes them every loop pass. A
/// client that does not read loses what does not fit (it never stalls the Basic).
pub const CLIENT_TX_BYTES: usize = 512;

/// One network client, from [`NetworkClients::connect`]. Never reused.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub struct NetClient {
    index: u8,
    session: u32,
}

/// One connected client.
#[derive(Debug)]
struct Slot {
    session: u32,
    link: LinkId,
    rx: Deque<u8, CLIENT_RX_BYTES>,
    tx: Deque<u8, CLIENT_TX_BYTES>,
}

/// The network clients. See the [module doc](self).
#[derive(Debug)]
pub struct NetworkClients {
    slots: [Option<Slot>; MAX_NETWORK_CLIENTS],
    next_session: u32,
    /// Bytes for clients dropped because their buffer was full (a client that does not read).
    /// Wraps.
    pub tx_dropped: u32,
}

impl Default for NetworkClients {
    fn default() -> Self {
        Self::new()
    }
}

impl NetworkClients {
    /// No client connected.
    pub const fn new() -> Self {
        Self {
            slots: [const { None }; MAX_NETWORK_CLIENTS],
            next_session: 0,
            tx_dropped: 0,
        }
    }

    /// A connection was established: opens a host link on `basic` for it. `None`: turn it away
    /// (close the connection at once), every link is in use.
    pub fn connect(&mut self, basic: &mut Basic) -> Option<NetClient> {
        let index = self.slots.iter().position(Option::is_none)?;
        let link = basic.open_link(LinkKind::Network).ok()?;
        let session = self.next_session;
        self.next_session = self.next_session.wrapping_add(1);
        let slot = self.slots.get_mut(index)?;
        *slot = Some(Slot {
            session,
            link,
            rx: Deque::new(),
            tx: Deque::new(),
        });
        Some(NetClient {
            // Cannot truncate: index < MAX_NETWORK_CLIENTS.
            index: index as u8,
            session,
        })
    }

    /// `client` has gone: its link on `basic` is closed. No-op for a client already gone.
    pub fn disconnect(&mut self, basic: &mut Basic, client: NetClient) {
        if let Some(gone) = self.slot_entry(client).and_then(Option::take) {
            basic.close_link(gone.link);
        }
    }

    /// Forgets every client without closing links: the Basic they were on has restarted (and
    /// has no links but USB). Handles given out before still reach nobody.
    pub fn clear(&mut self) {
        self.slots = [const { None }; MAX_NETWORK_CLIENTS];
    }

    /// True while `client` is connected.
    pub fn is_connected(&self, client: NetClient) -> bool {
        self.slot(client).is_some()
    }

    /// Clients connected now.
    pub fn count(&self) -> u8 {
        // Cannot truncate: at most MAX_NETWORK_CLIENTS.
        self.slots.iter().flatten().count() as u8
    }

    /// How many bytes `client` may send now (0 for a client that has gone).
    pub fn room(&self, client: NetClient) -> usize {
        self.slot(client)
            .map_or(0, |s| CLIENT_RX_BYTES - s.rx.len())
    }

    /// Takes what `client` sent, as far as there is [`Self::room`]; returns how many bytes were
    /// taken (the rest stays in the socket).
    pub fn receive(&mut self, client: NetClient, bytes: &[u8]) -> usize {
        let Some(slot) = self.slot_mut(client) else {
            return 0;
        };
        let mut taken = 0;
        for &b in bytes {
            if slot.rx.push_back(b).is_err() {
                break;
            }
            taken += 1;
        }
        taken
    }

    /// Bytes the Basic has for `client`, waiting for its socket.
    pub fn pending(&self, client: NetClient) -> usize {
        self.slot(client).map_or(0, |s| s.tx.len())
    }

    /// Moves up to `out.len()` of the bytes the Basic has for `client` into `out` (for its
    /// socket); returns how many.
    pub fn transmit(&mut self, client: NetClient, out: &mut [u8]) -> usize {
        let Some(slot) = self.slot_mut(client) else {
            return 0;
        };
        let mut n = 0;
        for place in out.iter_mut() {
            match slot.tx.pop_front() {
                Some(b) => *place = b,
                None => break,
            }
            n += 1;
        }
        n
    }

    /// The Basic's host links as one [`HostPorts`]: `usb` for the USB link, these clients'
    /// buffers for theirs.
    pub fn ports<'a, U: BytePort>(&'a mut self, usb: &'a mut U) -> ClientPorts<'a, U> {
        ClientPorts { usb, clients: self }
    }

    /// Polls `basic` at `now_us` with its USB port `usb`, these clients, the bus and the board's
    /// IO ([`Basic::poll`] with [`Self::ports`]).
    pub fn poll_basic<U: BytePort, B: BytePort, I: BasicIo>(
        &mut self,
        basic: &mut Basic,
        now_us: u64,
        usb: &mut U,
        bus: &mut B,
        io: &mut I,
    ) {
        basic.poll(now_us, &mut self.ports(usb), bus, io);
    }

    fn slot_entry(&mut self, client: NetClient) -> Option<&mut Option<Slot>> {
        self.slots
            .get_mut(usize::from(client.index))
            .filter(|s| s.as_ref().is_some_and(|s| s.session == client.session))
    }

    fn slot(&self, client: NetClient) -> Option<&Slot> {
        self.slots
            .get(usize::from(client.index))?
            .as_ref()
            .filter(|s| s.session == client.session)
    }

    fn slot_mut(&mut self, client: NetClient) -> Option<&mut Slot> {
        self.slots
            .get_mut(usize::from(client.index))?
            .as_mut()
            .filter(|s| s.session == client.session)
    }

    fn by_link(&mut self, link: LinkId) -> Option<&mut Slot> {
        self.slots.iter_mut().flatten().find(|s| s.link == link)
    }
}

/// The USB port and the network clients' buffers, as the Basic's [`HostPorts`].
pub struct ClientPorts<'a, U> {
    usb: &'a mut U,
    clients: &'a mut NetworkClients,
}

impl<U: BytePort> HostPorts for ClientPorts<'_, U> {
    fn read_from(&mut self, link: LinkId) -> Option<u8> {
        if link == LinkId::USB {
            return self.usb.read_byte();
        }
        self.clients.by_link(link)?.rx.pop_front()
    }

    fn write_to(&mut self, link: LinkId, bytes: &[u8]) {
        if link == LinkId::USB {
            self.usb.write(bytes);
            return;
        }
        let mut dropped = 0u32;
        if let Some(slot) = self.clients.by_link(link) {
            for &b in bytes {
                if slot.tx.push_back(b).is_err() {
                    dropped += 1;
                }
            }
        }
        self.clients.tx_dropped = self.clients.tx_dropped.wrapping_add(dropped);
    }

    fn tx_idle_on(&self, link: LinkId) -> bool {
        if link == LinkId::USB {
            return self.usb.tx_idle();
        }
        self.clients
            .slots
            .iter()
            .flatten()
            .find(|s| s.link == link)
            .is_some_and(|s| CLIENT_TX_BYTES - s.tx.len() >= HOST_WRITE_CHUNK)
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::config::BasicConfig;
    use crate::io::NullIo;
    use protocol_core::NullPort;

    fn poll(clients: &mut NetworkClients, basic: &mut Basic, now_us: u64) {
        clients.poll_basic(basic, now_us, &mut NullPort, &mut NullPort, &mut NullIo);
    }

    fn take(clients: &mut NetworkClients, client: NetClient) -> std::vec::Vec<u8> {
        let mut out = [0u8; CLIENT_TX_BYTES];
        let n = clients.transmit(client, &mut out);
        out[..n].to_vec()
    }

    const VERSION: [u8; 5] = [0xFE, 0xFE, 0x02, 0xC1, 0xFA];

    #[test]
    fn each_client_gets_its_own_answer() {
        let mut basic = Basic::new(BasicConfig::default());
        let mut clients = NetworkClients::new();
        let a = clients.connect(&mut basic).unwrap();
        let b = clients.connect(&mut basic).unwrap();
        assert_eq!(clients.receive(a, &VERSION), 5);
        assert_eq!(clients.receive(b, &[0xFE, 0xFE, 0x02, 0xC3, 0xFA]), 5);
        poll(&mut clients, &mut basic, 1_000);
        assert_eq!(take(&mut clients, a)[3], 0xC1);
        assert_eq!(take(&mut clients, b)[3], 0xC3);
        assert_eq!(clients.count(), 2);
    }

    #[test]
    fn the_limit_turns_the_next_client_away_and_a_leaver_makes_room() {
        let mut basic = Basic::new(BasicConfig::default());
        let mut clients = NetworkClients::new();
        let all: std::vec::Vec<NetClient> = (0..MAX_NETWORK_CLIENTS)
            .map(|_| clients.connect(&mut basic).unwrap())
            .collect();
        assert_eq!(clients.connect(&mut basic), None);
        clients.disconnect(&mut basic, all[3]);
        assert!(!clients.is_connected(all[3]));
        let newcomer = clients.connect(&mut basic).unwrap();
        assert_ne!(newcomer, all[3], "a handle is never reused");
        // The old handle reaches nobody.
        assert_eq!(clients.receive(all[3], &VERSION), 0);
        assert_eq!(clients.room(all[3]), 0);
        clients.disconnect(&mut basic, all[3]);
        assert!(clients.is_connected(newcomer));
    }

    #[test]
    fn a_client_sends_no_more_than_its_room_and_a_reader_that_lags_loses_the_excess() {
        let mut basic = Basic::new(BasicConfig::default());
        let mut clients = NetworkClients::new();
        let a = clients.connect(&mut basic).unwrap();
        assert_eq!(
            clients.receive(a, &[0x55; 2 * CLIENT_RX_BYTES]),
            CLIENT_RX_BYTES
        );
        assert_eq!(clients.room(a), 0);
        let mut usb = NullPort;
        let mut ports = clients.ports(&mut usb);
        let link = LinkId::from_index(1).unwrap();
        ports.write_to(link, &[1; CLIENT_TX_BYTES + 10]);
        assert!(!ports.tx_idle_on(link));
        assert_eq!(clients.tx_dropped, 10);
        assert_eq!(clients.pending(a), CLIENT_TX_BYTES);
    }

    #[test]
    fn a_long_answer_leaves_in_one_piece() {
        let mut basic = Basic::new(BasicConfig::default());
        let mut clients = NetworkClients::new();
        let a = clients.connect(&mut basic).unwrap();
        // 0x20 get_angles has no answer here (no Atom); 0xB1 without Wi-Fi answers its text.
        clients.receive(a, &[0xFE, 0xFE, 0x02, 0xB1, 0xFA]);
        poll(&mut clients, &mut basic, 1_000);
        assert_eq!(take(&mut clients, a), b"ssid:  password: ");
    }

    #[test]
    fn after_the_basic_restarts_old_handles_reach_nobody() {
        let mut basic = Basic::new(BasicConfig::default());
        let mut clients = NetworkClients::new();
        let old = clients.connect(&mut basic).unwrap();
        basic = Basic::new(BasicConfig::default());
        clients.clear();
        let new = clients.connect(&mut basic).unwrap();
        assert_ne!(old, new);
        assert!(!clients.is_connected(old));
        clients.disconnect(&mut basic, new);
        assert_eq!(clients.count(), 0);
        assert_eq!(basic.open_link(LinkKind::Network).map(LinkId::index), Ok(1));
    }
}
