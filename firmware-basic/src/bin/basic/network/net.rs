//! The TCP/IP side: smoltcp over esp-radio's station interface, polled from the super-loop.
//! DHCP gets the address; [`TCP_SOCKETS`] TCP sockets listen on the configured port, one client
//! each.
//!
//! Each [`Net::poll`] does a bounded amount of work: smoltcp's maintenance and egress, at most
//! [`INGRESS_PER_POLL`] received frames, and at most [`TCP_CHUNK`] bytes each way per client.
//! Frames left over wait for the next pass (esp-radio queues them).

use alloc::vec;
use alloc::vec::Vec;
use core::net::Ipv4Addr;

use esp_radio::wifi::{Interface as WifiInterface, WifiRxToken, WifiTxToken};
use firmware_basic::wifi::LinkEvent;
use firmware_basic::{Basic, NetClient, NetworkClients};
use smoltcp::iface::{Config, Interface, SocketHandle, SocketSet, SocketStorage};
use smoltcp::phy::{Device, DeviceCapabilities, Medium};
use smoltcp::socket::{dhcpv4, tcp};
use smoltcp::time::{Duration, Instant};
use smoltcp::wire::{EthernetAddress, HardwareAddress, IpCidr, Ipv4Cidr};

/// TCP clients served at once. More are turned away (reset) while all are connected (or while
/// the Basic's router has no link left: [`NetworkClients::connect`]).
pub const TCP_SOCKETS: usize = 4;
/// Each client's receive buffer, bytes: pymycobot sends one request (at most 68 bytes) and waits
/// for its reply, so 1 KiB holds a long burst.
const TCP_RX_BYTES: usize = 1024;
/// Each client's send buffer, bytes: replies, or raw bus bytes in transparent mode (1 KiB is
/// 10 ms of a busy 1 Mbaud bus).
const TCP_TX_BYTES: usize = 1024;
/// Most received frames processed per poll: bounds the time one loop pass spends in smoltcp.
const INGRESS_PER_POLL: usize = 4;
/// Most bytes moved between a socket and its client per poll and direction.
const TCP_CHUNK: usize = 256;
/// A client silent this long with a dead connection is dropped: keep-alive probes every
/// [`KEEP_ALIVE`], connection given up after [`TCP_TIMEOUT`] without an answer.
const KEEP_ALIVE: Duration = Duration::from_secs(10);
const TCP_TIMEOUT: Duration = Duration::from_secs(30);
/// Ethernet frame size esp-radio hands over (its MTU is 1492 bytes of payload).
const MAX_FRAME: usize = 1514;

/// smoltcp's view of esp-radio's station interface.
pub struct WifiDevice(pub WifiInterface);

/// A received frame.
pub struct Rx(WifiRxToken);
/// Room for a frame to send.
pub struct Tx(WifiTxToken);

impl smoltcp::phy::RxToken for Rx {
    fn consume<R, F: FnOnce(&[u8]) -> R>(self, f: F) -> R {
        self.0.consume_token(|frame| f(frame))
    }
}

impl smoltcp::phy::TxToken for Tx {
    fn consume<R, F: FnOnce(&mut [u8]) -> R>(self, len: usize, f: F) -> R {
        self.0.consume_token(len, f)
    }
}

impl Device for WifiDevice {
    type RxToken<'a> = Rx;
    type TxToken<'a> = Tx;

    fn receive(&mut self, _: Instant) -> Option<(Rx, Tx)> {
        self.0.receive().map(|(rx, tx)| (Rx(rx), Tx(tx)))
    }

    fn transmit(&mut self, _: Instant) -> Option<Tx> {
        self.0.transmit().map(Tx)
    }

    fn capabilities(&self) -> DeviceCapabilities {
        let mut caps = DeviceCapabilities::default();
        caps.medium = Medium::Ethernet;
        caps.max_transmission_unit = MAX_FRAME;
        caps
    }
}

/// One TCP socket and the client on it, once admitted ([`NetworkClients::connect`]).
#[derive(Clone, Copy)]
struct Slot {
    handle: SocketHandle,
    client: Option<NetClient>,
}

/// The network stack: interface, DHCP client and the TCP sockets.
pub struct Net {
    device: WifiDevice,
    iface: Interface,
    sockets: SocketSet<'static>,
    dhcp: SocketHandle,
    slots: [Slot; TCP_SOCKETS],
    /// The link is up and DHCP is asking (between `start_dhcp` and `down`).
    up: bool,
    address: Option<Ipv4Addr>,
    /// The port the sockets listen on (0: not listening).
    port: u16,
}

fn timestamp(now_us: u64) -> Instant {
    Instant::from_micros(i64::try_from(now_us).unwrap_or(i64::MAX))
}

impl Net {
    /// The stack on `interface`, at `now_us`; `seed` randomises TCP sequence numbers and DHCP
    /// transaction ids. Its buffers (about 9 KiB) come from the heap, once.
    pub fn new(interface: WifiInterface, now_us: u64, seed: u64) -> Self {
        let mut device = WifiDevice(interface);
        let mac = EthernetAddress(device.0.mac_address());
        let mut config = Config::new(HardwareAddress::Ethernet(mac));
        config.random_seed = seed;
        let iface = Interface::new(config, &mut device, timestamp(now_us));
        let storage: Vec<SocketStorage<'static>> =
            (0..=TCP_SOCKETS).map(|_| SocketStorage::EMPTY).collect();
        let mut sockets = SocketSet::new(storage.leak());
        let dhcp = sockets.add(dhcpv4::Socket::new());
        let slots = core::array::from_fn(|_| {
            let rx = tcp::SocketBuffer::new(vec![0u8; TCP_RX_BYTES].leak());
            let tx = tcp::SocketBuffer::new(vec![0u8; TCP_TX_BYTES].leak());
            let mut socket = tcp::Socket::new(rx, tx);
            socket.set_keep_alive(Some(KEEP_ALIVE));
            socket.set_timeout(Some(TCP_TIMEOUT));
            socket.set_nagle_enabled(false);
            Slot {
                handle: sockets.add(socket),
                client: None,
            }
        });
        Self {
            device,
            iface,
            sockets,
            dhcp,
            slots,
            up: false,
            address: None,
            port: 0,
        }
    }

    /// The link is up: forget any address and ask DHCP for one.
    pub fn start_dhcp(&mut self) {
        self.set_address(None);
        self.sockets.get_mut::<dhcpv4::Socket>(self.dhcp).reset();
        self.up = true;
    }

    /// The network is going: every client's connection is closed once what was queued for it
    /// has been sent (a FIN after the data), so the last answers still leave. [`Self::down`]
    /// follows.
    pub fn close_gracefully(&mut self) {
        for slot in &self.slots {
            if slot.client.is_some() {
                self.sockets.get_mut::<tcp::Socket>(slot.handle).close();
            }
        }
    }

    /// The network is gone: drop the address and every client (their links on `basic` closed).
    pub fn down(&mut self, basic: &mut Basic, clients: &mut NetworkClients) {
        self.up = false;
        self.set_address(None);
        for index in 0..TCP_SOCKETS {
            self.close(index, basic, clients);
        }
    }

    /// Listens on `port` from now on: sockets without a client move to it, connected clients
    /// stay where they are.
    pub fn listen_on(&mut self, port: u16) {
        if port == self.port {
            return;
        }
        self.port = port;
        for slot in &self.slots {
            let socket = self.sockets.get_mut::<tcp::Socket>(slot.handle);
            if socket.is_listening() {
                socket.abort();
            }
        }
    }

    /// One bounded round of network work at `now_us`; returns what DHCP reported, if anything.
    /// Client bytes go to and come from `clients` (new clients get a link on `basic`).
    pub fn poll(
        &mut self,
        now_us: u64,
        basic: &mut Basic,
        clients: &mut NetworkClients,
    ) -> Option<LinkEvent> {
        let now = timestamp(now_us);
        self.iface.poll_maintenance(now);
        for _ in 0..INGRESS_PER_POLL {
            let result = self
                .iface
                .poll_ingress_single(now, &mut self.device, &mut self.sockets);
            if result == smoltcp::iface::PollIngressSingleResult::None {
                break;
            }
        }
        let event = self.poll_dhcp();
        for index in 0..TCP_SOCKETS {
            self.serve(index, basic, clients);
        }
        self.iface
            .poll_egress(now, &mut self.device, &mut self.sockets);
        event
    }

    fn poll_dhcp(&mut self) -> Option<LinkEvent> {
        if !self.up {
            return None;
        }
        let event = match self.sockets.get_mut::<dhcpv4::Socket>(self.dhcp).poll()? {
            dhcpv4::Event::Configured(config) => Some((config.address, config.router)),
            dhcpv4::Event::Deconfigured => None,
        };
        match event {
            Some((cidr, router)) => {
                self.set_address(Some(cidr));
                self.iface.routes_mut().update(|routes| routes.clear());
                if let Some(router) = router {
                    let _ = self.iface.routes_mut().add_default_ipv4_route(router);
                }
                Some(LinkEvent::GotAddress(cidr.address()))
            }
            None => {
                self.set_address(None);
                Some(LinkEvent::LostAddress)
            }
        }
    }

    fn set_address(&mut self, cidr: Option<Ipv4Cidr>) {
        self.address = cidr.map(|c| c.address());
        self.iface.update_ip_addrs(|addrs| {
            addrs.clear();
            if let Some(cidr) = cidr {
                let _ = addrs.push(IpCidr::Ipv4(cidr));
            }
        });
    }

    /// Keeps socket `index` listening while there is an address, admits a new client once its
    /// connection is established (or turns it away), moves its bytes, and ends it when it has
    /// gone or has closed its side.
    fn serve(&mut self, index: usize, basic: &mut Basic, clients: &mut NetworkClients) {
        let Some(slot) = self.slots.get(index).copied() else {
            return;
        };
        let socket = self.sockets.get_mut::<tcp::Socket>(slot.handle);
        let Some(client) = slot.client else {
            match socket.state() {
                tcp::State::Closed => {
                    if self.address.is_some() && self.port != 0 {
                        let _ = socket.listen(self.port);
                    }
                }
                tcp::State::Listen | tcp::State::SynReceived => {}
                tcp::State::Established => match clients.connect(basic) {
                    Some(client) => self.set_client(index, Some(client)),
                    // Every link in use: turned away at once.
                    None => socket.abort(),
                },
                // Closed by the client before it was admitted.
                _ => socket.abort(),
            }
            return;
        };
        let mut chunk = [0u8; TCP_CHUNK];
        if socket.can_recv() {
            // Peeked, then taken as far as the client's buffer took it: the rest waits in the
            // socket (TCP flow control slows a client the Basic cannot keep up with).
            if let Ok(n) = socket.peek_slice(&mut chunk) {
                let taken = clients.receive(client, chunk.get(..n).unwrap_or(&[]));
                let _ = socket.recv_slice(chunk.get_mut(..taken.min(n)).unwrap_or(&mut []));
            }
        }
        if socket.can_send() {
            let room = socket.send_capacity() - socket.send_queue();
            let out = chunk.get_mut(..room.min(TCP_CHUNK)).unwrap_or(&mut []);
            let n = clients.transmit(client, out);
            let _ = socket.send_slice(chunk.get(..n).unwrap_or(&[]));
        }
        // Gone (reset, timed out, closed by us and done), or done sending and all it sent
        // taken.
        if !socket.is_active() || !socket.may_recv() {
            self.close(index, basic, clients);
        }
    }

    /// Ends the client on socket `index`, if there is one: its link on `basic` is closed.
    fn close(&mut self, index: usize, basic: &mut Basic, clients: &mut NetworkClients) {
        let Some(slot) = self.slots.get(index).copied() else {
            return;
        };
        self.sockets.get_mut::<tcp::Socket>(slot.handle).abort();
        if let Some(client) = slot.client {
            self.set_client(index, None);
            clients.disconnect(basic, client);
        }
    }

    fn set_client(&mut self, index: usize, client: Option<NetClient>) {
        if let Some(slot) = self.slots.get_mut(index) {
            slot.client = client;
        }
    }
}
