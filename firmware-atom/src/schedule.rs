//! The bus schedule: who talks on the shared wire when.
//!
//! One servo transaction at a time ([`ServoDriver`]). Between transactions the wire stays
//! silent for [`ATOM_TRANSACTION_GAP_US`] so the Basic can send a host frame; a frame that
//! starts holds the schedule until it ends, and its reply goes out at once (from cached
//! state), followed on the wire by the next transaction with no gap (so a host that sends
//! request after request cannot take every gap). Transactions, by priority: servo operations of host
//! commands (torque, calibration, register access), then the newest goals, then the state
//! refresh, which reads every servo in turn. After every non-refresh transaction one refresh
//! read runs, so host traffic cannot starve the state refresh.
//!
//! Host replies on the bus: a reply whose echo comes back garbled (a collision) is sent again
//! once the wire is quiet, up to [`REPLY_RESENDS`] times, so the host never has to resend (and
//! never repeats an incremental jog); a frame equal to our last reply heard just after it is our
//! own echo, not a request.

use protocol_core::listener::{Heard, Listener};
use protocol_core::servo::Packet;
use protocol_core::timing::{
    ATOM_TRANSACTION_GAP_US, BUS_BAUD, BUS_QUIET_BEFORE_SEND_US, wire_time_us,
};
use protocol_core::{BytePort, Frame};

use crate::bank::ServoBank;
use crate::driver::{Op, Outcome, ServoDriver, Taken};
use crate::settings::Settings;

/// How long after its last byte a frame equal to our last bus reply is taken for its echo.
/// 300 us: far beyond the echo's arrival (tens of us), far below the time a client needs to
/// receive that reply through the Basic and send a new request (over a millisecond at 115200).
const OWN_REPLY_WINDOW_US: u64 = 300;

/// How often a bus reply is sent again after a collision garbled it: twice, then the host's
/// own resend takes over.
pub const REPLY_RESENDS: u8 = 2;

/// What the Atom hears on the bus.
#[derive(Clone, Debug, PartialEq, Eq)]
pub enum BusEvent {
    /// A host frame (a request from the Basic).
    Frame(Frame),
    /// A servo packet with a valid checksum (a status reply).
    Packet(Packet),
}

/// Events found in one received byte or one passage of time: a byte can complete a packet and
/// up to [`MAX_FRAMES_AT_ONCE`] frames uncovered by a rescan.
pub type BusEvents = heapless::Vec<BusEvent, { MAX_FRAMES_AT_ONCE + 1 }>;

/// Most frames one byte (or one quiet gap) can complete: the framer holds at most
/// `MAX_FRAME_BYTES` bytes, and a frame takes at least `3 + MIN_LEN` of them.
pub const MAX_FRAMES_AT_ONCE: usize =
    protocol_core::frame::MAX_FRAME_BYTES / (3 + protocol_core::frame::MIN_LEN as usize);

/// Keeps what the Atom acts on of what the listener heard.
fn collect(events: &mut BusEvents) -> impl FnMut(Heard) + '_ {
    |heard| {
        let event = match heard {
            Heard::Frame(f) => BusEvent::Frame(f),
            Heard::Packet(p) => BusEvent::Packet(p),
            // Echo verdicts: the collision flag covers what the schedule needs.
            Heard::Byte(_) | Heard::Echo(_) => return,
        };
        let _ = events.push(event);
    }
}

/// The schedule of the shared bus. See the [module doc](self).
#[derive(Clone, Debug)]
pub struct BusSchedule {
    rx: Listener,
    driver: ServoDriver,
    /// A refresh read is owed after a non-refresh transaction.
    owe_refresh: bool,
    /// The receiver's checksum-error count when the transaction in flight started.
    checksum_errors_at_start: u32,
    /// A reply to send at the next chance.
    reply: Option<Frame>,
    /// The last reply sent and when its echo window closes.
    last_reply: Option<(Frame, u64)>,
    /// True while the last thing put on the bus was a host reply (so a collision reported by
    /// the echo concerns it).
    reply_on_wire: bool,
    /// Resends left for the last reply.
    reply_resends: u8,
    /// A reply to send again once the wire is quiet (its first copy collided).
    resend: Option<Frame>,
}

impl BusSchedule {
    /// A schedule allowing `reply_margin_us` beyond the computed time of each servo answer.
    pub fn new(reply_margin_us: u64) -> Self {
        Self {
            rx: Listener::default(),
            driver: ServoDriver::new(reply_margin_us),
            owe_refresh: false,
            checksum_errors_at_start: 0,
            reply: None,
            last_reply: None,
            reply_on_wire: false,
            reply_resends: 0,
            resend: None,
        }
    }

    /// Takes one byte heard on the bus at `now_us`; appends to `events` the frames and packets
    /// it completes (our own reply's echo left out).
    ///
    /// `events` is the caller's, emptied by it after each call: [`BusEvents`] holds up to
    /// `MAX_FRAMES_AT_ONCE + 1` whole frames and packets (about 1.5 KiB), and returning a fresh
    /// one per byte cost two copies of it for every byte heard, most of the loop's time at
    /// 1 Mbaud (docs/boards.md, "Emulated boards").
    pub fn hear(&mut self, now_us: u64, byte: u8, events: &mut BusEvents) {
        self.rx.push(now_us, byte, &mut collect(events));
        self.drop_own_reply(now_us, events);
    }

    /// Handles the passage of time: frames and packets cut short by a quiet line (appended to
    /// `events`, as in [`BusSchedule::hear`]), and a reply that collided (queued again). Call
    /// once per poll after the received bytes.
    pub fn on_time(&mut self, now_us: u64, events: &mut BusEvents) {
        self.rx.on_time(now_us, &mut collect(events));
        if self.rx.take_collision()
            && self.reply_on_wire
            && self.reply_resends > 0
            && let Some((reply, _)) = &self.last_reply
        {
            // The Basic never got it; an incremental jog must not be resent by the host.
            self.reply_resends -= 1;
            self.resend = Some(reply.clone());
        }
        self.drop_own_reply(now_us, events);
    }

    /// Leaves out a frame equal to our last reply within its echo window (some replies, e.g.
    /// angles to coords, have the layout of a valid request).
    fn drop_own_reply(&self, now_us: u64, events: &mut BusEvents) {
        if events.is_empty() {
            return;
        }
        if let Some((last, until_us)) = &self.last_reply
            && now_us <= *until_us
        {
            events.retain(|e| !matches!(e, BusEvent::Frame(f) if f == last));
        }
    }

    /// Queues `reply` for the host; a newer reply replaces an unsent one (the host has given
    /// up on it).
    pub fn send_reply(&mut self, reply: Frame) {
        self.reply = Some(reply);
    }

    /// Offers a received servo packet to the transaction in flight, or as the late answer to
    /// a READ that timed out ([`ServoDriver::on_packet`]).
    pub fn on_packet(&mut self, packet: Packet) -> Option<Taken> {
        self.driver.on_packet(packet)
    }

    /// Ends the transaction in flight if its time is up.
    pub fn poll_driver<B: BytePort>(&mut self, now_us: u64, bus: &B) -> Option<(Op, Outcome)> {
        self.driver.poll(now_us, bus)
    }

    /// True if nothing is under way on the bus: no servo transaction in flight, no reply
    /// waiting to go out or to be sent again, no frame or packet half heard.
    pub fn is_idle(&self) -> bool {
        !self.driver.busy()
            && self.reply.is_none()
            && self.resend.is_none()
            && !self.rx.frame_in_progress()
    }

    /// True if the receiver saw a corrupt servo packet since the transaction in flight started.
    pub fn saw_corruption(&self) -> bool {
        self.rx.checksum_errors() != self.checksum_errors_at_start
    }

    /// Starts the next bus action if the wire is ours: a held host reply first, then a servo
    /// transaction (from `bank`) once the wire has been quiet for the transaction gap.
    pub fn start_next<B: BytePort>(
        &mut self,
        now_us: u64,
        bus: &mut B,
        bank: &mut ServoBank,
        settings: &Settings,
    ) {
        if self.driver.busy() {
            return;
        }
        let resend_due = self.resend.is_some()
            && self.rx.quiet_us(now_us) >= BUS_QUIET_BEFORE_SEND_US
            && !self.rx.frame_in_progress();
        let fresh = self.reply.take();
        if fresh.is_some() {
            self.reply_resends = REPLY_RESENDS;
            self.resend = None;
        }
        let reply = match fresh {
            Some(r) => Some(r),
            None if resend_due => self.resend.take(),
            None => None,
        };
        let replied = reply.is_some();
        if let Some(reply) = reply {
            let bytes = reply.to_bytes();
            bus.write(&bytes);
            self.rx.on_transmit(now_us, &bytes);
            let window_us = wire_time_us(bytes.len() as u32, BUS_BAUD) + OWN_REPLY_WINDOW_US;
            self.last_reply = Some((reply, now_us + window_us));
            self.reply_on_wire = true;
        } else if self.resend.is_some() {
            // Hold the servo schedule until the resent reply is out.
            return;
        } else if self.rx.frame_in_progress()
            || !bus.tx_idle()
            || self.rx.quiet_us(now_us) < ATOM_TRANSACTION_GAP_US
        {
            return;
        }
        // A reply is followed at once by the next transaction, with no gap: the Basic waits
        // for a quiet wire before its next request, so a host that keeps the bus busy still
        // leaves every other turn to the servos, and the state refresh cannot starve.
        let op = if self.owe_refresh {
            self.owe_refresh = false;
            bank.next_refresh_op(settings)
        } else if let Some(op) = bank.due_job() {
            self.owe_refresh = true;
            Some(op)
        } else if let Some(op) = bank.take_goal_write(now_us, settings) {
            self.owe_refresh = true;
            Some(op)
        } else {
            bank.next_refresh_op(settings)
        };
        if let Some(op) = op
            && self.driver.start(now_us, op, bus, &mut self.rx)
        {
            // Right behind a reply, a collision the echo reports may concern either.
            self.reply_on_wire = replied;
            self.checksum_errors_at_start = self.rx.checksum_errors();
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::bank::test_support::at_rest;
    use crate::safety::{Goal, Goals};
    use protocol_core::servo::{BROADCAST_ID, reg};
    use protocol_core::units::Steps;

    /// A bus where nobody answers; keeps what the Atom wrote.
    #[derive(Default)]
    struct Wire {
        written: std::vec::Vec<std::vec::Vec<u8>>,
    }

    impl BytePort for Wire {
        fn read_byte(&mut self) -> Option<u8> {
            None
        }
        fn write(&mut self, bytes: &[u8]) {
            self.written.push(bytes.to_vec());
        }
        fn tx_idle(&self) -> bool {
            true
        }
    }

    /// Servo id and instruction of each servo packet written.
    fn instructions(wire: &Wire) -> std::vec::Vec<(u8, u8)> {
        wire.written.iter().map(|p| (p[2], p[4])).collect()
    }

    const READ: u8 = 2;
    const WRITE: u8 = 3;
    const SYNC_WRITE: u8 = 0x83;

    #[test]
    fn host_operations_goals_and_the_refresh_take_turns() {
        let (settings, mut bank) = at_rest();
        let mut schedule = BusSchedule::new(settings.config().timing.reply_margin_us);
        let mut wire = Wire::default();
        for _ in 0..2 {
            let op = Op::write(1, reg::ACCELERATION, &[5]).unwrap();
            assert!(bank.queue_op(op));
        }
        let goal = Goal {
            position: Steps(2_100),
            speed_steps_per_s: 100,
            accel: 10,
        };
        bank.send_goals(0, &settings, Goals::one(0, goal)).unwrap();
        // Nobody answers: each read times out, and its late answer is given up on before the
        // next pass 10 ms later.
        let mut now = 10_000;
        for _ in 0..8 {
            if let Some((op, outcome)) = schedule.poll_driver(now, &wire) {
                bank.finish(now, &settings, op, outcome, false);
            }
            schedule.start_next(now, &mut wire, &mut bank, &settings);
            now += 10_000;
        }
        assert_eq!(
            instructions(&wire),
            [
                (1, WRITE),
                (1, READ),
                (1, WRITE),
                (2, READ),
                (BROADCAST_ID, SYNC_WRITE),
                (3, READ),
                (4, READ),
                (5, READ),
            ],
            "after each host operation or goal write one refresh read, then the refresh alone"
        );
    }

    /// A schedule that has just sent a reply at 10 ms, the wire it went on, and the reply.
    fn replied() -> (BusSchedule, Wire, Frame) {
        let (settings, mut bank) = at_rest();
        let mut schedule = BusSchedule::new(settings.config().timing.reply_margin_us);
        let mut wire = Wire::default();
        let reply = Frame::new(0x20, &[1]).unwrap();
        schedule.send_reply(reply.clone());
        schedule.start_next(10_000, &mut wire, &mut bank, &settings);
        (schedule, wire, reply)
    }

    #[test]
    fn a_reply_goes_out_first_and_the_next_transaction_right_behind_it() {
        let (schedule, wire, reply) = replied();
        assert_eq!(wire.written.len(), 2, "{:?}", wire.written);
        assert_eq!(wire.written[0], reply.to_bytes().to_vec());
        assert_eq!(
            wire.written[1][..2],
            [0xFF, 0xFF],
            "a servo instruction, no gap"
        );
        assert!(schedule.driver.busy());
    }

    /// What the Atom hears goes into the caller's buffer, in order, and the echo of its own
    /// last reply is left out of it there (no buffer is returned per byte: docs/boards.md).
    #[test]
    fn heard_frames_fill_the_callers_buffer_without_our_own_echo() {
        let (mut schedule, _, reply) = replied();
        let mut events = BusEvents::new();
        for (i, &byte) in reply.to_bytes().iter().enumerate() {
            schedule.hear(10_010 + i as u64 * 10, byte, &mut events);
        }
        schedule.on_time(10_300, &mut events);
        assert!(events.is_empty(), "our own echo: {events:?}");
        let request = Frame::new(0x20, &[]).unwrap();
        let mut heard = std::vec::Vec::new();
        for (i, &byte) in request.to_bytes().iter().enumerate() {
            schedule.hear(20_000 + i as u64 * 10, byte, &mut events);
            heard.extend(events.drain(..));
        }
        schedule.on_time(30_000, &mut events);
        heard.extend(events.drain(..));
        assert_eq!(heard, [BusEvent::Frame(request)]);
    }
}
