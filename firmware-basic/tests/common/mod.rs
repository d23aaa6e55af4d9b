//! A simulated Basic board for tests and benchmarks: host links (the USB serial and network
//! clients), the shared bus of `sim-hw` (byte timing, echo, collisions), a scripted Atom, other
//! stations that inject traffic, and virtual time.
//!
//! Two transmissions that overlap on the bus garble each other for every listener. The Basic
//! hears everything the others send, and its own bytes when `echo` is on; the scripted Atom
//! listens to the Basic, and can poll a servo by the Atom's bus schedule ([`Wire::poll_servos`]).
#![allow(dead_code, clippy::unwrap_used, clippy::indexing_slicing)]

pub mod clients;

use std::collections::VecDeque;

use firmware_basic::wifi::{FlashWifiStore, WifiStore};
use firmware_basic::{
    Basic, BasicConfig, BasicIo, Buttons, HostPorts, LinkId, LinkKind, LinksFull, MAX_HOST_LINKS,
};
use flash_store::MemFlash;
use protocol_core::listener::{Heard, Listener, ListenerConfig};
use protocol_core::{BytePort, Frame, FrameDecoder, timing};
use sim_hw::{Bus, HeardByte, StationId};

/// Nanoseconds of one byte on the bus.
pub const BUS_BYTE_NS: u64 = timing::wire_time_ns(1, timing::BUS_BAUD);
/// Nanoseconds of one byte on the host link.
pub const HOST_BYTE_NS: u64 = timing::wire_time_ns(1, timing::HOST_BAUD);

/// The Atom's servo poll: a READ of servo 1's state (present position and more)...
pub const SERVO_READ: [u8; 8] = [0xFF, 0xFF, 0x01, 0x04, 0x02, 0x38, 0x0F, 0xB1];
/// ...and the servo's 21-byte status answering it.
pub const SERVO_STATUS: [u8; 21] = [
    0xFF, 0xFF, 0x01, 0x11, 0x00, 0x10, 0x10, 0x10, 0x10, 0x10, 0x10, 0x10, 0x10, 0x10, 0x10, 0x10,
    0x10, 0x10, 0x10, 0x10, 0x10,
];
/// One servo transaction at most, READ, turnaround and status, in ns.
pub const SERVO_TRANSACTION_NS: u64 = (SERVO_READ.len() + SERVO_STATUS.len()) as u64 * BUS_BYTE_NS
    + timing::SERVO_TURNAROUND_MAX_US * 1_000;

/// The scripted Atom polling a servo as `firmware-atom`'s bus schedule does: a transaction
/// starts only after [`timing::ATOM_TRANSACTION_GAP_US`] of quiet on the wire (whoever spoke
/// last), never while it has a reply to send, and not while a frame it hears is unfinished
/// (until the frame gap cuts it short).
struct ServoPolling {
    /// No transaction starts before this, ns: the start asked for, then the end of the last
    /// transaction and the gap.
    not_before_ns: u64,
    /// No transaction starts from this time on, ns.
    until_ns: u64,
    /// The bytes of the READ on the wire heard so far; `None` between transactions.
    read_heard: Option<Vec<u8>>,
}

/// The shared wire: `sim-hw`'s bus with the Basic, the scripted Atom and other stations
/// (servo traffic, noise) attached.
pub struct Wire {
    bus: Bus,
    now_ns: u64,
    basic: StationId,
    atom: StationId,
    /// Transmitters of injected traffic, each with the end (ns) of what it was given, so that
    /// bursts that overlap in time come from different stations and collide as on a real wire.
    injectors: Vec<(StationId, u64)>,
    /// Injected bursts waiting for their start: (start ns, station, bytes), by start.
    scheduled: VecDeque<(u64, StationId, Vec<u8>)>,
    heard: Vec<HeardByte>,
    /// Who sent the last byte that ended on the wire.
    last_from: Option<StationId>,
    /// Bytes the Basic transmitted, with their start time in ns.
    pub basic_sent: Vec<(u64, u8)>,
    /// Bytes the Atom heard from the Basic, with their end time in ns, for its decoder.
    atom_rx: VecDeque<(u64, u8)>,
    /// The Atom's answers waiting for a free wire: (earliest start ns, bytes).
    atom_outbox: VecDeque<(u64, Vec<u8>)>,
    /// When the Atom tries its waiting answer again, ns.
    atom_retry_ns: Option<u64>,
    /// The Atom's servo polling, while on.
    servo_polling: Option<ServoPolling>,
    /// The Atom has heard the start of a frame that has not ended.
    atom_frame_open: bool,
    /// When each of the Atom's servo READs started, ns.
    pub servo_reads: Vec<u64>,
}

impl Wire {
    fn new(echo: bool) -> Self {
        let mut bus = Bus::mycobot(11);
        bus.set_tap(true);
        bus.set_tracing(true);
        let basic = bus.attach(echo);
        let atom = bus.attach_transmitter();
        Self {
            bus,
            now_ns: 0,
            basic,
            atom,
            injectors: Vec::new(),
            scheduled: VecDeque::new(),
            heard: Vec::new(),
            last_from: None,
            basic_sent: Vec::new(),
            atom_rx: VecDeque::new(),
            atom_outbox: VecDeque::new(),
            atom_retry_ns: None,
            servo_polling: None,
            atom_frame_open: false,
            servo_reads: Vec::new(),
        }
    }

    /// The Atom polls servo 1 ([`SERVO_READ`], answered by [`SERVO_STATUS`] after the longest
    /// turnaround) from `from_ns` until `until_ns`, one transaction after another as its bus
    /// schedule allows: it holds back while the Basic talks in its gap, and while it answers.
    pub fn poll_servos(&mut self, from_ns: u64, until_ns: u64) {
        self.servo_polling = Some(ServoPolling {
            not_before_ns: from_ns,
            until_ns,
            read_heard: None,
        });
    }

    /// Bytes garbled by overlapping transmissions so far.
    pub fn collisions(&self) -> u64 {
        self.bus.collisions()
    }

    /// When the Atom's next servo transaction may start, ns, if nothing but time holds it.
    fn servo_poll_due_ns(&self) -> Option<u64> {
        let polling = self.servo_polling.as_ref()?;
        if polling.read_heard.is_some() || self.bus.busy() || !self.atom_outbox.is_empty() {
            // A byte's end, or the Atom's answer, comes first.
            return None;
        }
        let hold_us = if self.atom_frame_open {
            timing::BUS_FRAME_GAP_US
        } else {
            timing::ATOM_TRANSACTION_GAP_US
        };
        let due = polling
            .not_before_ns
            .max(self.bus.last_activity_ns() + hold_us * 1_000);
        (due < polling.until_ns).then_some(due)
    }

    /// Starts the Atom's next servo READ if its schedule allows it now.
    fn servo_poll(&mut self) {
        let now = self.now_ns;
        if self.servo_poll_due_ns().is_none_or(|due| due > now) {
            return;
        }
        if let Some(polling) = self.servo_polling.as_mut() {
            polling.read_heard = Some(Vec::new());
            polling.not_before_ns =
                now + SERVO_TRANSACTION_NS + timing::ATOM_TRANSACTION_GAP_US * 1_000;
            self.bus.port(self.atom).unwrap().write(&SERVO_READ);
            self.servo_reads.push(now);
        }
    }

    /// Follows the Atom's READ on the wire: a servo answers one that arrived intact.
    fn servo_hears(&mut self, byte: u8, end_ns: u64) {
        let Some(polling) = self.servo_polling.as_mut() else {
            return;
        };
        let Some(read) = polling.read_heard.as_mut() else {
            return;
        };
        read.push(byte);
        if read.len() < SERVO_READ.len() {
            return;
        }
        let intact = read[..] == SERVO_READ;
        polling.read_heard = None;
        if intact {
            self.inject(
                end_ns + timing::SERVO_TURNAROUND_MAX_US * 1_000,
                &SERVO_STATUS,
            );
        }
    }

    /// Schedules `bytes` from another station, back to back from `start_ns` (or from now, if
    /// that has passed).
    pub fn inject(&mut self, start_ns: u64, bytes: &[u8]) {
        let start_ns = start_ns.max(self.now_ns);
        let end_ns = start_ns + bytes.len() as u64 * BUS_BYTE_NS;
        let free = self
            .injectors
            .iter_mut()
            .find(|(_, busy_until)| *busy_until <= start_ns);
        let station = match free {
            Some((id, busy_until)) => {
                *busy_until = end_ns;
                *id
            }
            None => {
                let id = self.bus.attach_transmitter();
                self.injectors.push((id, end_ns));
                id
            }
        };
        let pos = self.scheduled.partition_point(|(t, _, _)| *t <= start_ns);
        self.scheduled
            .insert(pos, (start_ns, station, bytes.to_vec()));
    }

    /// Time the wire has been silent, in ns (0 while somebody transmits).
    pub fn quiet_ns(&self) -> u64 {
        if self.bus.busy() {
            0
        } else {
            self.now_ns.saturating_sub(self.bus.last_activity_ns())
        }
    }

    /// The next instant the wire needs attention: a byte ends, a burst starts, the Atom tries
    /// to send.
    fn next_event_ns(&self) -> Option<u64> {
        [
            self.bus.next_event_ns(),
            self.scheduled.front().map(|(t, _, _)| *t),
            self.atom_retry_ns,
            self.servo_poll_due_ns(),
        ]
        .into_iter()
        .flatten()
        .min()
    }

    /// Moves to `now_ns`: bytes that ended arrive, injected bursts that are due are queued.
    fn arrive(&mut self, now_ns: u64) {
        self.now_ns = now_ns;
        self.bus.deliver(now_ns);
        self.bus.take_heard(&mut self.heard);
        let mut heard = std::mem::take(&mut self.heard);
        for h in heard.drain(..) {
            self.last_from = Some(h.from);
            if h.from == self.basic {
                self.atom_rx.push_back((h.end_ns, h.byte));
            } else if h.from == self.atom {
                self.servo_hears(h.byte, h.end_ns);
            }
        }
        self.heard = heard;
        while let Some((_, station, bytes)) = self.scheduled.pop_front_if(|(t, _, _)| *t <= now_ns)
        {
            self.bus.port(station).unwrap().write(&bytes);
        }
    }

    /// Starts the bytes queued at the current instant.
    fn start_transmissions(&mut self) {
        self.bus.start_transmissions(self.now_ns);
        for b in self.bus.take_trace() {
            if b.from == self.basic {
                self.basic_sent.push((b.start_ns, b.byte));
            }
        }
    }

    /// The Atom sends its waiting answer once its time has come and the wire is free: it may
    /// answer the Basic right after its request, but leaves the quiet time around other
    /// stations' traffic (heard, or scheduled to start). Returns what it started, with when.
    fn atom_try_send(&mut self) -> Option<(u64, Vec<u8>)> {
        self.atom_retry_ns = None;
        let (earliest, bytes) = self.atom_outbox.front()?;
        let now = self.now_ns;
        if self.bus.busy() {
            // Tried again at the next byte end.
            self.atom_retry_ns = Some(*earliest).filter(|&t| t > now);
            return None;
        }
        let quiet = timing::BUS_QUIET_BEFORE_SEND_US * 1_000;
        let after_others = if self.last_from.is_some_and(|f| f != self.basic) {
            self.bus.last_activity_ns() + quiet
        } else {
            0
        };
        let end = now + bytes.len() as u64 * BUS_BYTE_NS;
        let clash = self
            .scheduled
            .iter()
            .map(|(t, _, b)| (*t, *t + b.len() as u64 * BUS_BYTE_NS))
            .filter(|&(start, stop)| start < end + quiet && now < stop + quiet)
            .map(|(_, stop)| stop + quiet)
            .max()
            .unwrap_or(0);
        let ready = (*earliest).max(after_others).max(clash);
        if ready > now {
            self.atom_retry_ns = Some(ready);
            return None;
        }
        let (_, bytes) = self.atom_outbox.pop_front()?;
        self.bus.port(self.atom).unwrap().write(&bytes);
        if let Some((earliest, _)) = self.atom_outbox.front() {
            self.atom_retry_ns = Some((*earliest).max(now + 1));
        }
        Some((now, bytes))
    }
}

/// A client's side of a host link: what it sends (with the link's byte timing) and what the
/// Basic wrote.
pub struct HostPort {
    now_ns: u64,
    /// Time of one byte on the link, ns: 115200 baud for the USB serial, 0 for a network
    /// client (whatever it writes is there at once).
    byte_ns: u64,
    to_basic: VecDeque<(u64, u8)>,
    tx_busy_until_ns: u64,
    /// Bytes the Basic wrote, with the time (ns) each started on the wire.
    pub from_basic: Vec<(u64, u8)>,
}

impl Default for HostPort {
    fn default() -> Self {
        Self::serial()
    }
}

impl HostPort {
    /// The USB serial at 115200 baud.
    pub fn serial() -> Self {
        Self::with_byte_ns(HOST_BYTE_NS)
    }

    /// A network client: no wire time.
    pub fn network() -> Self {
        Self::with_byte_ns(0)
    }

    fn with_byte_ns(byte_ns: u64) -> Self {
        Self {
            now_ns: 0,
            byte_ns,
            to_basic: VecDeque::new(),
            tx_busy_until_ns: 0,
            from_basic: Vec::new(),
        }
    }

    /// Queues `bytes` from the host, back to back after whatever is queued, from `now`;
    /// returns when the last of them has arrived, in ns.
    pub fn send(&mut self, bytes: &[u8]) -> u64 {
        let mut end = self
            .to_basic
            .back()
            .map_or(self.now_ns, |&(end, _)| end.max(self.now_ns));
        for &b in bytes {
            end += self.byte_ns;
            self.to_basic.push_back((end, b));
        }
        end
    }

    /// The frames the Basic sent to this client so far, decoded.
    pub fn frames(&self) -> Vec<Frame> {
        let mut out = Vec::new();
        FrameDecoder::new().feed(&self.received(), |f| out.push(f));
        out
    }

    /// The bytes the Basic sent to the host so far.
    pub fn received(&self) -> Vec<u8> {
        self.from_basic.iter().map(|&(_, b)| b).collect()
    }
}

impl BytePort for HostPort {
    fn read_byte(&mut self) -> Option<u8> {
        match self.to_basic.front() {
            Some(&(at, b)) if at <= self.now_ns => {
                self.to_basic.pop_front();
                Some(b)
            }
            _ => None,
        }
    }

    fn write(&mut self, bytes: &[u8]) {
        let start = self.now_ns.max(self.tx_busy_until_ns);
        for (i, &b) in bytes.iter().enumerate() {
            self.from_basic.push((start + i as u64 * self.byte_ns, b));
        }
        self.tx_busy_until_ns = start + bytes.len() as u64 * self.byte_ns;
    }

    fn tx_idle(&self) -> bool {
        self.now_ns >= self.tx_busy_until_ns
    }
}

/// A Basic board's pins in memory.
#[derive(Default)]
pub struct MemIo {
    /// Levels written to outputs, in order.
    pub outputs: Vec<(u8, bool)>,
    /// Level of input 35 and 36.
    pub inputs: [bool; 2],
    /// ToF reading.
    pub tof_mm: Option<u16>,
    /// Buttons pressed now.
    pub buttons: Buttons,
    /// The Wi-Fi settings' flash (`None`: a board without Wi-Fi).
    pub wifi: Option<WifiFlash>,
}

/// The Wi-Fi settings' store in the tests: 24 KiB of RAM flash, like the board's `nvs` range.
pub type WifiFlash = FlashWifiStore<MemFlash<{ 6 * 4096 }>>;

/// An erased Wi-Fi settings flash.
pub fn wifi_flash() -> WifiFlash {
    FlashWifiStore::new(MemFlash::new(), 0..6 * 4096)
}

impl BasicIo for MemIo {
    fn set_output(&mut self, pin: u8, high: bool) -> bool {
        self.outputs.push((pin, high));
        true
    }

    fn read_input(&mut self, pin: u8) -> Option<bool> {
        match pin {
            35 => Some(self.inputs[0]),
            36 => Some(self.inputs[1]),
            _ => None,
        }
    }

    fn tof_distance_mm(&mut self) -> Option<u16> {
        self.tof_mm
    }

    fn buttons(&mut self) -> Buttons {
        self.buttons
    }

    fn wifi_store(&mut self) -> Option<&mut dyn WifiStore> {
        self.wifi.as_mut().map(|s| s as &mut dyn WifiStore)
    }
}

/// How the scripted Atom answers a request: the raw bytes it puts on the bus, if any.
pub type Responder = Box<dyn FnMut(&Frame) -> Option<Vec<u8>>>;

/// The standard Atom: status `01` for everything, `01` for 0x12, six angles for 0x20.
pub fn ack_everything() -> Responder {
    Box::new(|f: &Frame| {
        let data: Vec<u8> = match f.cmd() {
            0x20 => vec![0, 100, 0xFF, 0x9C, 0, 0, 0, 0, 0x12, 0x34, 0xFE, 0xFA],
            _ => vec![1],
        };
        Some(Frame::new(f.cmd(), &data).unwrap().to_bytes().to_vec())
    })
}

/// Every host link's client side, for [`Basic::poll`]: the USB serial and the network clients
/// by link index.
struct RigPorts<'a> {
    usb: &'a mut HostPort,
    clients: &'a mut [Option<HostPort>],
}

impl RigPorts<'_> {
    fn port(&mut self, link: LinkId) -> Option<&mut HostPort> {
        if link == LinkId::USB {
            return Some(self.usb);
        }
        self.clients.get_mut(link.index())?.as_mut()
    }
}

impl HostPorts for RigPorts<'_> {
    fn read_from(&mut self, link: LinkId) -> Option<u8> {
        self.port(link)?.read_byte()
    }

    fn write_to(&mut self, link: LinkId, bytes: &[u8]) {
        if let Some(port) = self.port(link) {
            port.write(bytes);
        }
    }

    fn tx_idle_on(&self, link: LinkId) -> bool {
        if link == LinkId::USB {
            return self.usb.tx_idle();
        }
        self.clients
            .get(link.index())
            .and_then(Option::as_ref)
            .is_none_or(HostPort::tx_idle)
    }
}

/// The Basic, its ports and a scripted Atom on one simulated wire.
pub struct Rig {
    /// The firmware under test.
    pub basic: Basic,
    /// The USB host link.
    pub host: HostPort,
    /// The network clients, by link index (`None`: no client there).
    pub clients: Vec<Option<HostPort>>,
    /// The shared bus.
    wire: Wire,
    /// The Basic's pins.
    pub io: MemIo,
    /// Virtual time, ns.
    pub now_ns: u64,
    /// Poll period, ns.
    pub step_ns: u64,
    /// How the scripted Atom hears the Basic: host frames, the bus frame gap.
    atom_rx: Listener,
    /// Frames the Atom received intact, with the time (ns) their last byte ended.
    pub atom_got: Vec<(u64, Frame)>,
    /// The Atom's replies: when each started on the wire (ns) and its bytes.
    pub atom_sent: Vec<(u64, Vec<u8>)>,
    /// How the Atom answers.
    pub atom: Responder,
    /// Time from the end of a request to the start of the Atom's answer, ns.
    pub atom_delay_ns: u64,
}

impl Rig {
    /// A rig with `config`, an echoing or silent wire, and an Atom that acks everything.
    pub fn new(config: BasicConfig, echo: bool) -> Self {
        Self {
            basic: Basic::new(config),
            host: HostPort::default(),
            clients: (0..MAX_HOST_LINKS).map(|_| None).collect(),
            wire: Wire::new(echo),
            io: MemIo::default(),
            now_ns: 0,
            step_ns: 1_000,
            atom_rx: Listener::new(ListenerConfig::new().with_packets(false)),
            atom_got: Vec::new(),
            atom_sent: Vec::new(),
            atom: ack_everything(),
            atom_delay_ns: 200_000,
        }
    }

    /// A rig for forwarding tests: no boot power-on, no probes.
    pub fn quiet(echo: bool) -> Self {
        Self::new(
            BasicConfig {
                power_on_at_boot: false,
                probe_interval_us: 0,
                ..BasicConfig::default()
            },
            echo,
        )
    }

    /// The wire.
    pub fn wire(&mut self) -> &mut Wire {
        &mut self.wire
    }

    /// A network client connects: the Basic opens a link for it.
    pub fn connect(&mut self) -> Result<LinkId, LinksFull> {
        let link = self.basic.open_link(LinkKind::Network)?;
        if let Some(slot) = self.clients.get_mut(link.index()) {
            *slot = Some(HostPort::network());
        }
        Ok(link)
    }

    /// The network client on `link` leaves.
    pub fn disconnect(&mut self, link: LinkId) {
        self.basic.close_link(link);
        if let Some(slot) = self.clients.get_mut(link.index()) {
            *slot = None;
        }
    }

    /// The client side of `link` (the USB serial, or a network client).
    pub fn client(&mut self, link: LinkId) -> &mut HostPort {
        if link == LinkId::USB {
            return &mut self.host;
        }
        self.clients[link.index()].as_mut().unwrap()
    }

    /// One poll at the current time (after the wire has run up to it), then time moves on by
    /// one step.
    pub fn step(&mut self) {
        while let Some(t) = self.wire.next_event_ns().filter(|&t| t < self.now_ns) {
            self.wire_instant(t);
        }
        self.wire.arrive(self.now_ns);
        self.run_atom();
        // Before the Basic's poll: neither hears what the other starts in this instant.
        self.wire.servo_poll();
        self.host.now_ns = self.now_ns;
        for client in self.clients.iter_mut().flatten() {
            client.now_ns = self.now_ns;
        }
        let mut bus = self.wire.bus.port(self.wire.basic).unwrap();
        let mut ports = RigPorts {
            usb: &mut self.host,
            clients: &mut self.clients,
        };
        self.basic
            .poll(self.now_ns / 1_000, &mut ports, &mut bus, &mut self.io);
        self.atom_send();
        self.wire.start_transmissions();
        self.now_ns += self.step_ns;
    }

    /// An instant between polls: bytes arrive, the Atom answers, transmitters start.
    fn wire_instant(&mut self, t_ns: u64) {
        self.wire.arrive(t_ns);
        self.run_atom();
        self.wire.servo_poll();
        self.atom_send();
        self.wire.start_transmissions();
    }

    fn atom_send(&mut self) {
        if let Some(sent) = self.wire.atom_try_send() {
            self.atom_sent.push(sent);
        }
    }

    /// Runs for `us` microseconds of virtual time.
    pub fn run_us(&mut self, us: u64) {
        let end = self.now_ns + us * 1_000;
        while self.now_ns < end {
            self.step();
        }
    }

    /// Runs until the host has received `n` bytes, or `max_us` passed; true if it did.
    pub fn run_until_host_has(&mut self, n: usize, max_us: u64) -> bool {
        let end = self.now_ns + max_us * 1_000;
        while self.now_ns < end {
            if self.host.from_basic.len() >= n {
                return true;
            }
            self.step();
        }
        self.host.from_basic.len() >= n
    }

    fn run_atom(&mut self) {
        let heard: Vec<(u64, u8)> = self.wire.atom_rx.drain(..).collect();
        let mut frames = Vec::new();
        for (at, b) in heard {
            // Each byte is heard when it ends: the silence before it passes first.
            let mut on_heard = |h| {
                if let Heard::Frame(f) = h {
                    frames.push((at, f));
                }
            };
            self.atom_rx.on_time(at / 1_000, &mut on_heard);
            self.atom_rx.push(at / 1_000, b, &mut on_heard);
        }
        self.wire.atom_frame_open = self.atom_rx.frame_in_progress();
        for (at, frame) in frames {
            self.atom_got.push((at, frame.clone()));
            if let Some(reply) = (self.atom)(&frame) {
                self.wire
                    .atom_outbox
                    .push_back((at + self.atom_delay_ns, reply));
            }
        }
    }

    /// The frames the host received, decoded.
    pub fn host_frames(&self) -> Vec<Frame> {
        let mut d = FrameDecoder::new();
        let mut out = Vec::new();
        d.feed(&self.host.received(), |f| out.push(f));
        out
    }
}

/// PING servo 1, a raw servo packet for transparent mode...
pub const PING: [u8; 6] = [0xFF, 0xFF, 0x01, 0x02, 0x01, 0xFB];
/// ...and the servo's status reply.
pub const PING_REPLY: [u8; 6] = [0xFF, 0xFF, 0x01, 0x02, 0x00, 0xFC];

impl Rig {
    /// The client on `link` sends [`PING`] in transparent mode and the servo answers
    /// [`PING_REPLY`] 50 us after it: returns every byte the Basic has put on the bus so far,
    /// and what the client has received.
    pub fn ping_servo_raw(&mut self, link: LinkId) -> (Vec<u8>, Vec<u8>) {
        self.client(link).send(&PING);
        self.run_us(2_000);
        let sent = self.wire.basic_sent.iter().map(|&(_, b)| b).collect();
        let now = self.now_ns;
        self.wire.inject(now + 50_000, &PING_REPLY);
        self.run_us(1_000);
        (sent, self.client(link).received())
    }
}

/// A frame's wire bytes.
pub fn frame(cmd: u8, data: &[u8]) -> Vec<u8> {
    Frame::new(cmd, data).unwrap().to_bytes().to_vec()
}

/// The frames pymycobot 4.0.7's serial client (`pymycobot.common.read`) would return from
/// `bytes`, one per call, as it parses them: it waits for `FE FE` (two in a row), takes the
/// next byte as LEN (one above 30 is skipped and the byte after it read as LEN), reads LEN
/// bytes and returns the frame if the last one is `FA`; otherwise it goes on waiting for the
/// next `FE FE`, and a call that runs out of bytes returns nothing (its timeout).
pub fn pymycobot_reads(bytes: &[u8]) -> Vec<Vec<u8>> {
    let mut out = Vec::new();
    let mut rest = bytes.iter().copied();
    'calls: loop {
        let mut datas: Vec<u8> = Vec::new();
        let mut data_len: i32 = -1;
        let (mut k, mut pre) = (0usize, 0usize);
        for data in rest.by_ref() {
            k += 1;
            if data_len == 1 && data == 0xFA {
                datas.push(data);
                out.push(datas);
                continue 'calls;
            } else if datas.len() == 2 {
                let len = i32::from(data as i8);
                if !(0..=30).contains(&len) {
                    data_len = -1;
                    continue;
                }
                datas.push(data);
                data_len = len;
            } else if datas.len() > 2 && data_len > 0 {
                datas.push(data);
                data_len -= 1;
            } else if data == 0xFE {
                if datas.is_empty() {
                    datas.push(data);
                    pre = k;
                } else if k - 1 == pre {
                    datas.push(data);
                } else {
                    datas = vec![0xFE];
                    pre = k;
                }
            }
        }
        return out;
    }
}
