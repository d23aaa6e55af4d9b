//! A test rig: the Atom, the simulated bus with servos, a USB link and recording IO, under virtual
//! time, with a request/reply helper that behaves like the Basic (waits for a quiet wire).
#![allow(
    dead_code,
    clippy::unwrap_used,
    clippy::expect_used,
    clippy::indexing_slicing
)]

use firmware_atom::{Atom, AtomConfig, RecordingIo};
use protocol_core::Frame;
use protocol_core::timing::BUS_QUIET_BEFORE_SEND_US;

use super::{ArmBus, FakeUsb};

/// Poll period of the rig, microseconds (the contract: at least every 10 us).
pub const TICK_US: u64 = 5;

pub struct Rig {
    pub atom: Atom,
    pub bus: ArmBus,
    pub usb: FakeUsb,
    pub io: RecordingIo,
}

impl Rig {
    /// The default arm, powered, with echo on the bus, after the first refresh rounds.
    pub fn new() -> Self {
        Self::with(
            AtomConfig {
                powered_at_boot: true,
                ..AtomConfig::default()
            },
            true,
        )
    }

    /// An arm with `config` (its servos powered if `config.powered_at_boot`) and the Atom
    /// hearing its own echo if `echo`, after the first refresh rounds.
    pub fn with(config: AtomConfig, echo: bool) -> Self {
        let mut bus = ArmBus::new(echo);
        if config.powered_at_boot {
            bus.power_servos();
        }
        let mut rig = Self {
            atom: Atom::new(config),
            bus,
            usb: FakeUsb::default(),
            io: RecordingIo::default(),
        };
        rig.run_ms(20);
        rig
    }

    pub fn now(&self) -> u64 {
        self.bus.now_us()
    }

    /// Runs the wire and servos for one poll period, then polls the Atom.
    pub fn tick(&mut self) {
        let now = self.now() + TICK_US;
        self.bus.run_until(now * 1_000);
        self.atom
            .poll(now, &mut self.bus.atom_port(), &mut self.usb, &mut self.io);
        self.bus.start_transmissions();
    }

    pub fn run_us(&mut self, us: u64) {
        let end = self.now() + us;
        while self.now() < end {
            self.tick();
        }
    }

    pub fn run_ms(&mut self, ms: u64) {
        self.run_us(ms * 1000);
    }

    /// Sends `frame` on the bus like the Basic (after a quiet wire) and returns the first reply
    /// frame with the time from the request's last byte to the reply's last byte, or `None`
    /// after 600 ms.
    pub fn request_timed(&mut self, frame: &Frame) -> Option<(Frame, u64)> {
        let seen = self.bus.replies.len();
        let mut first_end = None;
        let deadline = self.now() + 600_000;
        'attempt: while self.now() < deadline {
            while self.bus.quiet_us() < BUS_QUIET_BEFORE_SEND_US {
                self.tick();
            }
            let start = self.now();
            let end = self.bus.send_frame(frame);
            first_end.get_or_insert(end);
            while self.now() < deadline {
                self.tick();
                if self.now() <= end + TICK_US && self.another_talked_between(start, end) {
                    // Another station (the Atom, or a servo answering late) talked over the
                    // frame and garbled it: the real Basic sees its echo differ and sends
                    // again once the wire is quiet.
                    while self.now() <= end + 2 * TICK_US {
                        self.tick();
                    }
                    continue 'attempt;
                }
                if let Some(r) = self.bus.replies.get(seen) {
                    let since = first_end.unwrap_or(end);
                    return Some((r.frame.clone(), r.end_us.saturating_sub(since)));
                }
            }
        }
        None
    }

    /// True if the Atom or a servo transmitted while the host's frame was on the wire (a
    /// collision).
    fn another_talked_between(&self, start: u64, end: u64) -> bool {
        self.bus
            .trace
            .iter()
            .rev()
            .take(256)
            .any(|&(t, who, _)| who != 'H' && t > start && t <= end)
    }

    pub fn request(&mut self, frame: &Frame) -> Option<Frame> {
        self.request_timed(frame).map(|(f, _)| f)
    }

    /// Sends a request given as command code and data; returns the reply data.
    pub fn ask(&mut self, cmd: u8, data: &[u8]) -> Vec<u8> {
        let reply = self
            .request(&Frame::new(cmd, data).unwrap())
            .unwrap_or_else(|| panic!("no reply to {cmd:#04x}"));
        assert_eq!(reply.cmd(), cmd, "reply carries the request's CMD");
        reply.data().to_vec()
    }

    /// The int16 values of a reply.
    pub fn ask_i16(&mut self, cmd: u8, data: &[u8]) -> Vec<i16> {
        self.ask(cmd, data)
            .chunks(2)
            .map(|c| i16::from_be_bytes([c[0], c[1]]))
            .collect()
    }
}

/// Big-endian int16 bytes of several values, for building requests.
pub fn be(values: &[i16]) -> Vec<u8> {
    values.iter().flat_map(|v| v.to_be_bytes()).collect()
}
