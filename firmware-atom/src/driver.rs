//! The servo driver: one transaction at a time on the shared bus, each with a deadline.
//!
//! A transaction is one instruction packet and, for PING and READ, the one status packet that
//! answers it. The driver sends the instruction, matches the answer by servo id and reports
//! the outcome; retries and the gap between transactions are the callers' decisions (the servo
//! bank keeps a timed-out operation queued for a bounded number of retries, and the bus
//! schedule waits
//! [`ATOM_TRANSACTION_GAP_US`](protocol_core::timing::ATOM_TRANSACTION_GAP_US) of silence).

use heapless::Vec;
use protocol_core::BytePort;
use protocol_core::servo::{BROADCAST_ID, Instruction, Packet};
use protocol_core::timing::{BUS_BAUD, SERVO_TURNAROUND_MAX_US, wire_time_us};

use protocol_core::listener::Listener;

/// Most data bytes one WRITE carries: the parameter block a restore writes (registers 9..=39,
/// 31 bytes) is the largest the Atom writes.
pub const MAX_WRITE: usize = 32;

/// One servo transaction.
#[derive(Clone, Debug, PartialEq, Eq)]
pub enum Op {
    /// Is servo `id` there?
    Ping {
        /// Servo id.
        id: u8,
    },
    /// Read `count` bytes at `addr` of servo `id`.
    Read {
        /// Servo id.
        id: u8,
        /// First register.
        addr: u8,
        /// Number of bytes.
        count: u8,
    },
    /// Write `data` at `addr` of servo `id`. The answer is optional (status return level 0
    /// servos stay silent): its absence is not an error.
    Write {
        /// Servo id.
        id: u8,
        /// First register.
        addr: u8,
        /// Bytes to write.
        data: Vec<u8, MAX_WRITE>,
    },
    /// A broadcast instruction (SYNC WRITE): nobody answers.
    Broadcast(Packet),
}

impl Op {
    /// A WRITE of `data` at `addr`; `None` if `data` is longer than [`MAX_WRITE`].
    pub fn write(id: u8, addr: u8, data: &[u8]) -> Option<Self> {
        Some(Self::Write {
            id,
            addr,
            data: Vec::from_slice(data).ok()?,
        })
    }

    /// The servo this transaction addresses ([`BROADCAST_ID`] for a broadcast).
    pub fn id(&self) -> u8 {
        match self {
            Self::Ping { id } | Self::Read { id, .. } | Self::Write { id, .. } => *id,
            Self::Broadcast(_) => BROADCAST_ID,
        }
    }

    fn packet(&self) -> Option<Packet> {
        match self {
            Self::Ping { id } => Instruction::Ping.to_packet(*id),
            Self::Read { id, addr, count } => Instruction::Read {
                addr: *addr,
                count: *count,
            }
            .to_packet(*id),
            Self::Write { id, addr, data } => {
                Instruction::Write { addr: *addr, data }.to_packet(*id)
            }
            Self::Broadcast(p) => Some(p.clone()),
        }
    }

    /// Number of data bytes the answer carries, if one is expected.
    fn answer_data_len(&self) -> Option<u8> {
        match self {
            Self::Ping { .. } => Some(0),
            Self::Read { count, .. } => Some(*count),
            Self::Write { id, .. } if *id != BROADCAST_ID => Some(0),
            Self::Write { .. } | Self::Broadcast(_) => None,
        }
    }

    fn answer_required(&self) -> bool {
        matches!(self, Self::Ping { .. } | Self::Read { .. })
    }
}

/// How a transaction ended.
#[derive(Clone, Debug, PartialEq, Eq)]
pub enum Outcome {
    /// The servo answered (PING, READ, WRITE with status return level 1).
    Answered(Packet),
    /// Done without an answer (broadcast, or a WRITE to a silent servo).
    Sent,
    /// The servo did not answer with a valid packet before the deadline.
    TimedOut,
}

/// The transaction in flight.
#[derive(Clone, Debug)]
struct InFlight {
    op: Op,
    /// When its instruction was written.
    sent_us: u64,
    deadline_us: u64,
}

/// How long after its deadline the answer to a READ is still awaited and taken, if it comes
/// whole: a servo that answers late (its return delay, a busy servo) or an answer held up on
/// its way (an emulated board's socket) is still the servo's state, read after the instruction
/// went out. Meanwhile the Atom starts nothing on the wire (the driver stays busy), so a late
/// answer never meets the Atom's next instruction, and an answer is never taken for a later
/// question. A servo that does not answer at all costs its round this much more; a lost servo
/// is read only every 8th round. Shorter than the bank's read slack (10 ms), so an answer dated
/// when it was asked never looks faster than the servo can turn.
pub const LATE_ANSWER_WINDOW_US: u64 = 5_000;

/// A READ that timed out, whose answer is taken until `until_us` if it comes whole.
#[derive(Clone, Debug)]
struct Overdue {
    op: Op,
    sent_us: u64,
    until_us: u64,
}

/// A servo packet the driver took: the answer to the transaction in flight, or the late
/// answer to a READ that timed out ([`LATE_ANSWER_WINDOW_US`]).
#[derive(Clone, Debug, PartialEq, Eq)]
pub enum Taken {
    /// The transaction in flight ended.
    Finished(Op, Outcome),
    /// A READ that timed out was answered after all; `sent_us`: when its instruction went out
    /// (the state it carries was read after that).
    Late {
        /// The READ.
        op: Op,
        /// Its answer.
        answer: Packet,
        /// When its instruction was written.
        sent_us: u64,
    },
}

/// Runs one servo transaction at a time.
#[derive(Clone, Debug, Default)]
pub struct ServoDriver {
    in_flight: Option<InFlight>,
    /// The READ that timed out last, while its answer is still awaited.
    overdue: Option<Overdue>,
    reply_margin_us: u64,
}

impl ServoDriver {
    /// A driver that allows `reply_margin_us` beyond the computed answer time.
    pub fn new(reply_margin_us: u64) -> Self {
        Self {
            in_flight: None,
            overdue: None,
            reply_margin_us,
        }
    }

    /// True while a transaction is in flight, or the answer to a READ that timed out is still
    /// awaited ([`LATE_ANSWER_WINDOW_US`]).
    pub fn busy(&self) -> bool {
        self.in_flight.is_some() || self.overdue.is_some()
    }

    /// Sends `op`'s instruction at `now_us`. `false` (and nothing sent) if a transaction is
    /// already in flight or the op cannot be encoded.
    pub fn start<B: BytePort>(
        &mut self,
        now_us: u64,
        op: Op,
        bus: &mut B,
        rx: &mut Listener,
    ) -> bool {
        if self.busy() {
            return false;
        }
        let Some(packet) = op.packet() else {
            return false;
        };
        let bytes = packet.to_bytes();
        bus.write(&bytes);
        rx.on_transmit(now_us, &bytes);
        // The instruction may follow other bytes still going out (a host reply).
        let sent_us = rx
            .busy_until_us()
            .max(now_us + wire_time_us(bytes.len() as u32, BUS_BAUD));
        let answer_us = op
            .answer_data_len()
            .map(|n| SERVO_TURNAROUND_MAX_US + wire_time_us(u32::from(n) + 6, BUS_BAUD))
            .unwrap_or(0);
        self.in_flight = Some(InFlight {
            op,
            sent_us: now_us,
            deadline_us: sent_us + answer_us + self.reply_margin_us,
        });
        true
    }

    /// Offers a received servo packet: the answer to the transaction in flight, or else the
    /// late answer to a READ that timed out; `None` if it is neither.
    pub fn on_packet(&mut self, packet: Packet) -> Option<Taken> {
        if let Some(flight) = self.in_flight.as_ref()
            && answers(&flight.op, &packet)
        {
            let flight = self.in_flight.take()?;
            return Some(Taken::Finished(flight.op, Outcome::Answered(packet)));
        }
        let overdue = self.overdue.take_if(|o| answers(&o.op, &packet))?;
        Some(Taken::Late {
            op: overdue.op,
            answer: packet,
            sent_us: overdue.sent_us,
        })
    }

    /// Ends the transaction in flight if its time is up: a broadcast once it has left the
    /// transmitter, an answerable one at its deadline.
    pub fn poll<B: BytePort>(&mut self, now_us: u64, bus: &B) -> Option<(Op, Outcome)> {
        self.overdue.take_if(|o| now_us > o.until_us);
        let flight = self.in_flight.as_ref()?;
        let done = match flight.op.answer_data_len() {
            None => bus.tx_idle() || now_us >= flight.deadline_us,
            Some(_) => now_us >= flight.deadline_us,
        };
        if !done {
            return None;
        }
        let flight = self.in_flight.take()?;
        let outcome = if flight.op.answer_required() {
            Outcome::TimedOut
        } else {
            Outcome::Sent
        };
        let until_us = flight.deadline_us.saturating_add(LATE_ANSWER_WINDOW_US);
        if matches!(flight.op, Op::Read { .. }) && now_us <= until_us {
            self.overdue = Some(Overdue {
                op: flight.op.clone(),
                sent_us: flight.sent_us,
                until_us,
            });
        }
        Some((flight.op, outcome))
    }
}

/// True if `packet` is the answer `op` expects: from its servo, and for a READ as long as asked.
fn answers(op: &Op, packet: &Packet) -> bool {
    if op.answer_data_len().is_none() || packet.id() != op.id() {
        return false;
    }
    match op {
        Op::Read { count, .. } => packet.params().len() == usize::from(*count),
        _ => true,
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use protocol_core::NullPort;

    fn start(driver: &mut ServoDriver, op: Op) {
        let mut rx = Listener::default();
        assert!(driver.start(0, op, &mut NullPort, &mut rx));
    }

    fn status(id: u8, data: &[u8]) -> Packet {
        Packet::new(id, 0, data).unwrap()
    }

    #[test]
    fn read_is_answered_only_by_its_servo_with_the_right_length() {
        let mut d = ServoDriver::new(150);
        start(
            &mut d,
            Op::Read {
                id: 3,
                addr: 56,
                count: 2,
            },
        );
        assert!(!d.start(
            0,
            Op::Ping { id: 1 },
            &mut NullPort,
            &mut Listener::default()
        ));
        assert_eq!(d.on_packet(status(4, &[0, 8])), None, "another servo");
        assert_eq!(d.on_packet(status(3, &[0])), None, "short answer");
        let Some(Taken::Finished(op, outcome)) = d.on_packet(status(3, &[0, 8])) else {
            panic!("the answer ends the transaction");
        };
        assert_eq!(op.id(), 3);
        assert_eq!(outcome, Outcome::Answered(status(3, &[0, 8])));
        assert!(!d.busy());
    }

    fn read(id: u8) -> Op {
        Op::Read {
            id,
            addr: 56,
            count: 2,
        }
    }

    /// A READ of servo `id` sent at 0 and timed out (its deadline: 80 us out, 40 us
    /// turnaround, 80 us back, 150 us margin).
    fn timed_out(d: &mut ServoDriver, id: u8) {
        start(d, read(id));
        assert_eq!(
            d.poll(1_000, &NullPort),
            Some((read(id), Outcome::TimedOut))
        );
    }

    #[test]
    fn a_late_answer_that_comes_whole_is_taken_with_the_time_its_read_was_sent() {
        let mut d = ServoDriver::new(150);
        timed_out(&mut d, 3);
        assert!(d.busy(), "the wire stays the servo's for its late answer");
        assert!(!d.start(0, read(4), &mut NullPort, &mut Listener::default()));
        assert_eq!(d.on_packet(status(4, &[0, 8])), None, "another servo");
        assert_eq!(d.on_packet(status(3, &[0])), None, "short answer");
        assert_eq!(
            d.on_packet(status(3, &[0, 8])),
            Some(Taken::Late {
                op: read(3),
                answer: status(3, &[0, 8]),
                sent_us: 0,
            })
        );
        assert!(!d.busy(), "taken: the wire is free");
        assert_eq!(d.on_packet(status(3, &[0, 8])), None, "taken once");
    }

    #[test]
    fn a_late_answer_is_awaited_until_its_window_ends_and_not_taken_after() {
        const DEADLINE_US: u64 = 350;
        let mut d = ServoDriver::new(150);
        timed_out(&mut d, 3);
        d.poll(DEADLINE_US + LATE_ANSWER_WINDOW_US, &NullPort);
        assert!(d.busy());
        assert!(
            d.on_packet(status(3, &[0, 8])).is_some(),
            "at the window's end"
        );
        timed_out(&mut d, 3);
        d.poll(DEADLINE_US + LATE_ANSWER_WINDOW_US + 1, &NullPort);
        assert!(!d.busy(), "given up: the wire is free");
        assert_eq!(d.on_packet(status(3, &[0, 8])), None, "too late");
    }

    #[test]
    fn a_write_that_got_no_answer_waits_for_none() {
        let mut d = ServoDriver::new(150);
        start(&mut d, Op::write(2, 40, &[1]).unwrap());
        assert_eq!(
            d.poll(1_000, &NullPort).map(|(_, o)| o),
            Some(Outcome::Sent)
        );
        assert_eq!(d.on_packet(status(2, &[])), None);
    }

    #[test]
    fn silent_servo_times_out_at_the_deadline() {
        let mut d = ServoDriver::new(150);
        start(&mut d, Op::Ping { id: 5 });
        // PING: 6 bytes out (60 us), turnaround 40 us, 6 bytes back (60 us), margin 150 us.
        assert_eq!(d.poll(309, &NullPort), None);
        assert_eq!(
            d.poll(310, &NullPort),
            Some((Op::Ping { id: 5 }, Outcome::TimedOut))
        );
    }

    #[test]
    fn write_without_answer_is_sent_not_failed_and_broadcast_ends_with_the_transmission() {
        let mut d = ServoDriver::new(150);
        start(&mut d, Op::write(2, 40, &[1]).unwrap());
        assert_eq!(
            d.poll(1_000, &NullPort).map(|(_, o)| o),
            Some(Outcome::Sent)
        );
        let packet = status(0xFE, &[]);
        start(&mut d, Op::Broadcast(packet.clone()));
        assert_eq!(
            d.poll(0, &NullPort),
            Some((Op::Broadcast(packet), Outcome::Sent))
        );
    }
}
