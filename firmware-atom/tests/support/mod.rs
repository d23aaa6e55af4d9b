//! The Atom's world for tests and the benchmark, built from the simulated hardware of `sim-hw`:
//! the shared 1 Mbaud wire (byte timing, echo, collisions) with seven STS servos on it, and a
//! host (the Basic's side) that sends frames and collects the Atom's replies with their times.
//!
//! What the Atom sent is read back from the wire as every listener heard it: its reply frames,
//! its servo instructions and the goal positions they carry (for the safety checks).
#![allow(
    dead_code,
    clippy::unwrap_used,
    clippy::expect_used,
    clippy::indexing_slicing
)]

use std::collections::VecDeque;

use protocol_core::servo::{BROADCAST_ID, Instruction, Packet, reg, sign_magnitude};
use protocol_core::{BytePort, Frame, FrameDecoder};
use sim_hw::wire::BusPort;
use sim_hw::{Bus, HeardByte, PacketListener, ServoChain, SimServo, StationId};

pub mod rig;

/// Ids of the servos on the arm: joints 1..=6 and the gripper.
pub const SERVO_IDS: std::ops::RangeInclusive<u8> = 1..=7;

/// A reply frame the Atom sent to the host, with the time its last byte ended (us).
#[derive(Clone, Debug)]
pub struct TimedFrame {
    pub frame: Frame,
    pub end_us: u64,
}

/// The wire, the servos and the host side.
pub struct ArmBus {
    wire: Bus,
    now_ns: u64,
    atom: StationId,
    host: StationId,
    /// When the host's transmitter is done with what it was given, ns.
    host_tx_end_ns: u64,
    servos: ServoChain,
    heard: Vec<HeardByte>,
    atom_packets: PacketListener,
    atom_frames: FrameDecoder,
    /// The goal position register of each servo as written on the wire so far (raw bytes).
    goal_bytes: Vec<[u8; 2]>,
    /// Replies the Atom sent to the host.
    pub replies: Vec<TimedFrame>,
    /// Number of servo instructions the Atom sent.
    pub instructions: u64,
    /// Goal positions (steps) the Atom sent to each servo, by index (id - 1), in order.
    pub goals: Vec<Vec<i16>>,
    /// Every byte on the wire: (time it ends in us, who sent it: 'A' Atom, 'H' host, 'S'
    /// servo, as heard).
    pub trace: Vec<(u64, char, u8)>,
}

impl ArmBus {
    /// Seven servos with ids 1..=7 at 2048 with torque off (as at power-up); the Atom hears
    /// its own echo if `echo`.
    pub fn new(echo: bool) -> Self {
        let mut wire = Bus::mycobot(7);
        wire.set_tap(true);
        let atom = wire.attach(echo);
        let host = wire.attach_transmitter();
        let mut servos = ServoChain::new();
        for id in SERVO_IDS {
            servos.attach(&mut wire, SimServo::new(id, 2048));
        }
        Self {
            wire,
            now_ns: 0,
            atom,
            host,
            host_tx_end_ns: 0,
            goal_bytes: servos
                .iter()
                .map(|s| s.goal_position().to_le_bytes())
                .collect(),
            servos,
            heard: Vec::new(),
            atom_packets: PacketListener::default(),
            atom_frames: FrameDecoder::new(),
            replies: Vec::new(),
            instructions: 0,
            goals: vec![Vec::new(); SERVO_IDS.count()],
            trace: Vec::new(),
        }
    }

    /// Virtual time, us.
    pub fn now_us(&self) -> u64 {
        self.now_ns / 1_000
    }

    /// The servo with `id` (1..=7).
    pub fn servo(&mut self, id: u8) -> &mut SimServo {
        self.servos.get_mut(id).unwrap()
    }

    /// Switches every servo's torque on without a word on the wire: an arm powered before the
    /// Atom booted.
    pub fn power_servos(&mut self) {
        let on = Instruction::Write {
            addr: reg::TORQUE_ENABLE,
            data: &[1],
        }
        .to_packet(BROADCAST_ID)
        .unwrap();
        for id in SERVO_IDS {
            self.servo(id).receive(&on, 0);
        }
    }

    /// The Atom's port on the wire.
    pub fn atom_port(&mut self) -> BusPort<'_> {
        self.wire.port(self.atom).unwrap()
    }

    /// Microseconds the wire has been quiet (0 while a byte is on it or queued).
    pub fn quiet_us(&self) -> u64 {
        if self.wire.busy() {
            0
        } else {
            self.now_ns.saturating_sub(self.wire.last_activity_ns()) / 1_000
        }
    }

    /// The host (the Basic) sends `frame` starting now; returns the time its last byte ends.
    pub fn send_frame(&mut self, frame: &Frame) -> u64 {
        self.send_raw(&frame.to_bytes())
    }

    /// The host sends raw bytes starting now (after what it is still sending); returns the
    /// time the last of them ends, us. Whoever else talks meanwhile collides with them.
    pub fn send_raw(&mut self, bytes: &[u8]) -> u64 {
        let start = self.now_ns.max(self.host_tx_end_ns);
        self.host_tx_end_ns = start + bytes.len() as u64 * self.wire.byte_time_ns();
        self.wire.port(self.host).unwrap().write(bytes);
        self.wire.start_transmissions(self.now_ns);
        self.host_tx_end_ns / 1_000
    }

    /// Runs the wire and the servos up to `t_ns`, stopping at every byte end and servo answer.
    pub fn run_until(&mut self, t_ns: u64) {
        while self.now_ns < t_ns {
            let next = [self.servos.next_event_ns(), self.wire.next_event_ns()]
                .into_iter()
                .flatten()
                .fold(t_ns, u64::min)
                .max(self.now_ns + 1);
            self.step(next);
        }
    }

    /// Starts the bytes stations queued at the current instant (call after polling the Atom).
    pub fn start_transmissions(&mut self) {
        self.wire.start_transmissions(self.now_ns);
    }

    fn step(&mut self, now_ns: u64) {
        self.now_ns = now_ns;
        self.wire.deliver(now_ns);
        self.wire.take_heard(&mut self.heard);
        for heard in std::mem::take(&mut self.heard) {
            self.observe(heard);
            self.servos.hear(&heard);
        }
        self.servos.transmit_due(now_ns, &mut self.wire);
        self.wire.start_transmissions(now_ns);
    }

    /// Records a byte heard on the wire; decodes the Atom's replies and instructions.
    fn observe(&mut self, heard: HeardByte) {
        let end_us = heard.end_ns / 1_000;
        let who = if heard.from == self.atom {
            'A'
        } else if heard.from == self.host {
            'H'
        } else {
            'S'
        };
        self.trace.push((end_us, who, heard.byte));
        if heard.from != self.atom {
            return;
        }
        let mut packets = Vec::new();
        self.atom_packets
            .hear(heard.byte, heard.end_ns, |p| packets.push(p));
        for packet in &packets {
            self.on_instruction(packet);
        }
        let replies = &mut self.replies;
        self.atom_frames.feed(&[heard.byte], |frame| {
            replies.push(TimedFrame { frame, end_us });
        });
    }

    /// Counts an instruction and records the goal positions it writes.
    fn on_instruction(&mut self, packet: &Packet) {
        self.instructions += 1;
        let Ok(instr) = Instruction::parse(packet) else {
            return;
        };
        for id in SERVO_IDS {
            let (addr, data) = match instr {
                Instruction::Write { addr, data } | Instruction::RegWrite { addr, data }
                    if packet.id() == id || packet.id() == BROADCAST_ID =>
                {
                    (addr, data)
                }
                Instruction::SyncWrite { addr, .. } => match instr.sync_write_data_for(id) {
                    Some(data) => (addr, data),
                    None => continue,
                },
                _ => continue,
            };
            self.record_goal(id, addr, data);
        }
    }

    fn record_goal(&mut self, id: u8, addr: u8, data: &[u8]) {
        let i = usize::from(id) - 1;
        let mut touched = false;
        for (offset, slot) in self.goal_bytes[i].iter_mut().enumerate() {
            let a = usize::from(reg::GOAL_POSITION) + offset;
            if let Some(&b) = a.checked_sub(usize::from(addr)).and_then(|k| data.get(k)) {
                *slot = b;
                touched = true;
            }
        }
        if touched {
            let goal = sign_magnitude(u16::from_le_bytes(self.goal_bytes[i]), 15);
            self.goals[i].push(goal);
        }
    }
}

/// A host link (the Atom's USB serial) under test control: frames in, replies out.
#[derive(Default)]
pub struct FakeUsb {
    pub incoming: VecDeque<u8>,
    decoder: FrameDecoder,
    pub replies: Vec<Frame>,
}

impl FakeUsb {
    pub fn send_frame(&mut self, frame: &Frame) {
        self.incoming.extend(frame.to_bytes().iter().copied());
    }
}

impl BytePort for FakeUsb {
    fn read_byte(&mut self) -> Option<u8> {
        self.incoming.pop_front()
    }

    fn write(&mut self, bytes: &[u8]) {
        let mut frames = Vec::new();
        self.decoder.feed(bytes, |f| frames.push(f));
        self.replies.extend(frames);
    }

    fn tx_idle(&self) -> bool {
        true
    }
}
