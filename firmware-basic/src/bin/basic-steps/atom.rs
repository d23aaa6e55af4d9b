//! The bus as the Basic hears it, inside the image: an Atom that refreshes its servos' state
//! without a pause and answers every host frame the Basic forwards, with the wire's timing.
//!
//! The Atom asks one servo at a time (an 8-byte READ of 31 bytes of state, a 37-byte answer
//! 20 us later) and leaves [`GAP_US`] of quiet after each transaction, as the real one does.
//! A byte from the Basic in that gap holds its next transaction back; a frame from the Basic is
//! answered 50 us after its last byte (`get_angles` with six angles, anything else `01`), and
//! the refresh goes on after the reply. Every byte is readable once it has crossed the wire at
//! 1 Mbaud. The wire does not echo (the Basic finds that out, as on the emulated boards).

use heapless::Deque;
use protocol_core::command::cmd;
use protocol_core::servo::{Instruction, Packet};
use protocol_core::timing::{ATOM_TRANSACTION_GAP_US, BUS_BAUD, wire_time_us};
use protocol_core::{BytePort, Frame, FrameDecoder};

/// The Atom's quiet time after each servo transaction.
const GAP_US: u64 = ATOM_TRANSACTION_GAP_US;
/// A servo's turnaround before its answer.
const TURNAROUND_US: u64 = 20;
/// The Atom's time from a request's last byte to its reply.
const REPLY_AFTER_US: u64 = 50;
/// Bytes on their way to the Basic.
const RX_BYTES: usize = 512;

/// The wire with the Atom and its servos on it. See the [module doc](self).
pub struct AtomBus {
    now_us: u64,
    /// Bytes for the Basic, each with the time its last bit is in.
    rx: Deque<(u64, u8), RX_BYTES>,
    /// When the wire is free again.
    busy_until_us: u64,
    /// When the Atom starts its next servo transaction.
    next_transaction_us: u64,
    next_servo: u8,
    requests: FrameDecoder,
    /// Frames the Basic forwarded.
    pub forwarded: u32,
}

impl AtomBus {
    /// A bus with the Atom's refresh starting at once.
    pub fn new() -> Self {
        Self {
            now_us: 0,
            rx: Deque::new(),
            busy_until_us: 0,
            next_transaction_us: 0,
            next_servo: 1,
            requests: FrameDecoder::new(),
            forwarded: 0,
        }
    }

    /// Lets the wire run to `now_us`: the servo transactions due by then go out.
    pub fn run_to(&mut self, now_us: u64) {
        self.now_us = now_us;
        while self.next_transaction_us <= now_us && self.rx.len() + 64 < RX_BYTES {
            let start = self.next_transaction_us;
            let id = self.next_servo;
            self.next_servo = if id >= 7 { 1 } else { id + 1 };
            let read = Instruction::Read {
                addr: 40,
                count: 31,
            }
            .to_packet(id);
            let Some(read) = read else { return };
            let asked = self.send(start, &read.to_bytes());
            let state = [0u8; 31];
            let Some(answer) = Packet::new(id, 0, &state) else {
                return;
            };
            let answered = self.send(asked + TURNAROUND_US, &answer.to_bytes());
            self.next_transaction_us = answered + GAP_US;
        }
    }

    /// Puts `bytes` on the wire from `start_us` (or when it is free); when the last is in.
    fn send(&mut self, start_us: u64, bytes: &[u8]) -> u64 {
        let mut t = start_us.max(self.busy_until_us);
        for &b in bytes {
            t += wire_time_us(1, BUS_BAUD);
            self.rx.push_back((t, b)).ok();
        }
        self.busy_until_us = t;
        t
    }

    /// The Atom's reply to a forwarded frame.
    fn reply(request: &Frame) -> Option<Frame> {
        if request.cmd() == cmd::GET_ANGLES {
            Frame::new(
                cmd::GET_ANGLES,
                &[
                    0x03, 0xE8, 0xF4, 0x48, 0xEC, 0x78, 0xFC, 0x18, 0x03, 0xE8, 0x07, 0xD0,
                ],
            )
        } else {
            Frame::new(request.cmd(), &[1])
        }
    }
}

impl BytePort for AtomBus {
    fn read_byte(&mut self) -> Option<u8> {
        match self.rx.front() {
            Some(&(due, b)) if due <= self.now_us => {
                self.rx.pop_front();
                Some(b)
            }
            _ => None,
        }
    }

    fn write(&mut self, bytes: &[u8]) {
        // The Basic's bytes cross the wire (no echo); the Atom holds its refresh for them.
        let start = self.now_us.max(self.busy_until_us);
        let end = start + wire_time_us(bytes.len() as u32, BUS_BAUD);
        self.busy_until_us = end;
        self.next_transaction_us = self.next_transaction_us.max(end + GAP_US);
        for &b in bytes {
            let mut found = self.requests.push(b);
            while let Some(frame) = found {
                self.forwarded += 1;
                if let Some(reply) = Self::reply(&frame) {
                    let done = self.send(end + REPLY_AFTER_US, &reply.to_bytes());
                    self.next_transaction_us = done + GAP_US;
                }
                found = self.requests.next_frame();
            }
        }
    }

    fn tx_idle(&self) -> bool {
        self.now_us >= self.busy_until_us
    }
}
