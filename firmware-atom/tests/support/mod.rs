//! A small fake of the Atom's world for tests and the benchmark: a shared 1 Mbaud wire under
//! virtual time with seven simple STS servos on it, and a host (the Basic's side) that sends
//! frames and collects the Atom's replies with their timestamps.
//!
//! Servos answer PING, READ, WRITE, SYNC READ and SYNC WRITE; they move toward their goal at
//! the goal speed. A servo can be removed, made to drop answers, or to corrupt checksums.
//! Bytes are not corrupted by overlap (the root package's simulator models that).
#![allow(
    dead_code,
    clippy::unwrap_used,
    clippy::expect_used,
    clippy::indexing_slicing
)]

use std::collections::VecDeque;

use protocol_core::servo::{
    Instruction, Packet, PacketDecoder, reg, sign_magnitude, to_sign_magnitude,
};
use protocol_core::{BytePort, Frame, FrameDecoder};

/// Wire time of one byte at 1 Mbaud, microseconds.
pub const BYTE_US: u64 = 10;
/// Servo turnaround in this fake, microseconds (below SERVO_TURNAROUND_MAX_US).
pub const TURNAROUND_US: u64 = 20;

/// One fake STS servo.
#[derive(Clone, Debug)]
pub struct FakeServo {
    pub id: u8,
    pub table: [u8; reg::TABLE_SIZE],
    /// Exact position (steps, fractional while moving).
    pub position: f64,
    pub present: bool,
    /// Answers to drop from now on (counted down).
    pub drop_answers: u32,
    /// Answers to send with a wrong checksum (counted down).
    pub corrupt_answers: u32,
    /// Instructions to ignore from now on (counted down): a write lost in a collision.
    pub deaf_to: u32,
    /// Goals received (position register writes), for the safety checks.
    pub goals: Vec<i16>,
    pub last_update_us: u64,
}

impl FakeServo {
    pub fn new(id: u8) -> Self {
        let mut table = [0u8; reg::TABLE_SIZE];
        table[reg::ID as usize] = id;
        table[reg::STATUS_RETURN_LEVEL as usize] = 1;
        table[reg::TORQUE_ENABLE as usize] = 1;
        table[reg::PRESENT_VOLTAGE as usize] = 120;
        table[reg::PRESENT_TEMPERATURE as usize] = 31;
        table[reg::EEPROM_LOCK as usize] = 1;
        let mut s = Self {
            id,
            table,
            position: 2048.0,
            present: true,
            drop_answers: 0,
            corrupt_answers: 0,
            deaf_to: 0,
            goals: Vec::new(),
            last_update_us: 0,
        };
        s.set_u16(reg::GOAL_POSITION, 2048);
        s.refresh_present();
        s
    }

    fn u16_at(&self, addr: u8) -> u16 {
        u16::from_le_bytes([self.table[addr as usize], self.table[addr as usize + 1]])
    }

    fn set_u16(&mut self, addr: u8, v: u16) {
        let [lo, hi] = v.to_le_bytes();
        self.table[addr as usize] = lo;
        self.table[addr as usize + 1] = hi;
    }

    pub fn goal(&self) -> i16 {
        sign_magnitude(self.u16_at(reg::GOAL_POSITION), 15)
    }

    pub fn torque_on(&self) -> bool {
        self.table[reg::TORQUE_ENABLE as usize] != 0
    }

    /// Moves toward the goal at the goal speed (0 = 3400 steps/s, the STS maximum).
    pub fn advance(&mut self, now_us: u64) {
        let dt = now_us.saturating_sub(self.last_update_us) as f64 / 1e6;
        self.last_update_us = now_us;
        let mut moving = false;
        if self.torque_on() {
            let speed = match sign_magnitude(self.u16_at(reg::GOAL_SPEED), 15).unsigned_abs() {
                0 => 3400.0,
                v => f64::from(v),
            };
            let goal = f64::from(self.goal());
            let step = speed * dt;
            let diff = goal - self.position;
            if diff.abs() <= step {
                self.position = goal;
            } else {
                self.position += step.copysign(diff);
                moving = true;
            }
        }
        self.table[reg::MOVING as usize] = u8::from(moving);
        self.refresh_present();
    }

    fn refresh_present(&mut self) {
        let p = self.position.round() as i16;
        self.set_u16(reg::PRESENT_POSITION, to_sign_magnitude(p, 15));
    }

    /// Applies an instruction; returns the status packet to send back, if any.
    fn execute(&mut self, instr: &Instruction, now_us: u64) -> Option<Packet> {
        self.advance(now_us);
        let reply_all = self.table[reg::STATUS_RETURN_LEVEL as usize] == 1;
        let err = self.table[reg::STATUS as usize];
        match *instr {
            Instruction::Ping => Packet::new(self.id, err, &[]),
            Instruction::Read { addr, count } => {
                let a = addr as usize;
                let data = self.table.get(a..a + count as usize)?;
                Packet::new(self.id, err, data)
            }
            Instruction::Write { addr, data } => {
                self.write(addr, data);
                reply_all.then(|| Packet::new(self.id, err, &[])).flatten()
            }
            _ => None,
        }
    }

    fn write(&mut self, addr: u8, data: &[u8]) {
        for (i, &b) in data.iter().enumerate() {
            let a = addr as usize + i;
            if a >= reg::TABLE_SIZE {
                break;
            }
            if a == reg::TORQUE_ENABLE as usize && b == 128 {
                // Calibration: the present position becomes 2048.
                self.position = 2048.0;
                self.set_u16(reg::GOAL_POSITION, 2048);
                self.refresh_present();
                continue;
            }
            self.table[a] = b;
        }
        let goal_range = reg::GOAL_POSITION..reg::GOAL_POSITION + 2;
        if goal_range.contains(&addr)
            || (addr..addr + data.len() as u8).contains(&reg::GOAL_POSITION)
        {
            let g = self.goal();
            self.goals.push(g);
        }
    }
}

/// A byte on its way to the Atom, and when it arrives.
#[derive(Clone, Copy, Debug)]
struct Timed {
    at_us: u64,
    byte: u8,
}

/// A reply frame the Atom sent to the host, with the time its last byte left.
#[derive(Clone, Debug)]
pub struct TimedFrame {
    pub frame: Frame,
    pub end_us: u64,
}

/// The wire, the servos and the host side.
pub struct FakeBus {
    pub now_us: u64,
    pub servos: Vec<FakeServo>,
    /// Whether the Atom hears its own transmissions.
    pub echo: bool,
    to_atom: VecDeque<Timed>,
    /// When the wire is free again (last scheduled byte's end).
    wire_free_us: u64,
    /// When the Atom's transmitter is done.
    atom_tx_end_us: u64,
    instr_decoder: PacketDecoder,
    reply_decoder: FrameDecoder,
    /// Replies the Atom sent to the host.
    pub replies: Vec<TimedFrame>,
    /// Number of servo transactions (instructions) the Atom sent.
    pub instructions: u64,
    /// Times at which each servo's state block was read (servo index, time).
    pub state_reads: Vec<(usize, u64)>,
    /// Every byte on the wire: (time it ends, who sent it: 'A' Atom, 'H' host, 'S' servo).
    pub trace: Vec<(u64, char, u8)>,
}

impl FakeBus {
    /// Seven servos with ids 1..=7 at 2048, echo on or off.
    pub fn new(echo: bool) -> Self {
        Self {
            now_us: 0,
            servos: (1..=7).map(FakeServo::new).collect(),
            echo,
            to_atom: VecDeque::new(),
            wire_free_us: 0,
            atom_tx_end_us: 0,
            instr_decoder: PacketDecoder::new(),
            reply_decoder: FrameDecoder::new(),
            replies: Vec::new(),
            instructions: 0,
            state_reads: Vec::new(),
            trace: Vec::new(),
        }
    }

    pub fn servo(&mut self, id: u8) -> &mut FakeServo {
        &mut self.servos[id as usize - 1]
    }

    /// Microseconds the wire has been quiet at `now_us`.
    pub fn quiet_us(&self) -> u64 {
        self.now_us.saturating_sub(self.wire_free_us)
    }

    /// The host (the Basic) sends `frame` starting now; returns the time its last byte ends.
    pub fn send_frame(&mut self, frame: &Frame) -> u64 {
        self.send_raw(&frame.to_bytes())
    }

    /// Sends raw bytes to the Atom starting now (or when the wire frees up).
    pub fn send_raw(&mut self, bytes: &[u8]) -> u64 {
        let mut t = self.now_us.max(self.wire_free_us);
        for &b in bytes {
            t += BYTE_US;
            self.to_atom.push_back(Timed { at_us: t, byte: b });
            self.trace.push((t, 'H', b));
        }
        self.wire_free_us = self.wire_free_us.max(t);
        self.sort();
        t
    }

    fn sort(&mut self) {
        self.to_atom.make_contiguous().sort_by_key(|t| t.at_us);
    }

    /// Advances every servo's motion to the current time.
    pub fn advance_servos(&mut self) {
        let now = self.now_us;
        for s in &mut self.servos {
            s.advance(now);
        }
    }

    fn on_instruction(&mut self, packet: &Packet, end_us: u64) {
        self.instructions += 1;
        let Ok(instr) = Instruction::parse(packet) else {
            return;
        };
        let mut answer_at = end_us + TURNAROUND_US;
        let mut answers: Vec<Packet> = Vec::new();
        match instr {
            Instruction::SyncWrite { .. } => {
                for s in &mut self.servos {
                    if let Some(data) = instr.sync_write_data_for(s.id)
                        && s.present
                    {
                        if s.deaf_to > 0 {
                            s.deaf_to -= 1;
                            continue;
                        }
                        let addr = match instr {
                            Instruction::SyncWrite { addr, .. } => addr,
                            _ => unreachable!(),
                        };
                        s.advance(end_us);
                        s.write(addr, data);
                    }
                }
            }
            Instruction::SyncRead { addr, count, ids } => {
                for &id in ids {
                    let read = Instruction::Read { addr, count };
                    if let Some(s) = self.servos.iter_mut().find(|s| s.id == id && s.present)
                        && let Some(p) = s.execute(&read, end_us)
                    {
                        answers.push(p);
                    }
                }
            }
            _ => {
                let id = packet.id();
                if let Instruction::Read { addr, .. } = instr
                    && addr <= reg::STATE_BLOCK
                {
                    self.state_reads.push((id as usize - 1, end_us));
                }
                if let Some(s) = self.servos.iter_mut().find(|s| s.id == id && s.present)
                    && matches!(instr, Instruction::Write { .. })
                    && s.deaf_to > 0
                {
                    s.deaf_to -= 1;
                } else if let Some(s) = self.servos.iter_mut().find(|s| s.id == id && s.present)
                    && let Some(p) = s.execute(&instr, end_us)
                {
                    if s.drop_answers > 0 {
                        s.drop_answers -= 1;
                    } else {
                        let mut bytes = p.to_bytes();
                        if s.corrupt_answers > 0 {
                            s.corrupt_answers -= 1;
                            let last = bytes.len() - 1;
                            bytes[last] ^= 0x5A;
                        }
                        for b in bytes {
                            answer_at += BYTE_US;
                            self.trace.push((answer_at, 'S', b));
                            self.to_atom.push_back(Timed {
                                at_us: answer_at,
                                byte: b,
                            });
                        }
                    }
                }
            }
        }
        for p in answers {
            for b in p.to_bytes() {
                answer_at += BYTE_US;
                self.to_atom.push_back(Timed {
                    at_us: answer_at,
                    byte: b,
                });
            }
        }
        self.wire_free_us = self.wire_free_us.max(answer_at);
        self.sort();
    }
}

impl BytePort for FakeBus {
    fn read_byte(&mut self) -> Option<u8> {
        match self.to_atom.front() {
            Some(t) if t.at_us <= self.now_us => self.to_atom.pop_front().map(|t| t.byte),
            _ => None,
        }
    }

    fn write(&mut self, bytes: &[u8]) {
        let mut t = self.now_us.max(self.atom_tx_end_us);
        for &b in bytes {
            t += BYTE_US;
            self.trace.push((t, 'A', b));
            if self.echo {
                self.to_atom.push_back(Timed { at_us: t, byte: b });
            }
            let mut packets = Vec::new();
            self.instr_decoder.feed(&[b], |p| packets.push(p));
            for p in packets {
                self.on_instruction(&p, t);
            }
            let mut frames = Vec::new();
            self.reply_decoder.feed(&[b], |f| frames.push(f));
            for frame in frames {
                self.replies.push(TimedFrame { frame, end_us: t });
            }
        }
        self.atom_tx_end_us = t;
        self.wire_free_us = self.wire_free_us.max(t);
        self.sort();
    }

    fn tx_idle(&self) -> bool {
        self.now_us >= self.atom_tx_end_us
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
pub mod rig;
