//! The Atom application: the bus schedule, the servos' state and the robot's actions.
//!
//! # Bus schedule
//! One servo transaction at a time ([`ServoDriver`]). Between transactions the wire stays
//! silent for [`ATOM_TRANSACTION_GAP_US`] so the Basic can send a host frame; a frame that
//! starts holds the schedule until it ends, and its reply goes out at once (from cached
//! state), before the next transaction. Transactions, by priority: servo operations of host
//! commands (torque, calibration, register access), then the newest goals, then the state
//! refresh, which reads registers 40..=70 of each servo in turn (one READ per servo, so a
//! missing servo costs only its own timeout; [`readback`]). After every non-refresh transaction one refresh
//! read runs, so host traffic cannot starve the state refresh.
//!
//! Straight-line moves and Cartesian jogs are stepped by [`stepper`].

use heapless::Deque;
use protocol_core::command::Pose;
use protocol_core::servo::reg;
use protocol_core::timing::{
    ATOM_TRANSACTION_GAP_US, BUS_BAUD, BUS_QUIET_BEFORE_SEND_US, HOST_FRAME_GAP_US, wire_time_us,
};
use protocol_core::units::{Centideg, Steps};
use protocol_core::{BytePort, Frame, FrameDecoder};

use crate::bus::{BusEvent, BusReceiver};
use crate::cartesian::Cartesian;
use crate::config::{AtomConfig, ConfigError, GRIPPER, JOINTS, JointLimit, SERVOS, STEPS_PER_TURN};
use crate::driver::{Op, Outcome, ServoDriver};
use crate::health::ServoHealth;
use crate::io::AtomIo;
use crate::motion::{self, Activity, JogDirection};
use crate::safety::{self, Goal, GoalSet, Refusal};

mod readback;
mod stepper;

use readback::{STATE_READ_ADDR, STATE_READ_LEN, apply_state};
use stepper::Stepper;

/// Servo operations waiting for the bus. 16: a command queues at most 3 (EEPROM unlock,
/// write, lock) or 7 (torque on/off for every servo), and the host waits for each reply.
const OP_QUEUE: usize = 16;

/// Motions waiting in queue mode (fresh mode 0). 16 moves: a script sending a short path
/// without waiting; more is refused (answer 0) rather than silently dropped.
const MOTION_QUEUE: usize = 16;

/// A servo that stopped answering is probed only every this many refresh rounds, so a missing
/// servo (often the gripper) does not cost its timeout in every round.
const LOST_SERVO_PROBE_ROUNDS: u32 = 8;

/// Speed at which a servo switched on outside its joint limits is pulled back inside: 10 %.
const HOLD_SPEED_PERCENT: u8 = 10;

/// How long a fresh goal counts as "moving" before the servo's own moving flag is read back:
/// several refresh rounds (a round takes about 3 ms).
const GOAL_CONFIRM_US: u64 = 30_000;

/// Distance from its goal within which a servo counts as arrived: 10 steps, under one degree.
const IN_POSITION_STEPS: i32 = 10;

/// How long after its last byte a frame equal to our last bus reply is taken for its echo.
/// 300 us: far beyond the echo's arrival (tens of us), far below the time a client needs to
/// receive that reply through the Basic and send a new request (over a millisecond at 115200).
const OWN_REPLY_WINDOW_US: u64 = 300;

/// How often a bus reply is sent again after a collision garbled it: twice, then the host's
/// own resend takes over.
const REPLY_RESENDS: u8 = 2;

/// Which host link a request came from (its reply goes back there).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub(crate) enum Link {
    /// The shared bus (requests forwarded by the Basic).
    Bus,
    /// The Atom's own USB serial.
    Usb,
}

/// What to do when a queued servo operation finishes.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub(crate) enum Then {
    /// Nothing (the host was already answered).
    Nothing,
    /// Answer get servo data (0x53) with the value read.
    ReplyServoData {
        /// Where the request came from.
        link: Link,
        /// True for the 2-byte form.
        two_bytes: bool,
    },
}

/// A servo operation waiting for the bus.
#[derive(Clone, Debug)]
struct Job {
    op: Op,
    then: Then,
    attempt: u8,
}

/// A queued motion (queue mode).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub(crate) struct Target {
    /// Joint targets; `None` leaves a joint where it is going.
    pub angles: [Option<Centideg>; JOINTS],
    /// Speed, percent.
    pub speed_percent: u8,
    /// `Some`: reach `angles` along a straight line to this pose (send_coords mode 1).
    pub linear: Option<Pose>,
}

/// Why an action was not carried out. Converted to the 0x07 error code in one place
/// ([`ActionError::error_code`]).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub(crate) enum ActionError {
    /// The arm is powered off.
    PoweredOff,
    /// Joint `index` (0-based) would leave its limits.
    JointLimit(usize),
    /// The gripper value or servo goal is out of range.
    GripperRange,
    /// The pose has no inverse-kinematics solution.
    Unreachable,
    /// A straight line has no continuous solution.
    NoLinearSolution,
    /// A queue is full; the host may retry.
    Busy,
    /// The command cannot be carried out for another reason (bad register, missing servo).
    Invalid,
}

impl ActionError {
    /// The error code 0x07 reports for this failure (`protocol.md`), if it has one.
    pub(crate) fn error_code(self) -> Option<u8> {
        match self {
            Self::JointLimit(j) => Some(j as u8 + 1),
            Self::Unreachable => Some(32),
            Self::NoLinearSolution => Some(33),
            _ => None,
        }
    }
}

impl From<Refusal> for ActionError {
    fn from(r: Refusal) -> Self {
        match r {
            Refusal::PoweredOff => Self::PoweredOff,
            Refusal::JointLimit(j) => Self::JointLimit(j),
            Refusal::GripperRange => Self::GripperRange,
        }
    }
}

/// The Atom firmware. Create it once with [`Atom::new`] and call [`Atom::poll`] in a loop.
pub struct Atom {
    pub(crate) config: AtomConfig,
    config_error: Option<ConfigError>,
    // Links.
    rx: BusReceiver,
    usb_frames: FrameDecoder,
    usb_last_rx_us: u64,
    bus_reply: Option<Frame>,
    /// The last reply sent on the bus and when its echo window closes: a frame equal to it
    /// heard before then is our own echo that slipped past the echo filter (some replies,
    /// e.g. angles to coords, have the layout of a valid request).
    last_bus_reply: Option<(Frame, u64)>,
    /// True while the last thing the Atom put on the bus was a host reply (so a collision
    /// reported by the echo concerns it).
    reply_on_wire: bool,
    /// Resends left for the last bus reply after collisions.
    reply_resends: u8,
    /// A reply to send again once the wire is quiet (its first copy collided).
    resend_reply: Option<Frame>,
    // Bus schedule.
    driver: ServoDriver,
    jobs: Deque<Job, OP_QUEUE>,
    pending_goals: Option<safety::SafeGoals>,
    refresh_next: usize,
    owe_refresh: bool,
    refresh_rounds_done: u32,
    /// The receiver's checksum-error count when the transaction in flight started.
    checksum_errors_at_start: u32,
    // Robot state.
    pub(crate) powered: bool,
    pub(crate) free_mode: bool,
    pub(crate) fresh_mode: bool,
    pub(crate) error_code: u8,
    pub(crate) limits: [JointLimit; JOINTS],
    pub(crate) speed_percent: u8,
    pub(crate) health: [ServoHealth; SERVOS],
    /// The goal each servo was last sent (checked by the choke point), for read-back.
    pub(crate) last_goal: [Option<Goal>; SERVOS],
    /// Corrective writes sent to each servo since its last command (bounded by
    /// [`MAX_REPAIRS`]).
    repairs: [u8; SERVOS],
    /// When each servo last got a goal (it may not report moving until its next state read).
    last_goal_us: [u64; SERVOS],
    /// The time of the current poll.
    now_us: u64,
    pub(crate) activity: Activity,
    pub(crate) paused: Option<Target>,
    queue: Deque<Target, MOTION_QUEUE>,
    last_host_cmd_us: u64,
    button_was_pressed: bool,
    pub(crate) gripper: crate::config::GripperRange,
    pub(crate) gripper_torque: i16,
    pub(crate) gripper_protect_current: i16,
    pub(crate) cart: Cartesian,
    /// A straight-line move or a Cartesian jog being stepped.
    stepper: Option<Stepper>,
}

impl Atom {
    /// An Atom with `config`. An invalid configuration is replaced by the default one and the
    /// reason kept in [`Atom::config_error`], so a board always boots into something safe.
    pub fn new(config: AtomConfig) -> Self {
        let (config, config_error) = match config.validate() {
            Ok(()) => (config, None),
            Err(e) => (AtomConfig::default(), Some(e)),
        };
        let mut health = [ServoHealth::default(); SERVOS];
        for h in &mut health {
            h.position = Steps(crate::config::STEPS_ZERO as i16);
            h.torque_on = config.powered_at_boot;
        }
        Self {
            config,
            config_error,
            rx: BusReceiver::new(),
            usb_frames: FrameDecoder::new(),
            usb_last_rx_us: 0,
            bus_reply: None,
            last_bus_reply: None,
            reply_on_wire: false,
            reply_resends: 0,
            resend_reply: None,
            driver: ServoDriver::new(config.timing.reply_margin_us),
            jobs: Deque::new(),
            pending_goals: None,
            refresh_next: 0,
            owe_refresh: false,
            refresh_rounds_done: 0,
            checksum_errors_at_start: 0,
            powered: config.powered_at_boot,
            free_mode: false,
            fresh_mode: true,
            error_code: 0,
            limits: config.joint_limits,
            speed_percent: 100,
            health,
            last_goal: [None; SERVOS],
            repairs: [0; SERVOS],
            last_goal_us: [0; SERVOS],
            now_us: 0,
            activity: Activity::Idle,
            paused: None,
            queue: Deque::new(),
            last_host_cmd_us: 0,
            button_was_pressed: false,
            gripper: config.gripper,
            gripper_torque: 300,
            gripper_protect_current: 300,
            cart: Cartesian::new(&config.joint_limits),
            stepper: None,
        }
    }

    /// Runs everything that is due at `now_us` (monotonic microseconds): reads the bytes that
    /// arrived on `bus` (the shared 1 Mbaud wire) and `usb` (the Atom's own host link,
    /// [`protocol_core::NullPort`] if unused), answers host commands, drives the servo
    /// transactions and the motion. Never blocks; call it as often as possible.
    pub fn poll<B: BytePort, U: BytePort, I: AtomIo>(
        &mut self,
        now_us: u64,
        bus: &mut B,
        usb: &mut U,
        io: &mut I,
    ) {
        self.now_us = now_us;
        self.receive_bus(now_us, bus, usb, io);
        if self.rx.take_collision()
            && self.reply_on_wire
            && self.reply_resends > 0
            && let Some((reply, _)) = &self.last_bus_reply
        {
            // The Basic never got it; an incremental jog must not be resent by the host.
            self.reply_resends -= 1;
            self.resend_reply = Some(reply.clone());
        }
        self.receive_usb(now_us, usb, io);
        if let Some((op, outcome)) = self.driver.poll(now_us, bus) {
            self.finish(op, outcome, usb);
        }
        self.update_motion(now_us);
        self.update_button(io);
        self.schedule_bus(now_us, bus);
    }

    fn receive_bus<B: BytePort, U: BytePort, I: AtomIo>(
        &mut self,
        now_us: u64,
        bus: &mut B,
        usb: &mut U,
        io: &mut I,
    ) {
        // Bounded: at most what arrived since the last poll, plus a cap against a stuck port.
        for _ in 0..512 {
            let Some(byte) = bus.read_byte() else { break };
            let mut events: heapless::Vec<BusEvent, 4> = heapless::Vec::new();
            self.rx.push(now_us, byte, &mut |e| {
                let _ = events.push(e);
            });
            for e in events {
                self.on_bus_event(now_us, e, usb, io);
            }
        }
        let mut events: heapless::Vec<BusEvent, 4> = heapless::Vec::new();
        self.rx.on_time(now_us, &mut |e| {
            let _ = events.push(e);
        });
        for e in events {
            self.on_bus_event(now_us, e, usb, io);
        }
    }

    fn on_bus_event<U: BytePort, I: AtomIo>(
        &mut self,
        now_us: u64,
        event: BusEvent,
        usb: &mut U,
        io: &mut I,
    ) {
        match event {
            BusEvent::Frame(frame) => {
                if let Some((last, until_us)) = &self.last_bus_reply
                    && now_us <= *until_us
                    && *last == frame
                {
                    return;
                }
                if let Some(reply) = self.handle_frame(now_us, &frame, Link::Bus, io) {
                    // A newer request replaces an unsent reply: the host has given up on it.
                    self.bus_reply = Some(reply);
                }
            }
            BusEvent::Packet(packet) => {
                if let Some((op, outcome)) = self.driver.on_packet(packet) {
                    self.finish(op, outcome, usb);
                }
            }
        }
    }

    fn receive_usb<U: BytePort, I: AtomIo>(&mut self, now_us: u64, usb: &mut U, io: &mut I) {
        for _ in 0..512 {
            let Some(byte) = usb.read_byte() else { break };
            self.usb_last_rx_us = now_us;
            let mut next = self.usb_frames.push(byte);
            while let Some(frame) = next {
                if let Some(reply) = self.handle_frame(now_us, &frame, Link::Usb, io) {
                    usb.write(&reply.to_bytes());
                }
                next = self.usb_frames.next_frame();
            }
        }
        if self.usb_frames.has_partial()
            && now_us.saturating_sub(self.usb_last_rx_us) >= HOST_FRAME_GAP_US
        {
            let mut next = self.usb_frames.on_quiet_line();
            while let Some(frame) = next {
                if let Some(reply) = self.handle_frame(now_us, &frame, Link::Usb, io) {
                    usb.write(&reply.to_bytes());
                }
                next = self.usb_frames.next_frame();
            }
        }
    }

    fn handle_frame<I: AtomIo>(
        &mut self,
        now_us: u64,
        frame: &Frame,
        link: Link,
        io: &mut I,
    ) -> Option<Frame> {
        // The Basic's own liveness probe (is powered on, every second while the wire is idle)
        // says nothing about the client, so it does not keep a jog alive.
        if frame.cmd() != protocol_core::command::cmd::IS_POWER_ON {
            self.last_host_cmd_us = now_us;
        }
        crate::commands::handle(self, now_us, frame, link, io)
    }

    /// Starts the next bus action if the wire is ours: a held host reply first, then a servo
    /// transaction once the wire has been quiet for the transaction gap.
    fn schedule_bus<B: BytePort>(&mut self, now_us: u64, bus: &mut B) {
        if self.driver.busy() {
            return;
        }
        let resend_due = self.resend_reply.is_some()
            && self.rx.quiet_us(now_us) >= BUS_QUIET_BEFORE_SEND_US
            && !self.rx.frame_in_progress();
        let fresh = self.bus_reply.take();
        if fresh.is_some() {
            self.reply_resends = REPLY_RESENDS;
            self.resend_reply = None;
        }
        if let Some(reply) = fresh.or_else(|| {
            if resend_due {
                self.resend_reply.take()
            } else {
                None
            }
        }) {
            let bytes = reply.to_bytes();
            bus.write(&bytes);
            self.rx.on_transmit(now_us, &bytes);
            let window_us = wire_time_us(bytes.len() as u32, BUS_BAUD) + OWN_REPLY_WINDOW_US;
            self.last_bus_reply = Some((reply, now_us + window_us));
            self.reply_on_wire = true;
            return;
        }
        if self.resend_reply.is_some() {
            // Hold the servo schedule until the resent reply is out.
            return;
        }
        if self.rx.frame_in_progress()
            || !bus.tx_idle()
            || self.rx.quiet_us(now_us) < ATOM_TRANSACTION_GAP_US
        {
            return;
        }
        let op = if self.owe_refresh {
            self.owe_refresh = false;
            self.next_refresh_op()
        } else if let Some(job) = self.jobs.front() {
            self.owe_refresh = true;
            Some(job.op.clone())
        } else if let Some(goals) = self.pending_goals.take() {
            self.owe_refresh = true;
            goals.sync_write(&self.config.servo_ids).map(Op::Broadcast)
        } else {
            self.next_refresh_op()
        };
        if let Some(op) = op
            && self.driver.start(now_us, op, bus, &mut self.rx)
        {
            self.reply_on_wire = false;
            self.checksum_errors_at_start = self.rx.checksum_errors();
        }
    }

    /// The state read of the next servo in the refresh round (lost servos only now and then).
    fn next_refresh_op(&mut self) -> Option<Op> {
        for _ in 0..SERVOS {
            let index = self.refresh_next;
            self.refresh_next += 1;
            if self.refresh_next >= SERVOS {
                self.refresh_next = 0;
                self.refresh_rounds_done = self.refresh_rounds_done.wrapping_add(1);
            }
            let lost = self
                .health
                .get(index)
                .is_some_and(|h| !h.answering && h.misses >= self.config.timing.misses_before_lost);
            if lost
                && !self
                    .refresh_rounds_done
                    .is_multiple_of(LOST_SERVO_PROBE_ROUNDS)
            {
                continue;
            }
            let id = *self.config.servo_ids.get(index)?;
            return Some(Op::Read {
                id,
                addr: STATE_READ_ADDR,
                count: STATE_READ_LEN,
            });
        }
        None
    }

    /// Applies the result of a finished transaction.
    fn finish<U: BytePort>(&mut self, op: Op, outcome: Outcome, usb: &mut U) {
        let index = self.config.servo_ids.iter().position(|&id| id == op.id());
        let is_state_read = matches!(
            op,
            Op::Read {
                addr: STATE_READ_ADDR,
                count: STATE_READ_LEN,
                ..
            }
        );
        let job_matches = self.jobs.front().is_some_and(|j| j.op == op);
        if is_state_read && !job_matches {
            if let Some(h) = index.and_then(|i| self.health.get_mut(i)) {
                match &outcome {
                    Outcome::Answered(p) => {
                        apply_state(h, p);
                        if let Some(i) = index {
                            self.verify(i);
                        }
                    }
                    _ => {
                        h.comm_errors = h.comm_errors.wrapping_add(1);
                        h.corrupt_answers =
                            self.rx.checksum_errors() != self.checksum_errors_at_start;
                        h.misses = h.misses.saturating_add(1);
                        if h.misses >= self.config.timing.misses_before_lost {
                            h.answering = false;
                        }
                    }
                }
            }
            return;
        }
        if !job_matches {
            return;
        }
        if let (Some(h), Outcome::Answered(p)) =
            (index.and_then(|i| self.health.get_mut(i)), &outcome)
        {
            h.fault_bits = p.code();
        }
        if outcome == Outcome::TimedOut {
            if let Some(job) = self.jobs.front_mut()
                && job.attempt < self.config.timing.retries
            {
                job.attempt += 1;
                return;
            }
            if let Some(h) = index.and_then(|i| self.health.get_mut(i)) {
                h.comm_errors = h.comm_errors.wrapping_add(1);
            }
        }
        let Some(job) = self.jobs.pop_front() else {
            return;
        };
        if let Then::ReplyServoData { link, two_bytes } = job.then {
            let value: i16 = match &outcome {
                Outcome::Answered(p) if two_bytes => p.u16_at(0).map_or(-1, |v| v as i16),
                Outcome::Answered(p) => p.params().first().map_or(-1, |&v| i16::from(v)),
                _ => -1,
            };
            let reply = if two_bytes {
                Frame::new(crate::commands::GET_SERVO_DATA, &value.to_be_bytes())
            } else {
                Frame::new(crate::commands::GET_SERVO_DATA, &[value as u8])
            };
            if let Some(reply) = reply {
                match link {
                    Link::Bus => self.bus_reply = Some(reply),
                    Link::Usb => usb.write(&reply.to_bytes()),
                }
            }
        }
    }

    /// Queues a servo operation. `false` if the queue is full.
    pub(crate) fn queue_op(&mut self, op: Op, then: Then) -> bool {
        self.jobs
            .push_back(Job {
                op,
                then,
                attempt: 0,
            })
            .is_ok()
    }

    /// Room for `n` more servo operations.
    pub(crate) fn op_room(&self) -> usize {
        OP_QUEUE - self.jobs.len()
    }

    /// The safety choke point's caller: checks `goals` and, if they pass, makes them the next
    /// goals written to the servos (merged with goals not sent yet). Switches torque on for a
    /// released servo that gets a goal.
    pub(crate) fn send_goals(&mut self, goals: GoalSet) -> Result<(), ActionError> {
        let safe = safety::check(&self.config, &self.limits, self.powered, goals)?;
        let mut merged: GoalSet = self
            .pending_goals
            .take()
            .map(|p| *p.goals())
            .unwrap_or([None; SERVOS]);
        for (i, (slot, new)) in merged.iter_mut().zip(safe.goals()).enumerate() {
            if let Some(g) = new {
                *slot = Some(*g);
                if let Some(last) = self.last_goal.get_mut(i) {
                    *last = Some(*g);
                }
                if let Some(r) = self.repairs.get_mut(i) {
                    *r = 0;
                }
                if let Some(t) = self.last_goal_us.get_mut(i) {
                    *t = self.now_us;
                }
                let torque_off = self.health.get(i).is_some_and(|h| !h.torque_on);
                if torque_off {
                    self.set_torque(i, true);
                }
            }
        }
        // Re-checking the merge cannot fail (each goal passed on its own), but keeps the
        // invariant local: only checked goals are ever pending.
        self.pending_goals = Some(safety::check(
            &self.config,
            &self.limits,
            self.powered,
            merged,
        )?);
        Ok(())
    }

    /// Queues torque on/off for servo `index`.
    pub(crate) fn set_torque(&mut self, index: usize, on: bool) -> bool {
        let Some(&id) = self.config.servo_ids.get(index) else {
            return false;
        };
        if on && !self.powered {
            return false;
        }
        let queued = if on {
            match self.torque_on_op(index, id) {
                Some(op) => self.queue_op(op, Then::Nothing),
                // Position not read yet: `verify` switches it on after the first state read.
                None => true,
            }
        } else {
            // A limp servo holds no goal: nothing to compare its read-back against.
            if let Some(last) = self.last_goal.get_mut(index) {
                *last = None;
            }
            Op::write(id, reg::TORQUE_ENABLE, &[0])
                .is_some_and(|op| self.queue_op(op, Then::Nothing))
        };
        if queued && let Some(h) = self.health.get_mut(index) {
            h.torque_on = on;
            if let Some(r) = self.repairs.get_mut(index) {
                *r = 0;
            }
        }
        queued
    }

    /// The write that switches servo `index` on holding its present position (pulled into
    /// the joint limits if the arm was moved beyond them by hand, at [`HOLD_SPEED_PERCENT`]);
    /// `None` until the servo's position has been read. The hold goal becomes the servo's
    /// last goal (what the read-back compares against).
    fn torque_on_op(&mut self, index: usize, id: u8) -> Option<Op> {
        let h = self.health.get(index)?;
        if !h.answering {
            return None;
        }
        let position = match self.limits.get(index) {
            Some(limit) => {
                let angle = self.config.steps_to_angle(index, h.position);
                let inside = Centideg(angle.0.clamp(limit.min.0, limit.max.0));
                self.goal_steps(index, inside)
            }
            None => h.position,
        };
        let mut one: GoalSet = [None; SERVOS];
        if let Some(slot) = one.get_mut(index) {
            *slot = Some(Goal {
                position,
                speed_steps_per_s: motion::joint_speed_steps(&self.config, HOLD_SPEED_PERCENT)
                    as u16,
                accel: motion::joint_accel_register(&self.config),
            });
        }
        let safe = safety::check(&self.config, &self.limits, self.powered, one).ok()?;
        let op = safe.torque_on_write(index, id)?;
        if let Some(last) = self.last_goal.get_mut(index) {
            *last = safe.goals().get(index).copied().flatten();
        }
        Some(op)
    }

    // ----- motion -------------------------------------------------------------------------

    /// The encoder goal for joint `j` at `angle`: the nearest step whose angle is still within
    /// the joint's limits (a limit rarely falls on a whole step: 140 deg is step 3641.2, and
    /// step 3641 reads 140.01 deg, which the choke point would refuse).
    pub(crate) fn goal_steps(&self, j: usize, angle: Centideg) -> Steps {
        let steps = self.config.angle_to_steps(j, angle);
        let Some(limit) = self.limits.get(j) else {
            return steps;
        };
        [steps.0, steps.0 - 1, steps.0 + 1]
            .into_iter()
            .map(Steps)
            .find(|&s| limit.contains(self.config.steps_to_angle(j, s)))
            .unwrap_or(steps)
    }

    /// Present encoder positions of the joints.
    pub(crate) fn present_steps(&self) -> [Steps; JOINTS] {
        core::array::from_fn(|j| self.health.get(j).map(|h| h.position).unwrap_or_default())
    }

    /// Checks a target against power and limits without moving.
    pub(crate) fn check_target(&self, target: &Target) -> Result<(), ActionError> {
        if !self.powered {
            return Err(ActionError::PoweredOff);
        }
        for (j, (a, l)) in target.angles.iter().zip(&self.limits).enumerate() {
            if let Some(a) = a
                && !l.contains(*a)
            {
                return Err(ActionError::JointLimit(j));
            }
        }
        Ok(())
    }

    /// Accepts a motion: in fresh mode it starts now (replacing the current one), in queue
    /// mode it waits for the motions before it.
    pub(crate) fn submit_motion(&mut self, now_us: u64, target: Target) -> Result<(), ActionError> {
        self.check_target(&target)?;
        if self.fresh_mode {
            self.queue.clear();
            self.paused = None;
            self.start_motion(now_us, target, false)
        } else if self.activity == Activity::Idle && self.queue.is_empty() && self.paused.is_none()
        {
            self.start_motion(now_us, target, false)
        } else {
            self.queue.push_back(target).map_err(|_| ActionError::Busy)
        }
    }

    /// Sends the goals of `target` now.
    pub(crate) fn start_motion(
        &mut self,
        now_us: u64,
        target: Target,
        jog: bool,
    ) -> Result<(), ActionError> {
        self.check_target(&target)?;
        if let Some(pose) = target.linear {
            return self.start_line(now_us, pose, target);
        }
        let steps: [Option<Steps>; JOINTS] = core::array::from_fn(|j| {
            target
                .angles
                .get(j)
                .copied()
                .flatten()
                .map(|a| self.goal_steps(j, a))
        });
        let (goals, duration_us) = motion::plan_joint_move(
            &self.config,
            &self.present_steps(),
            &steps,
            target.speed_percent,
        );
        self.send_goals(goals)?;
        let present = self.present_angles();
        let full: [Centideg; JOINTS] = core::array::from_fn(|j| {
            target
                .angles
                .get(j)
                .copied()
                .flatten()
                .or_else(|| self.planned_angle(j))
                .unwrap_or(present.get(j).copied().unwrap_or_default())
        });
        self.activity = Activity::Moving {
            target: full,
            started_us: now_us,
            duration_us,
            jog,
        };
        Ok(())
    }

    /// The angle joint `j` was last sent to, if any.
    fn planned_angle(&self, j: usize) -> Option<Centideg> {
        self.last_goal
            .get(j)
            .copied()
            .flatten()
            .map(|g| self.config.steps_to_angle(j, g.position))
    }

    /// The target being executed (or the present angles when idle).
    pub(crate) fn planned_angles(&self) -> [Centideg; JOINTS] {
        match self.activity {
            Activity::Moving { target, .. } => target,
            Activity::Idle => self.present_angles(),
        }
    }

    /// Holds every joint where it is now and forgets the motion (and, if `clear`, the queue).
    pub(crate) fn halt(&mut self, clear: bool) {
        self.activity = Activity::Idle;
        self.stepper = None;
        if clear {
            self.queue.clear();
            self.paused = None;
        }
        if !self.powered {
            return;
        }
        let present = self.present_steps();
        let accel = motion::joint_accel_register(&self.config);
        let fastest_steps_per_s = self
            .health
            .iter()
            .take(JOINTS)
            .map(|h| h.speed_steps_per_s.unsigned_abs())
            .max()
            .unwrap_or(0);
        let mut goals: GoalSet = [None; SERVOS];
        for (j, slot) in goals.iter_mut().take(JOINTS).enumerate() {
            // Only servos whose position has been read: at boot the Basic's power on (0x10)
            // can arrive before the first state read, and a hold goal at a default position
            // would make the arm jump.
            let torque = self
                .health
                .get(j)
                .is_some_and(|h| h.torque_on && h.answering);
            if let (true, Some(&p)) = (torque, present.get(j)) {
                *slot = Some(self.braking_goal(j, p, accel, fastest_steps_per_s));
            }
        }
        // A present position outside the limits (arm moved by hand) is not sent: that joint
        // keeps its previous goal.
        for j in 0..JOINTS {
            let mut one: GoalSet = [None; SERVOS];
            if let (Some(slot), Some(g)) = (one.get_mut(j), goals.get(j).copied().flatten()) {
                *slot = Some(g);
                let _ = self.send_goals(one);
            }
        }
    }

    /// The goal that brings joint `j` (at `present`, moving at its last read speed) to rest.
    ///
    /// Holding at the present position would make a moving joint overshoot and swing back (a
    /// jog at full speed runs on about 14 degrees). Instead every joint brakes over the same
    /// time, the fastest joint's stopping time `T = v_max / a` at the full ramp `accel`
    /// (100 steps/s^2 units): joint `j` keeps its present speed as goal speed, decelerates at
    /// `a * |v_j| / v_max` and stops `v_j * T / 2` further on. All joints thus stop together,
    /// along the path they were on, so a Cartesian jog or line keeps its pose while it stops.
    /// The stop is kept within the joint's limits (a joint already past a limit stays where it
    /// is, it is not dragged back to it).
    fn braking_goal(&self, j: usize, present: Steps, accel: u8, fastest_steps_per_s: u16) -> Goal {
        let speed = i64::from(self.health.get(j).map_or(0, |h| h.speed_steps_per_s));
        let fastest = i64::from(fastest_steps_per_s.max(1));
        let full_ramp = i64::from(accel.max(1)) * 100;
        let travel = speed * fastest / (2 * full_ramp);
        let ramp = ((i64::from(accel) * speed.abs() + fastest - 1) / fastest).clamp(1, 254) as u8;
        let beyond = (i64::from(present.0) + travel).clamp(0, i64::from(STEPS_PER_TURN) - 1);
        let mut angle = self.config.steps_to_angle(j, Steps(beyond as i16));
        if let Some(limit) = self.limits.get(j) {
            let now = self.config.steps_to_angle(j, present);
            angle = angle.clamp(limit.min.min(now), limit.max.max(now));
        }
        Goal {
            position: self.goal_steps(j, angle),
            speed_steps_per_s: speed.unsigned_abs().clamp(1, u64::from(u16::MAX)) as u16,
            accel: ramp,
        }
    }

    /// Pauses the current motion (it can be resumed).
    pub(crate) fn pause(&mut self) {
        if let Activity::Moving {
            target, jog: false, ..
        } = self.activity
        {
            // A paused straight line resumes as a joint move to its end.
            self.paused = Some(Target {
                angles: target.map(Some),
                speed_percent: self.speed_percent,
                linear: None,
            });
        }
        self.halt(false);
    }

    /// Resumes a paused motion.
    pub(crate) fn resume(&mut self, now_us: u64) -> Result<(), ActionError> {
        match self.paused.take() {
            Some(t) => self.start_motion(now_us, t, false),
            None => Ok(()),
        }
    }

    /// Starts a continuous jog of joint `j` toward its limit.
    pub(crate) fn jog_joint(
        &mut self,
        now_us: u64,
        j: usize,
        direction: JogDirection,
        speed_percent: u8,
    ) -> Result<(), ActionError> {
        let limit = self.limits.get(j).ok_or(ActionError::Invalid)?;
        let end = match direction {
            JogDirection::Positive => limit.max,
            JogDirection::Negative => limit.min,
        };
        // A joint already past that limit (the user tightened it) would be dragged backwards,
        // against the direction asked for: refuse instead.
        let present = self.present_angles().get(j).copied().unwrap_or(end);
        let beyond = match direction {
            JogDirection::Positive => present > end,
            JogDirection::Negative => present < end,
        };
        if beyond {
            return Err(ActionError::JointLimit(j));
        }
        let mut angles = [None; JOINTS];
        if let Some(slot) = angles.get_mut(j) {
            *slot = Some(end);
        }
        self.queue.clear();
        self.paused = None;
        self.start_motion(
            now_us,
            Target {
                angles,
                speed_percent,
                linear: None,
            },
            true,
        )
    }

    fn update_motion(&mut self, now_us: u64) {
        self.update_stepper(now_us);
        if let Activity::Moving {
            target,
            started_us,
            duration_us,
            jog,
        } = self.activity
        {
            let elapsed = now_us.saturating_sub(started_us);
            // A servo that does not answer cannot arrive: judge by the ones that do.
            let present = self.present_angles();
            let answering: [bool; JOINTS] =
                core::array::from_fn(|j| self.health.get(j).is_some_and(|h| h.answering));
            let seen: [Centideg; JOINTS] = core::array::from_fn(|j| {
                if answering.get(j).copied().unwrap_or(false) {
                    present.get(j).copied().unwrap_or_default()
                } else {
                    target.get(j).copied().unwrap_or_default()
                }
            });
            let arrived = motion::angles_match(&seen, &target)
                && !self
                    .health
                    .iter()
                    .take(JOINTS)
                    .any(|h| h.answering && h.moving);
            let host_silent =
                now_us.saturating_sub(self.last_host_cmd_us) >= self.config.timing.jog_watchdog_us;
            if jog && host_silent {
                self.halt(true);
            } else if self.stepper.is_none()
                && (arrived || elapsed > duration_us + motion::MOVE_OVERTIME_US)
            {
                // (A stepped motion is over only when its stepper is: a slow jog catches up
                // with each step before the next one.)
                self.activity = Activity::Idle;
            }
        }
        if self.activity == Activity::Idle
            && self.paused.is_none()
            && let Some(next) = self.queue.pop_front()
            && let Err(e) = self.start_motion(now_us, next, false)
        {
            self.record(e);
        }
    }

    /// Free mode: the button releases the joints while held (to move the arm by hand).
    fn update_button<I: AtomIo>(&mut self, io: &mut I) {
        let pressed = io.button_pressed();
        if pressed != self.button_was_pressed && self.free_mode && self.powered {
            for j in 0..JOINTS {
                self.set_torque(j, !pressed);
            }
            if pressed {
                self.activity = Activity::Idle;
            }
        }
        self.button_was_pressed = pressed;
    }

    /// Forgets queued motions (0x05); the current one continues.
    pub(crate) fn clear_queue(&mut self) {
        self.queue.clear();
    }

    /// Records a failure's error code for 0x07.
    pub(crate) fn record(&mut self, e: ActionError) {
        if let Some(code) = e.error_code() {
            self.error_code = code;
        }
    }

    /// True while the arm moves (a motion runs or a servo reports moving).
    pub fn is_moving(&self) -> bool {
        self.activity != Activity::Idle
            || self
                .health
                .iter()
                .take(JOINTS)
                .any(|h| h.answering && h.moving)
    }

    /// True while servo `index` moves: its moving flag, or a goal sent moments ago that its
    /// state read has not confirmed yet (so "is moving" right after a command says yes).
    pub(crate) fn servo_moving(&self, index: usize) -> bool {
        let Some(h) = self.health.get(index) else {
            return false;
        };
        let recent = self
            .last_goal_us
            .get(index)
            .is_some_and(|&t| self.now_us.saturating_sub(t) < GOAL_CONFIRM_US);
        let far = self
            .last_goal
            .get(index)
            .copied()
            .flatten()
            .is_some_and(|g| {
                (i32::from(g.position.0) - i32::from(h.position.0)).abs() > IN_POSITION_STEPS
            });
        h.answering && (h.moving || (recent && far))
    }

    /// Powers the arm on: torque on for every servo.
    pub(crate) fn power_on(&mut self) -> bool {
        self.powered = true;
        self.free_mode = false;
        let ok = (0..SERVOS).all(|i| self.set_torque(i, true));
        // Hold where the arm is now instead of jumping to an old goal.
        self.halt(true);
        ok
    }

    /// Powers the arm off: motion forgotten, torque off for every servo.
    pub(crate) fn power_off(&mut self) -> bool {
        self.halt(true);
        self.pending_goals = None;
        self.powered = false;
        (0..SERVOS).all(|i| self.set_torque(i, false))
    }

    // ----- accessors ----------------------------------------------------------------------

    /// The configuration in use.
    pub fn config(&self) -> &AtomConfig {
        &self.config
    }

    /// Why the configuration passed to [`Atom::new`] was refused, if it was.
    pub fn config_error(&self) -> Option<ConfigError> {
        self.config_error
    }

    /// True while the arm is powered on (torque enabled by 0x10, until 0x11).
    pub fn is_powered(&self) -> bool {
        self.powered
    }

    /// The error code 0x07 reports (0 = none).
    pub fn error_code(&self) -> u8 {
        self.error_code
    }

    /// What the Atom knows about servo `index` (0..6 = joints 1..6, 6 = gripper).
    pub fn servo_health(&self, index: usize) -> Option<&ServoHealth> {
        self.health.get(index)
    }

    /// Present joint angles, from the servos' last reported positions.
    pub fn present_angles(&self) -> [Centideg; JOINTS] {
        core::array::from_fn(|j| {
            let steps = self.health.get(j).map(|h| h.position).unwrap_or_default();
            self.config.steps_to_angle(j, steps)
        })
    }

    /// Current joint limits (settable at run time with 0x4C/0x4D).
    pub fn joint_limits(&self) -> &[JointLimit; JOINTS] {
        &self.limits
    }

    /// Completed state-refresh rounds (every servo read once per round). Wraps.
    pub fn refresh_rounds(&self) -> u32 {
        self.refresh_rounds_done
    }

    /// Gripper opening 0 (closed) ..= 100 (open) from its present position.
    pub fn gripper_value(&self) -> u8 {
        let pos = i32::from(self.health.get(GRIPPER).map(|h| h.position.0).unwrap_or(0));
        let closed = i32::from(self.gripper.closed.0);
        let open = i32::from(self.gripper.open.0);
        let span = open - closed;
        if span == 0 {
            return 0;
        }
        ((pos - closed) * 100 / span).clamp(0, 100) as u8
    }

    /// The coordinate frames the host selected (tool pose, world pose, reference frame, end
    /// type) and the kinematics model they configure, as coordinates are reported with.
    pub fn cartesian(&self) -> &Cartesian {
        &self.cart
    }
}
