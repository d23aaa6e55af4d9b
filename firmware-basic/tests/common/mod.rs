//! A simulated Basic board for tests and benchmarks: a host link and a shared bus with byte
//! timing, a scripted Atom, other stations that inject traffic, and virtual time.
//!
//! The bus is modelled as a list of byte transmissions with start and end times. Two
//! transmissions that overlap corrupt each other (every listener hears the byte XOR 0xA5).
//! The Basic hears everything the others send, and its own bytes when `echo` is on.
#![allow(dead_code, clippy::unwrap_used, clippy::indexing_slicing)]

use std::cell::RefCell;
use std::collections::VecDeque;
use std::rc::Rc;

use firmware_basic::{Basic, BasicConfig, BasicIo, Buttons};
use protocol_core::{BytePort, Frame, FrameDecoder, timing};

/// Nanoseconds of one byte on the bus.
pub const BUS_BYTE_NS: u64 = timing::wire_time_ns(1, timing::BUS_BAUD);
/// Nanoseconds of one byte on the host link.
pub const HOST_BYTE_NS: u64 = timing::wire_time_ns(1, timing::HOST_BAUD);

/// Who put a byte on the bus.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Station {
    /// The Basic under test.
    Basic,
    /// Anyone else (the Atom, servos, noise).
    Other,
}

#[derive(Clone, Copy, Debug)]
struct Tx {
    station: Station,
    start_ns: u64,
    byte: u8,
    heard_by_basic: bool,
    heard_by_atom: bool,
}

impl Tx {
    fn end_ns(&self) -> u64 {
        self.start_ns + BUS_BYTE_NS
    }
}

/// The shared wire.
#[derive(Default)]
pub struct Wire {
    now_ns: u64,
    txs: Vec<Tx>,
    /// Whether the Basic hears its own bytes.
    pub echo: bool,
    basic_rx: VecDeque<u8>,
    basic_tx_busy_until_ns: u64,
    /// Bytes the Basic transmitted, with their start time in ns.
    pub basic_sent: Vec<(u64, u8)>,
    /// Bytes the Atom heard from others, for its decoder.
    atom_rx: VecDeque<(u64, u8)>,
    /// End time (ns) of the last byte anybody sent.
    last_end_ns: u64,
}

impl Wire {
    /// Schedules `bytes` from another station, back to back from `start_ns`.
    pub fn inject(&mut self, start_ns: u64, bytes: &[u8]) {
        for (i, &byte) in bytes.iter().enumerate() {
            self.push_tx(Tx {
                station: Station::Other,
                start_ns: start_ns + i as u64 * BUS_BYTE_NS,
                byte,
                heard_by_basic: false,
                heard_by_atom: true,
            });
        }
    }

    fn push_tx(&mut self, tx: Tx) {
        self.last_end_ns = self.last_end_ns.max(tx.end_ns());
        let pos = self.txs.partition_point(|t| t.start_ns <= tx.start_ns);
        self.txs.insert(pos, tx);
    }

    /// What a listener hears for transmission `i`: the byte, or garbage if it overlapped.
    fn heard(&self, i: usize) -> u8 {
        let t = self.txs[i];
        let overlaps = self
            .txs
            .iter()
            .enumerate()
            .any(|(j, o)| j != i && o.start_ns < t.end_ns() && t.start_ns < o.end_ns());
        if overlaps { t.byte ^ 0xA5 } else { t.byte }
    }

    /// Moves every byte whose end has passed to its listeners.
    fn advance(&mut self, now_ns: u64) {
        self.now_ns = now_ns;
        for i in 0..self.txs.len() {
            let t = self.txs[i];
            if t.end_ns() > now_ns {
                // Sorted by start and all the same length, so sorted by end too.
                break;
            }
            if !t.heard_by_basic {
                self.txs[i].heard_by_basic = true;
                if t.station == Station::Other || self.echo {
                    let b = self.heard(i);
                    self.basic_rx.push_back(b);
                }
            }
            if !t.heard_by_atom {
                self.txs[i].heard_by_atom = true;
                let b = self.heard(i);
                self.atom_rx.push_back((t.end_ns(), b));
            }
        }
        // Forget bytes long past: nothing new can overlap them.
        let horizon = now_ns.saturating_sub(10 * BUS_BYTE_NS);
        let keep_from = self
            .txs
            .iter()
            .position(|t| t.end_ns() > horizon || !t.heard_by_basic || !t.heard_by_atom)
            .unwrap_or(self.txs.len());
        self.txs.drain(..keep_from);
    }

    /// The first time from `from_ns` at which the Atom can put `n` bytes on the wire without
    /// touching traffic already scheduled: it leaves the quiet time around other stations'
    /// traffic, and may answer the Basic right after its request.
    pub fn free_slot(&self, from_ns: u64, n: usize) -> u64 {
        let mut start = from_ns;
        loop {
            let end = start + n as u64 * BUS_BYTE_NS;
            let clash = self
                .txs
                .iter()
                .filter(|t| {
                    let quiet_ns = match t.station {
                        Station::Basic => 0,
                        Station::Other => timing::BUS_QUIET_BEFORE_SEND_US * 1_000,
                    };
                    t.start_ns < end + quiet_ns && start < t.end_ns() + quiet_ns
                })
                .map(Tx::end_ns)
                .max();
            match clash {
                Some(busy_until) => start = busy_until + timing::BUS_QUIET_BEFORE_SEND_US * 1_000,
                None => return start,
            }
        }
    }

    /// Time the wire has been silent, in ns (0 while somebody transmits).
    pub fn quiet_ns(&self) -> u64 {
        self.now_ns.saturating_sub(self.last_end_ns)
    }
}

/// The Basic's bus port: a view of the shared wire.
#[derive(Clone, Default)]
pub struct BusPort(pub Rc<RefCell<Wire>>);

impl BytePort for BusPort {
    fn read_byte(&mut self) -> Option<u8> {
        self.0.borrow_mut().basic_rx.pop_front()
    }

    fn write(&mut self, bytes: &[u8]) {
        let mut w = self.0.borrow_mut();
        let start = w.now_ns.max(w.basic_tx_busy_until_ns);
        for (i, &byte) in bytes.iter().enumerate() {
            let start_ns = start + i as u64 * BUS_BYTE_NS;
            w.basic_sent.push((start_ns, byte));
            w.push_tx(Tx {
                station: Station::Basic,
                start_ns,
                byte,
                heard_by_basic: false,
                heard_by_atom: false,
            });
        }
        w.basic_tx_busy_until_ns = start + bytes.len() as u64 * BUS_BYTE_NS;
    }

    fn tx_idle(&self) -> bool {
        let w = self.0.borrow();
        w.now_ns >= w.basic_tx_busy_until_ns
    }
}

/// The host side: what the host sends (with 115200 timing) and what the Basic wrote.
#[derive(Default)]
pub struct HostPort {
    now_ns: u64,
    to_basic: VecDeque<(u64, u8)>,
    tx_busy_until_ns: u64,
    /// Bytes the Basic wrote, with the time (ns) each started on the wire.
    pub from_basic: Vec<(u64, u8)>,
}

impl HostPort {
    /// Queues `bytes` from the host, back to back after whatever is queued, from `now`;
    /// returns when the last of them has arrived, in ns.
    pub fn send(&mut self, bytes: &[u8]) -> u64 {
        let mut end = self
            .to_basic
            .back()
            .map_or(self.now_ns, |&(end, _)| end.max(self.now_ns));
        for &b in bytes {
            end += HOST_BYTE_NS;
            self.to_basic.push_back((end, b));
        }
        end
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
            self.from_basic.push((start + i as u64 * HOST_BYTE_NS, b));
        }
        self.tx_busy_until_ns = start + bytes.len() as u64 * HOST_BYTE_NS;
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

/// The Basic, its ports and a scripted Atom on one simulated wire.
pub struct Rig {
    /// The firmware under test.
    pub basic: Basic,
    /// The host link.
    pub host: HostPort,
    /// The Basic's view of the bus.
    pub bus: BusPort,
    /// The Basic's pins.
    pub io: MemIo,
    /// Virtual time, ns.
    pub now_ns: u64,
    /// Poll period, ns.
    pub step_ns: u64,
    atom_decoder: FrameDecoder,
    /// Frames the Atom received intact, with the time (ns) their last byte ended.
    pub atom_got: Vec<(u64, Frame)>,
    /// The Atom's replies: when each started on the wire (ns) and its bytes.
    pub atom_sent: Vec<(u64, Vec<u8>)>,
    /// How the Atom answers.
    pub atom: Responder,
    /// Time from the end of a request to the start of the Atom's answer, ns.
    pub atom_delay_ns: u64,
    atom_last_rx_ns: u64,
}

impl Rig {
    /// A rig with `config`, an echoing or silent wire, and an Atom that acks everything.
    pub fn new(config: BasicConfig, echo: bool) -> Self {
        let bus = BusPort::default();
        bus.0.borrow_mut().echo = echo;
        Self {
            basic: Basic::new(config),
            host: HostPort::default(),
            bus,
            io: MemIo::default(),
            now_ns: 0,
            step_ns: 1_000,
            atom_decoder: FrameDecoder::new(),
            atom_got: Vec::new(),
            atom_sent: Vec::new(),
            atom: ack_everything(),
            atom_delay_ns: 200_000,
            atom_last_rx_ns: 0,
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
    pub fn wire(&self) -> std::cell::RefMut<'_, Wire> {
        self.bus.0.borrow_mut()
    }

    /// One poll at the current time, then time moves on by one step.
    pub fn step(&mut self) {
        self.wire().advance(self.now_ns);
        self.host.now_ns = self.now_ns;
        self.run_atom();
        self.basic.poll(
            self.now_ns / 1_000,
            &mut self.host,
            &mut self.bus,
            &mut self.io,
        );
        self.now_ns += self.step_ns;
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
        let heard: Vec<(u64, u8)> = self.wire().atom_rx.drain(..).collect();
        let mut frames = Vec::new();
        for (at, b) in heard {
            if at.saturating_sub(self.atom_last_rx_ns) > timing::BUS_FRAME_GAP_US * 1_000 {
                while self.atom_decoder.on_quiet_line().is_some() {}
            }
            self.atom_last_rx_ns = at;
            self.atom_decoder.feed(&[b], |f| frames.push((at, f)));
        }
        for (at, frame) in frames {
            self.atom_got.push((at, frame.clone()));
            if let Some(reply) = (self.atom)(&frame) {
                let start = self.wire().free_slot(at + self.atom_delay_ns, reply.len());
                self.wire().inject(start, &reply);
                self.atom_sent.push((start, reply));
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

/// A frame's wire bytes.
pub fn frame(cmd: u8, data: &[u8]) -> Vec<u8> {
    Frame::new(cmd, data).unwrap().to_bytes().to_vec()
}
