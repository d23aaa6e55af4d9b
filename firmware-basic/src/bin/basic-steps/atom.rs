//! The bus as the Basic hears it, inside the image: an Atom that refreshes its servos' state
//! without a pause and answers every host frame the Basic forwards, with the wire's timing.
//!
//! The Atom asks one servo at a time (an 8-byte READ of 31 bytes of state, a 37-byte answer
//! 20 us later) and leaves [`GAP_US`] of quiet after each transaction, as the real one does.
//! A byte from the Basic in that gap holds its next transaction back; a frame from the Basic is
//! answered 50 us after its last byte (`get_angles` with six angles, anything else `01`), and
//! the refresh goes on after the reply. Every byte is readable once it has crossed the wire at
//! 1 Mbaud. The wire does not echo (the Basic finds that out, as on the emulated boards).

use protocol_core::command::cmd;
use protocol_core::servo::{Instruction, Packet};
use protocol_core::timing::{ATOM_TRANSACTION_GAP_US, BUS_BAUD};
use protocol_core::{BytePort, Frame, FrameDecoder};

use crate::line::Line;

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
    wire: Line<RX_BYTES>,
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
            wire: Line::new(BUS_BAUD),
            next_transaction_us: 0,
            next_servo: 1,
            requests: FrameDecoder::new(),
            forwarded: 0,
        }
    }

    /// Lets the wire run to `now_us`: the servo transactions due by then go out.
    pub fn run_to(&mut self, now_us: u64) {
        self.now_us = now_us;
        while self.next_transaction_us <= now_us && self.wire.room() > 64 {
            let start = self.next_transaction_us;
            let id = self.next_servo;
            self.next_servo = if id >= 7 { 1 } else { id + 1 };
            let read = Instruction::Read {
                addr: 40,
                count: 31,
            }
            .to_packet(id);
            let Some(read) = read else { return };
            let asked = self.wire.send(start, &read.to_bytes());
            let state = [0u8; 31];
            let Some(answer) = Packet::new(id, 0, &state) else {
                return;
            };
            let answered = self.wire.send(asked + TURNAROUND_US, &answer.to_bytes());
            self.next_transaction_us = answered + GAP_US;
        }
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
        self.wire.take(self.now_us)
    }

    fn write(&mut self, bytes: &[u8]) {
        // The Basic's bytes cross the wire (no echo); the Atom holds its refresh for them.
        let end = self.wire.occupy(self.now_us, bytes.len());
        self.next_transaction_us = self.next_transaction_us.max(end + GAP_US);
        for &b in bytes {
            let mut found = self.requests.push(b);
            while let Some(frame) = found {
                self.forwarded += 1;
                if let Some(reply) = Self::reply(&frame) {
                    let done = self.wire.send(end + REPLY_AFTER_US, &reply.to_bytes());
                    self.next_transaction_us = done + GAP_US;
                }
                found = self.requests.next_frame();
            }
        }
    }

    fn tx_idle(&self) -> bool {
        self.wire.free(self.now_us)
    }
}
