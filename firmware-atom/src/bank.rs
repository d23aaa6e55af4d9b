//! The servo bank: what the Atom knows about each servo (its state, read back in turn), what it
//! told each one (goals, torque), and the servo operations waiting for the bus.
//!
//! The bank is the only maker of goals: [`ServoBank::send_goals`] passes every goal through the
//! safety check ([`crate::safety::check`]) and keeps the checked result until the bus schedule
//! writes it. It also repairs what the shared wire lost: the state read returns each servo's
//! torque and goal registers, and a write that did not arrive is sent again ([`readback`]).

use heapless::Deque;
use protocol_core::servo::{Packet, reg};
use protocol_core::timing::{BUS_BAUD, wire_time_us};
use protocol_core::units::{Centideg, Steps};

use crate::config::{GRIPPER, JOINTS, SERVOS, STEPS_PER_TURN, STEPS_ZERO};
use crate::driver::{Op, Outcome};
use crate::error::AtomError;
use crate::health::ServoHealth;
use crate::safety::{self, Goal, Goals, SafeGoals};
use crate::settings::Settings;
use crate::tolerance;

mod profile;
mod readback;

pub use profile::Motion;
use profile::Segment;
use readback::{Repair, STATE_READ_ADDR, STATE_READ_LEN, apply_state, repair};

/// Servo operations waiting for the bus. 24: a command queues at most 3 (EEPROM unlock,
/// write, lock), 7 (torque for every servo) or 24 (a restore of all six joints: a read, then
/// unlock, write, lock each), and the host waits for each reply.
pub const OP_QUEUE: usize = 24;

/// A servo that stopped answering is probed only every this many refresh rounds, so a missing
/// servo (often the gripper) does not cost its timeout in every round.
const LOST_SERVO_PROBE_ROUNDS: u32 = 8;

/// Speed at which a servo switched on outside its joint limits is pulled back inside: 10 %.
const HOLD_SPEED_PERCENT: u8 = 10;

/// How long a fresh goal counts as "moving" before the servo's own moving flag is read back:
/// several refresh rounds (a round takes about 3 ms).
const GOAL_CONFIRM_US: u64 = 30_000;

/// How long a state reading says where its joint is: 50 ms, a dozen refresh rounds (a round
/// takes about 4 ms, and a reply lost now and then costs one). A joint without a reading this
/// recent (its servo's replies late or lost) is not known to be anywhere: a motion stops with
/// [`AtomError::StateLost`], none starts, and "is moving" says yes. At full speed a joint turns
/// 7.5 deg in this time, but not unwatched: the Atom keeps driving it along the commanded path.
pub const FRESH_STATE_US: u64 = 50_000;

/// How far a reading is carried on at its speed to say where its joint is now: 20 ms. A stop
/// and a followed path use a reading only this recent; an older one (though fresh) says too
/// little about a joint that may have sped up or slowed down since, so they go by what the
/// joint was told ([`ServoBank::commanded`]).
pub const ESTIMATE_HORIZON_US: u64 = 20_000;

/// Time a reading may have waited for the Atom beyond the time between two readings (a slow
/// loop reads its UART late), in the test of a reading against the one before: 10 ms.
const READ_SLACK_US: u64 = 10_000;

/// Steps a reading may differ from the one before beyond what the servo can turn in the time
/// between (encoder noise, rounding): 8 steps, 0.7 deg.
const READ_SLACK_STEPS: i64 = 8;

/// A servo that stopped answering for this long (or never answered) is only probed now and
/// then ([`LOST_SERVO_PROBE_ROUNDS`]): 1 s. Before that it is read in every round, so that a
/// joint whose replies were lost for a moment is seen again at once.
const LOST_SERVO_PROBE_AFTER_US: u64 = 1_000_000;

/// A servo acts on a goal at its next control step (its loop runs at 1 kHz): half a
/// millisecond after the goal arrives, on average.
const GOAL_TAKEN_AFTER_US: u64 = 500;

/// Who waits for a queued servo operation's result. Opaque to the bank: it hands the ticket
/// back with the result ([`Finished`]), and whoever queued the operation knows what it means.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct Ticket(pub u8);

/// A servo operation waiting for the bus.
#[derive(Clone, Debug)]
struct Job {
    op: Op,
    ticket: Option<Ticket>,
    attempt: u8,
}

/// A queued servo operation with a ticket that is done (answered, or out of retries).
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct Finished {
    /// The ticket it was queued with.
    pub ticket: Ticket,
    /// The bus id of the servo it addressed.
    pub id: u8,
    /// The servo's answer; `None` if it did not answer.
    pub answer: Option<Packet>,
}

/// What the Atom knows about one servo and what it told it.
#[derive(Clone, Copy, Debug, Default)]
struct Servo {
    /// Its state as last read.
    health: ServoHealth,
    /// Whether the Atom has told it anything (torque, a goal) since it started.
    commanded: bool,
    /// When its state was last read.
    read_us: u64,
    /// The goal it was last sent (checked), what its read-back is compared with.
    last_goal: Option<Goal>,
    /// Corrective writes sent to it since its last command.
    repairs: u8,
    /// When it last got a goal (it may not report moving until its next state read).
    goal_sent_us: u64,
    /// What its own motion profile does with the last goal written to it, from the moment it
    /// reached it ([`ServoBank::commanded`]); `None` while it is released or has not been told
    /// anything since its torque changed.
    profile: Option<Segment>,
    /// False while its latest reading is not believed: it jumped further from the last believed
    /// one than the servo can turn in the time between.
    trusted: bool,
    /// Its last believed reading and when it came.
    trusted_position: Steps,
    trusted_us: u64,
    /// When its last state read failed.
    missed_us: u64,
}

/// The servos' state and the Atom's instructions to them. See the [module doc](self).
#[derive(Clone, Debug)]
pub struct ServoBank {
    /// True while the arm is powered on (torque enabled by 0x10, until 0x11).
    powered: bool,
    /// One record per servo (0..6 joints, 6 gripper).
    servos: [Servo; SERVOS],
    /// Checked goals not written yet.
    pending: Option<SafeGoals>,
    jobs: Deque<Job, OP_QUEUE>,
    refresh_next: usize,
    refresh_rounds: u32,
    /// A joint whose reading jumped, not yet taken by [`ServoBank::take_jump`].
    jumped: Option<usize>,
}

impl ServoBank {
    /// A bank for the servos of `settings`, nothing read yet.
    pub fn new(settings: &Settings) -> Self {
        let powered = settings.config().powered_at_boot;
        let servo = Servo {
            health: ServoHealth {
                position: Steps(STEPS_ZERO as i16),
                torque_on: powered,
                ..ServoHealth::default()
            },
            ..Servo::default()
        };
        Self {
            powered,
            servos: [servo; SERVOS],
            pending: None,
            jobs: Deque::new(),
            refresh_next: 0,
            refresh_rounds: 0,
            jumped: None,
        }
    }

    /// True while the arm is powered on.
    pub fn powered(&self) -> bool {
        self.powered
    }

    /// Powers the arm on (torque on for every servo, holding where each one is) or off
    /// (goals not written yet forgotten, torque off). False if an operation did not fit.
    pub fn power(&mut self, settings: &Settings, on: bool) -> bool {
        if !on {
            self.pending = None;
        }
        self.powered = on;
        (0..SERVOS).all(|i| self.set_torque(settings, i, on))
    }

    /// Switches torque back on for every servo released since the arm was powered on (power
    /// on, 0x10, while already on). False if an operation did not fit.
    pub fn focus_released(&mut self, settings: &Settings) -> bool {
        let mut ok = true;
        for i in 0..SERVOS {
            if !self.enabled(i) {
                ok &= self.set_torque(settings, i, true);
            }
        }
        ok
    }

    /// What the Atom knows about servo `index` (0..6 = joints 1..6, 6 = gripper).
    pub fn health(&self, index: usize) -> Option<&ServoHealth> {
        self.servos.get(index).map(|s| &s.health)
    }

    /// `f` of each joint's health (the default for a joint the bank does not have).
    pub fn per_joint<T: Default>(&self, f: impl Fn(&ServoHealth) -> T) -> [T; JOINTS] {
        core::array::from_fn(|j| self.health(j).map(&f).unwrap_or_default())
    }

    /// Present encoder positions of the joints.
    pub fn present_steps(&self) -> [Steps; JOINTS] {
        self.per_joint(|h| h.position)
    }

    /// Present joint angles at `now_us`: each joint's last read position moved on by its last
    /// read speed for the time since ([`Self::estimated_millisteps`]). At rest that is exactly
    /// the servo's reading; while moving it is where the joint is now rather than where it was
    /// at its read (the seven reads of a round are up to 4 ms apart, which would skew a pose
    /// read during a fast move).
    pub fn present_angles(&self, now_us: u64, settings: &Settings) -> [Centideg; JOINTS] {
        core::array::from_fn(|j| {
            settings
                .config()
                .millisteps_to_angle(j, self.estimated_millisteps(now_us, j))
        })
    }

    /// Joint `j`'s last read speed, steps per second (0 if it does not answer or holds no
    /// torque).
    pub fn velocity(&self, j: usize) -> i32 {
        self.health(j)
            .filter(|h| h.answering && h.torque_on)
            .map_or(0, |h| i32::from(h.speed_steps_per_s))
    }

    /// Where joint `j` is at `now_us` as get angles reports it, in thousandths of a step: its
    /// last read position moved on by its last read speed for the time since, at most
    /// [`ESTIMATE_HORIZON_US`] (the reads of a round are a few ms apart).
    pub fn estimated_millisteps(&self, now_us: u64, j: usize) -> i64 {
        let position = self.health(j).map_or(0, |h| i64::from(h.position.0));
        let age_us = self.read_age_us(now_us, j).min(ESTIMATE_HORIZON_US) as i64;
        position * 1000 + i64::from(self.velocity(j)) * age_us / 1000
    }

    /// What servo `index`'s latest reading says about it now, if that reading is believed and
    /// at most [`ESTIMATE_HORIZON_US`] old: its position moved on by its read speed for the
    /// whole time since, and that speed. `None` for an older, missing or jumped reading: a
    /// goal is never made from one.
    pub fn observed(&self, now_us: u64, index: usize) -> Option<Motion> {
        let s = self.servos.get(index)?;
        let h = &s.health;
        let age_us = self.trusted_age_us(now_us, index)?;
        if age_us > ESTIMATE_HORIZON_US {
            return None;
        }
        let speed = if h.torque_on {
            i64::from(h.speed_steps_per_s)
        } else {
            0
        };
        Some(Motion {
            millisteps: i64::from(h.position.0) * 1000 + speed * age_us as i64 / 1000,
            millisteps_per_s: speed * 1000,
        })
    }

    /// What servo `index` was told, worked out for `now_us`: where its own motion profile has
    /// carried its setpoint with the last goal written to it, and how fast it moves
    /// ([`profile`]). `None` while it holds no goal the Atom wrote since its torque changed.
    pub fn commanded(&self, now_us: u64, index: usize) -> Option<Motion> {
        let s = self.servos.get(index)?;
        s.profile.map(|p| p.at(now_us))
    }

    /// Servo `index`'s motion at `now_us` as a goal may be made from it: what it was told
    /// ([`Self::commanded`]), else its recent reading ([`Self::observed`]), else at rest on its
    /// last goal; `None` if none of them is known.
    pub fn motion(&self, now_us: u64, index: usize) -> Option<Motion> {
        self.commanded(now_us, index)
            .or_else(|| self.observed(now_us, index))
            .or_else(|| {
                self.last_goal(index).map(|g| Motion {
                    millisteps: i64::from(g.position.0) * 1000,
                    millisteps_per_s: 0,
                })
            })
    }

    /// When servo `index`'s last state read arrived (monotonic microseconds); `None` before
    /// the first or for an index without a servo.
    pub fn read_at_us(&self, index: usize) -> Option<u64> {
        self.servos
            .get(index)
            .filter(|s| s.health.ever_answered)
            .map(|s| s.read_us)
    }

    /// Time from servo `index`'s last state read to `now_us`, microseconds.
    fn read_age_us(&self, now_us: u64, index: usize) -> u64 {
        now_us.saturating_sub(self.servos.get(index).map_or(0, |s| s.read_us))
    }

    /// Time from servo `index`'s last believed state read to `now_us`; `None` if it was never
    /// read or its latest reading jumped.
    fn trusted_age_us(&self, now_us: u64, index: usize) -> Option<u64> {
        let s = self.servos.get(index)?;
        (s.health.ever_answered && s.trusted).then(|| now_us.saturating_sub(s.read_us))
    }

    /// True if servo `index` has a believed reading at most [`FRESH_STATE_US`] old at
    /// `now_us`: the Atom knows where it is.
    pub fn fresh(&self, now_us: u64, index: usize) -> bool {
        self.trusted_age_us(now_us, index)
            .is_some_and(|age| age <= FRESH_STATE_US)
    }

    /// The first joint without a fresh reading at `now_us` ([`Self::fresh`]), if any.
    pub fn unknown_joint(&self, now_us: u64) -> Option<usize> {
        (0..JOINTS).find(|&j| !self.fresh(now_us, j))
    }

    /// Takes the joint whose reading last jumped (further from the one before than its servo
    /// can turn in the time between), if one did since the last call.
    pub fn take_jump(&mut self) -> Option<usize> {
        self.jumped.take()
    }

    /// True if servo `index` holds torque as far as the Atom knows and its position was read at
    /// least once, whether or not its latest reads came back: what a stop must brake. A servo
    /// whose answers are lost still hears the goals (a SYNC WRITE has no answer), and it goes
    /// on towards its last goal until it gets another one.
    pub fn holds_torque(&self, index: usize) -> bool {
        self.health(index)
            .is_some_and(|h| h.ever_answered && h.torque_on)
    }

    /// True if joint `j`'s latest fresh reading says it is at rest on its goal at `now_us`:
    /// not moving, and within [`tolerance::IN_POSITION_STEPS`] of the goal it was last sent
    /// (if it holds one). A joint without a fresh reading is not known to be at rest.
    fn settled(&self, now_us: u64, j: usize) -> bool {
        let Some(s) = self.servos.get(j) else {
            return false;
        };
        let on_goal = s
            .last_goal
            .is_none_or(|g| tolerance::servo_at(g.position, s.health.position));
        self.fresh(now_us, j) && !s.health.moving && on_goal
    }

    /// True at `now_us` unless every joint's latest fresh reading says it is at rest on its
    /// goal ([`Self::settled`]): a joint that moves, one not yet on its goal (a goal sent
    /// moments ago is not "at rest" before the servo starts), and one whose readings stopped
    /// or jumped all count as moving.
    pub fn joints_moving(&self, now_us: u64) -> bool {
        (0..JOINTS).any(|j| !self.settled(now_us, j))
    }

    /// True at `now_us` while servo `index` moves: its moving flag, or a goal sent moments ago
    /// that its state read has not confirmed yet (so "is moving" right after a command says
    /// yes).
    pub fn servo_moving(&self, now_us: u64, index: usize) -> bool {
        let Some(s) = self.servos.get(index) else {
            return false;
        };
        let recent = now_us.saturating_sub(s.goal_sent_us) < GOAL_CONFIRM_US;
        let far = s
            .last_goal
            .is_some_and(|g| !tolerance::servo_at(g.position, s.health.position));
        s.health.answering && (s.health.moving || (recent && far))
    }

    /// True if servo `index` answers and holds torque (0x50).
    pub fn enabled(&self, index: usize) -> bool {
        self.health(index)
            .is_some_and(|h| h.answering && h.torque_on)
    }

    /// The goal servo `index` was last sent, if it holds one.
    pub fn last_goal(&self, index: usize) -> Option<Goal> {
        self.servos.get(index).and_then(|s| s.last_goal)
    }

    /// Checks `goals` (the safety check) and, if they pass, makes them the next goals written
    /// to the servos (merged with goals not written yet), sent at `now_us`. Switches torque on
    /// for a released servo that gets a goal.
    pub fn send_goals(
        &mut self,
        now_us: u64,
        settings: &Settings,
        goals: Goals,
    ) -> Result<(), AtomError> {
        let safe = safety::check(settings.config(), settings.limits(), self.powered, goals)?;
        let waiting = self.pending.take().map_or(Goals::NONE, |p| *p.goals());
        for (i, goal) in safe.goals().iter() {
            // A released servo is switched on first (holding where it is, until the goal
            // is written): the goal below then replaces that hold as what it was told.
            if self.health(i).is_some_and(|h| !h.torque_on) {
                self.set_torque(settings, i, true);
            }
            if let Some(s) = self.servos.get_mut(i) {
                s.commanded = true;
                s.last_goal = Some(goal);
                s.repairs = 0;
                s.goal_sent_us = now_us;
            }
        }
        self.hold_pending(settings, waiting.merge(safe.goals()))
    }

    /// Re-sends what servo `index`'s read-back shows got lost ([`readback::repair`]): its
    /// torque, or its last goal (through the safety check again: the limits may have changed
    /// since).
    fn verify(&mut self, settings: &Settings, index: usize) {
        let Some(&id) = settings.config().servo_ids.get(index) else {
            return;
        };
        let Some(s) = self.servos.get(index).copied() else {
            return;
        };
        let pending_goal = self
            .pending
            .as_ref()
            .is_some_and(|p| p.goals().get(index).is_some());
        let pending_job = self.jobs.iter().any(|j| j.op.id() == id);
        match repair(
            &s.health,
            s.last_goal,
            s.repairs,
            pending_goal || pending_job,
        ) {
            Some(Repair::Torque(on)) => {
                let op = if on {
                    self.torque_on_op(settings, index, id)
                } else {
                    Op::write(id, reg::TORQUE_ENABLE, &[0])
                };
                if let Some(op) = op {
                    self.queue_op(op);
                }
            }
            Some(Repair::Goal(goal)) => {
                let waiting = self.pending.as_ref().map_or(Goals::NONE, |p| *p.goals());
                if self
                    .hold_pending(settings, waiting.merge(&Goals::one(index, goal)))
                    .is_err()
                {
                    return;
                }
            }
            None => return,
        }
        if let Some(s) = self.servos.get_mut(index) {
            s.repairs += 1;
        }
    }

    /// Makes `goals` the goals not written yet, through the safety check again: the limits
    /// may have changed since a goal was made, and only checked goals are ever pending.
    fn hold_pending(&mut self, settings: &Settings, goals: Goals) -> Result<(), AtomError> {
        self.pending = Some(safety::check(
            settings.config(),
            settings.limits(),
            self.powered,
            goals,
        )?);
        Ok(())
    }

    /// Queues torque on/off for servo `index`; false if it could not be queued.
    pub fn set_torque(&mut self, settings: &Settings, index: usize, on: bool) -> bool {
        let Some(&id) = settings.config().servo_ids.get(index) else {
            return false;
        };
        if on && !self.powered {
            return false;
        }
        let queued = if on {
            match self.torque_on_op(settings, index, id) {
                Some(op) => self.queue_op(op),
                // Position not read yet: the read-back switches it on after the first read.
                None => true,
            }
        } else {
            // A limp servo holds no goal: nothing to compare its read-back against.
            self.forget_goal(index);
            Op::write(id, reg::TORQUE_ENABLE, &[0]).is_some_and(|op| self.queue_op(op))
        };
        if let Some(s) = self.servos.get_mut(index) {
            s.commanded = true;
            if queued {
                s.health.torque_on = on;
                s.repairs = 0;
                // Switched on, it holds where its shaft is: its old profile is gone.
                s.profile = None;
            }
        }
        queued
    }

    /// The write that switches servo `index` on holding its present position (pulled into
    /// the joint limits if the arm was moved beyond them by hand, at [`HOLD_SPEED_PERCENT`]);
    /// `None` until the servo's position has been read. The hold goal becomes the servo's
    /// last goal (what the read-back compares against).
    fn torque_on_op(&mut self, settings: &Settings, index: usize, id: u8) -> Option<Op> {
        let h = self.health(index)?;
        if !h.answering {
            return None;
        }
        let position = match settings.limit(index) {
            Some(limit) => {
                let angle = settings.angle(index, h.position);
                let inside = Centideg(angle.0.clamp(limit.min.0, limit.max.0));
                settings.goal_steps(index, inside)
            }
            None => h.position,
        };
        let config = settings.config();
        let hold = Goal {
            position,
            speed_steps_per_s: config.joint_speed_steps(HOLD_SPEED_PERCENT) as u16,
            accel: config.joint_accel_register(),
        };
        let one = Goals::one(index, hold);
        let safe = safety::check(config, settings.limits(), self.powered, one).ok()?;
        let op = safe.torque_on_write(index, id)?;
        if let Some(s) = self.servos.get_mut(index) {
            s.last_goal = safe.goals().get(index);
        }
        Some(op)
    }

    /// Records that servo `index` was calibrated (torque 128): its present position is now
    /// 2048 and it holds no goal until told again.
    pub fn calibrated(&mut self, index: usize) {
        if let Some(s) = self.servos.get_mut(index) {
            s.health.position = Steps(STEPS_ZERO as i16);
            s.trusted_position = s.health.position;
        }
        self.forget_goal(index);
    }

    /// Forgets servo `index`'s goal, sent or not yet written: after a calibration or a
    /// release it would mean another place (or move a limp servo when it is switched on).
    fn forget_goal(&mut self, index: usize) {
        if let Some(s) = self.servos.get_mut(index) {
            s.last_goal = None;
            s.profile = None;
        }
        self.pending = self.pending.take().map(|p| p.without(index));
    }

    /// Queues a servo operation whose result nobody waits for. `false` if the queue is full.
    pub fn queue_op(&mut self, op: Op) -> bool {
        self.push_job(op, None)
    }

    /// Queues a servo operation whose result goes back with `ticket` ([`Self::finish`]).
    /// `false` if the queue is full.
    pub fn queue_read(&mut self, op: Op, ticket: Ticket) -> bool {
        self.push_job(op, Some(ticket))
    }

    fn push_job(&mut self, op: Op, ticket: Option<Ticket>) -> bool {
        self.jobs
            .push_back(Job {
                op,
                ticket,
                attempt: 0,
            })
            .is_ok()
    }

    /// Room for this many more servo operations.
    pub fn op_room(&self) -> usize {
        OP_QUEUE - self.jobs.len()
    }

    /// The servo operation of a host command that is due next (it stays queued until it
    /// finishes: a timed-out one is retried).
    pub fn due_job(&self) -> Option<Op> {
        self.jobs.front().map(|j| j.op.clone())
    }

    /// The SYNC WRITE of the goals not written yet, taking them, to be sent at `now_us`: each
    /// servo's profile continues with its new goal from the moment the write reaches it
    /// ([`Self::commanded`]).
    pub fn take_goal_write(&mut self, now_us: u64, settings: &Settings) -> Option<Op> {
        let goals = self.pending.take()?;
        let packet = goals.sync_write(&settings.config().servo_ids)?;
        let arrives_us =
            now_us + wire_time_us(packet.to_bytes().len() as u32, BUS_BAUD) + GOAL_TAKEN_AFTER_US;
        for (i, goal) in goals.goals().iter() {
            self.follow_goal(arrives_us, settings, i, goal);
        }
        Some(Op::Broadcast(packet))
    }

    /// Notes that servo `index`'s profile takes `goal` from `at_us` on, continuing from where
    /// it was carrying the setpoint then (from its latest reading if the Atom had told it
    /// nothing it can work out).
    fn follow_goal(&mut self, at_us: u64, settings: &Settings, index: usize, goal: Goal) {
        let Some(from) = self.motion(at_us, index) else {
            return;
        };
        let motion = &settings.config().motion;
        let speed = match goal.speed_steps_per_s {
            0 => motion.servo_speed_max_steps_per_s,
            v => u32::from(v).min(motion.servo_speed_max_steps_per_s),
        };
        let accel = match goal.accel {
            0 => motion.servo_accel_steps_per_s2,
            a => (u32::from(a) * 100).min(motion.servo_accel_steps_per_s2),
        };
        if let Some(s) = self.servos.get_mut(index) {
            s.profile = Some(Segment {
                start_us: at_us,
                from,
                goal_millisteps: i64::from(goal.position.0) * 1000,
                speed_millisteps_per_s: i64::from(speed) * 1000,
                accel_millisteps_per_s2: i64::from(accel) * 1000,
            });
        }
    }

    /// The state read of the next servo in the refresh round (lost servos only now and then).
    pub fn next_refresh_op(&mut self, settings: &Settings) -> Option<Op> {
        let config = settings.config();
        for _ in 0..SERVOS {
            let index = self.refresh_next;
            self.refresh_next += 1;
            if self.refresh_next >= SERVOS {
                self.refresh_next = 0;
                self.refresh_rounds = self.refresh_rounds.wrapping_add(1);
            }
            let lost = self
                .health(index)
                .is_some_and(|h| !h.answering && h.misses >= config.timing.misses_before_lost)
                && self.lost_for_long(index);
            if lost && !self.refresh_rounds.is_multiple_of(LOST_SERVO_PROBE_ROUNDS) {
                continue;
            }
            let id = *config.servo_ids.get(index)?;
            return Some(Op::Read {
                id,
                addr: STATE_READ_ADDR,
                count: STATE_READ_LEN,
            });
        }
        None
    }

    /// True if servo `index` never answered, or has not for [`LOST_SERVO_PROBE_AFTER_US`]
    /// (measured at its last failed read): a missing servo, not a reply lost for a moment.
    fn lost_for_long(&self, index: usize) -> bool {
        self.servos.get(index).is_none_or(|s| {
            !s.health.ever_answered
                || s.missed_us.saturating_sub(s.read_us) >= LOST_SERVO_PROBE_AFTER_US
        })
    }

    /// Completed state-refresh rounds (every servo read once per round). Wraps.
    pub fn refresh_rounds(&self) -> u32 {
        self.refresh_rounds
    }

    /// True if `op` is a state read of the refresh round (not one a job waits for).
    pub fn is_refresh_read(&self, op: &Op) -> bool {
        is_state_read(op) && !self.jobs.front().is_some_and(|j| j.op == *op)
    }

    /// Applies the result of a transaction that finished at `now_us`; `corrupt` says the
    /// receiver saw a bad checksum during it. A timed-out operation with retries left stays
    /// queued; one with a ticket that is done is handed back ([`Finished`]).
    pub fn finish(
        &mut self,
        now_us: u64,
        settings: &Settings,
        op: Op,
        outcome: Outcome,
        corrupt: bool,
    ) -> Option<Finished> {
        let config = settings.config();
        let index = config.servo_ids.iter().position(|&id| id == op.id());
        let is_state_read = is_state_read(&op);
        let job_matches = self.jobs.front().is_some_and(|j| j.op == op);
        if is_state_read && !job_matches {
            let i = index?;
            let s = self.servos.get_mut(i)?;
            match &outcome {
                Outcome::Answered(p) => {
                    let first = !s.health.ever_answered;
                    apply_state(&mut s.health, p);
                    s.read_us = now_us;
                    let speed_max = i64::from(config.motion.servo_speed_max_steps_per_s);
                    s.trusted = first || believable(s, now_us, speed_max);
                    if s.trusted {
                        s.trusted_position = s.health.position;
                        s.trusted_us = now_us;
                    } else if i < JOINTS {
                        self.jumped = Some(i);
                    }
                    if first {
                        self.adopt(now_us, i, p);
                    }
                    self.verify(settings, i);
                }
                _ => {
                    s.missed_us = now_us;
                    let h = &mut s.health;
                    h.comm_errors = h.comm_errors.wrapping_add(1);
                    h.corrupt_answers = corrupt;
                    h.misses = h.misses.saturating_add(1);
                    if h.misses >= config.timing.misses_before_lost {
                        h.answering = false;
                    }
                }
            }
            return None;
        }
        if !job_matches {
            return None;
        }
        let servo = index.and_then(|i| self.servos.get_mut(i));
        if let (Some(s), Outcome::Answered(p)) = (servo, &outcome) {
            s.health.fault_bits = p.code();
        }
        if outcome == Outcome::TimedOut {
            if let Some(job) = self.jobs.front_mut()
                && job.attempt < config.timing.retries
            {
                job.attempt += 1;
                return None;
            }
            if let Some(s) = index.and_then(|i| self.servos.get_mut(i)) {
                s.health.comm_errors = s.health.comm_errors.wrapping_add(1);
            }
        }
        let job = self.jobs.pop_front()?;
        Some(Finished {
            ticket: job.ticket?,
            id: op.id(),
            answer: match outcome {
                Outcome::Answered(p) => Some(p),
                _ => None,
            },
        })
    }

    /// Takes over what servo `index` is doing when the Atom hears it for the first time and
    /// has not told it anything yet: a servo that holds torque keeps its goal (the Atom
    /// restarted while the arm was on: the arm stays powered, a move in progress finishes,
    /// nothing goes limp or stops), a released one stays released.
    fn adopt(&mut self, now_us: u64, index: usize, packet: &Packet) {
        let Some(s) = self.servos.get_mut(index) else {
            return;
        };
        if s.commanded || !s.health.torque_reported {
            return;
        }
        s.health.torque_on = true;
        self.powered = true;
        let at = |addr: u8| usize::from(addr - STATE_READ_ADDR);
        let speed = packet.u16_at(at(reg::GOAL_SPEED)).unwrap_or(0) & 0x7FFF;
        let accel = packet
            .params()
            .get(at(reg::ACCELERATION))
            .copied()
            .unwrap_or(0);
        let goal = Goal {
            position: s.health.goal_reported,
            speed_steps_per_s: speed.max(1),
            accel: accel.max(1),
        };
        s.last_goal = Some(goal);
        // What its profile does with that goal, from where it is and how fast it moves.
        s.profile = Some(Segment {
            start_us: now_us,
            from: Motion {
                millisteps: i64::from(s.health.position.0) * 1000,
                millisteps_per_s: i64::from(s.health.speed_steps_per_s) * 1000,
            },
            goal_millisteps: i64::from(goal.position.0) * 1000,
            speed_millisteps_per_s: i64::from(goal.speed_steps_per_s) * 1000,
            accel_millisteps_per_s2: i64::from(goal.accel) * 100_000,
        });
    }

    /// The gripper's present position.
    pub fn gripper_position(&self) -> Steps {
        self.health(GRIPPER).map(|h| h.position).unwrap_or_default()
    }
}

/// True if `s`'s latest reading (at `now_us`) is one its servo could have made: no further from
/// the last believed one than the shaft turns at `speed_max` steps/s in the time between (plus
/// [`READ_SLACK_US`] for a reading that waited, and [`READ_SLACK_STEPS`]), across the encoder's
/// wrap. A released servo's shaft is turned by hand, however fast: always believed.
fn believable(s: &Servo, now_us: u64, speed_max: i64) -> bool {
    let h = &s.health;
    if !(h.torque_on && h.torque_reported) {
        return true;
    }
    let turn = i64::from(STEPS_PER_TURN);
    let d = (i64::from(h.position.0) - i64::from(s.trusted_position.0)).rem_euclid(turn);
    let moved = d.min(turn - d);
    let elapsed_us = now_us.saturating_sub(s.trusted_us) + READ_SLACK_US;
    let reach = speed_max.saturating_mul(elapsed_us.min(10_000_000) as i64) / 1_000_000;
    moved <= reach + READ_SLACK_STEPS
}

/// True if `op` reads a servo's state (the refresh's READ).
fn is_state_read(op: &Op) -> bool {
    matches!(
        op,
        Op::Read {
            addr: STATE_READ_ADDR,
            count: STATE_READ_LEN,
            ..
        }
    )
}

/// Servo state reads and banks that have read them, for the unit tests of the parts that act
/// on the servos.
#[cfg(test)]
pub(crate) mod test_support {
    use protocol_core::servo::{Packet, reg, to_sign_magnitude};

    use super::{STATE_READ_ADDR, STATE_READ_LEN, ServoBank};
    use crate::config::{AtomConfig, JOINTS, SERVOS};
    use crate::driver::{Op, Outcome};
    use crate::settings::Settings;

    /// The settings of a powered arm with the default configuration.
    pub fn powered() -> Settings {
        Settings::new(AtomConfig {
            powered_at_boot: true,
            ..AtomConfig::default()
        })
    }

    /// The state read (registers 40..=70) of servo `id` holding torque at `position`, moving at
    /// `speed` steps/s, its goal register at `goal`.
    pub fn state(id: u8, position: i16, speed: i16, goal: i16) -> Packet {
        let mut regs = [0u8; STATE_READ_LEN as usize];
        let mut put = |addr: u8, bytes: &[u8]| {
            let at = usize::from(addr - STATE_READ_ADDR);
            regs[at..at + bytes.len()].copy_from_slice(bytes);
        };
        put(reg::TORQUE_ENABLE, &[1]);
        put(reg::ACCELERATION, &[50]);
        put(
            reg::GOAL_POSITION,
            &to_sign_magnitude(goal, 15).to_le_bytes(),
        );
        put(reg::GOAL_SPEED, &1000u16.to_le_bytes());
        put(
            reg::PRESENT_POSITION,
            &to_sign_magnitude(position, 15).to_le_bytes(),
        );
        put(
            reg::PRESENT_SPEED,
            &to_sign_magnitude(speed, 15).to_le_bytes(),
        );
        put(reg::MOVING, &[u8::from(speed != 0)]);
        Packet::new(id, 0, &regs).expect("a state read fits a packet")
    }

    /// Reads servo `index` at `now_us` as [`state`] says.
    pub fn read(
        bank: &mut ServoBank,
        settings: &Settings,
        now_us: u64,
        index: usize,
        state: Packet,
    ) {
        let id = settings.config().servo_ids[index];
        let op = Op::Read {
            id,
            addr: STATE_READ_ADDR,
            count: STATE_READ_LEN,
        };
        assert_eq!(
            bank.finish(now_us, settings, op, Outcome::Answered(state), false),
            None
        );
    }

    /// Servo `index`'s state read at `now_us` gets no answer (timed out), `times` times.
    pub fn miss(bank: &mut ServoBank, settings: &Settings, now_us: u64, index: usize, times: u8) {
        let id = settings.config().servo_ids[index];
        for _ in 0..times {
            let op = Op::Read {
                id,
                addr: STATE_READ_ADDR,
                count: STATE_READ_LEN,
            };
            assert_eq!(
                bank.finish(now_us, settings, op, Outcome::TimedOut, false),
                None
            );
        }
    }

    /// A bank that read every servo at `now_us`: joint `j` at `positions[j]` moving at
    /// `speeds[j]` steps/s toward a goal far ahead (at rest: its goal is where it is), the
    /// gripper at 2048.
    pub fn bank_read(
        settings: &Settings,
        now_us: u64,
        positions: [i16; JOINTS],
        speeds: [i16; JOINTS],
    ) -> ServoBank {
        let mut bank = ServoBank::new(settings);
        for i in 0..SERVOS {
            let (position, speed) = if i < JOINTS {
                (positions[i], speeds[i])
            } else {
                (2048, 0)
            };
            let goal = position.saturating_add(speed.signum() * 1000);
            let id = settings.config().servo_ids[i];
            read(
                &mut bank,
                settings,
                now_us,
                i,
                state(id, position, speed, goal),
            );
        }
        bank
    }

    /// Reads every servo of `bank` again at `now_us`, at rest where it was last read, its goal
    /// register the goal it was last sent: time passed, nothing moved and no write was lost.
    pub fn reread(bank: &mut ServoBank, settings: &Settings, now_us: u64) {
        for i in 0..SERVOS {
            let position = bank.health(i).map_or(2048, |h| h.position.0);
            let goal = bank.last_goal(i).map_or(position, |g| g.position.0);
            let id = settings.config().servo_ids[i];
            read(bank, settings, now_us, i, state(id, position, 0, goal));
        }
    }

    /// A powered arm ([`powered`]) whose bank read every servo at rest at 2048 (every joint
    /// at 0 deg) at time 0.
    pub fn at_rest() -> (Settings, ServoBank) {
        let settings = powered();
        let bank = bank_read(&settings, 0, [2048; JOINTS], [0; JOINTS]);
        (settings, bank)
    }

    /// Every operation queued in `bank`, in order, each finished as sent.
    pub fn queued(bank: &mut ServoBank, settings: &Settings) -> std::vec::Vec<Op> {
        let mut ops = std::vec::Vec::new();
        while let Some(op) = bank.due_job() {
            ops.push(op.clone());
            bank.finish(0, settings, op, Outcome::Sent, false);
        }
        ops
    }
}

#[cfg(test)]
mod tests {
    use protocol_core::servo::Packet;

    use super::test_support::{at_rest, bank_read, powered, read, reread, state};
    use super::*;
    use crate::driver::Op;

    fn goal(position: i16) -> Goal {
        Goal {
            position: Steps(position),
            speed_steps_per_s: 500,
            accel: 20,
        }
    }

    #[test]
    fn goals_sent_before_the_write_merge_into_one_sync_write() {
        let (settings, mut bank) = at_rest();
        bank.send_goals(10, &settings, Goals::one(0, goal(2100)))
            .unwrap();
        bank.send_goals(20, &settings, Goals::one(1, goal(2200)))
            .unwrap();
        bank.send_goals(30, &settings, Goals::one(0, goal(2150)))
            .unwrap();
        let Some(Op::Broadcast(write)) = bank.take_goal_write(0, &settings) else {
            panic!("one SYNC WRITE");
        };
        // Two servos' move blocks (id + 7 bytes each) after the address and length.
        assert_eq!(write.params().len(), 2 + 2 * 8);
        assert_eq!(bank.take_goal_write(0, &settings), None, "taken");
        assert_eq!(
            bank.last_goal(0),
            Some(goal(2150)),
            "the newer goal of joint 1"
        );
        assert_eq!(bank.last_goal(1), Some(goal(2200)));
    }

    #[test]
    fn a_goal_outside_the_limits_or_powered_off_is_never_pending() {
        let (settings, mut bank) = at_rest();
        // Joint 2's limit is 140 deg: about 3641 steps.
        assert_eq!(
            bank.send_goals(0, &settings, Goals::one(1, goal(4000))),
            Err(AtomError::JointLimit(1))
        );
        assert!(bank.power(&settings, false));
        assert_eq!(
            bank.send_goals(0, &settings, Goals::one(0, goal(2100))),
            Err(AtomError::PoweredOff)
        );
        assert_eq!(bank.take_goal_write(0, &settings), None);
    }

    #[test]
    fn a_goal_lost_on_the_wire_is_repaired_at_most_three_times() {
        let (settings, mut bank) = at_rest();
        bank.send_goals(0, &settings, Goals::one(0, goal(2300)))
            .unwrap();
        assert!(bank.take_goal_write(0, &settings).is_some());
        for repair in 0..readback::MAX_REPAIRS {
            // The servo reports its old goal: the SYNC WRITE did not arrive.
            read(&mut bank, &settings, 1_000, 0, state(1, 2048, 0, 2048));
            assert!(
                bank.take_goal_write(0, &settings).is_some(),
                "repair {repair} re-sends the goal"
            );
        }
        read(&mut bank, &settings, 1_000, 0, state(1, 2048, 0, 2048));
        assert_eq!(bank.take_goal_write(0, &settings), None, "given up");
        // A goal that arrived needs no repair.
        bank.send_goals(0, &settings, Goals::one(0, goal(2400)))
            .unwrap();
        assert!(bank.take_goal_write(0, &settings).is_some());
        read(&mut bank, &settings, 2_000, 0, state(1, 2048, 100, 2400));
        assert_eq!(bank.take_goal_write(0, &settings), None);
    }

    #[test]
    fn a_lost_torque_write_is_repaired() {
        let (settings, mut bank) = at_rest();
        assert!(bank.set_torque(&settings, 2, false));
        assert!(bank.due_job().is_some(), "the torque write is queued");
        let job = bank.due_job().unwrap();
        assert_eq!(bank.finish(0, &settings, job, Outcome::Sent, false), None);
        // The servo still reports torque on: the write got lost.
        read(&mut bank, &settings, 1_000, 2, state(3, 2048, 0, 2048));
        assert_eq!(
            bank.due_job(),
            Op::write(3, reg::TORQUE_ENABLE, &[0]),
            "written again"
        );
    }

    #[test]
    fn a_read_with_a_ticket_comes_back_once_done_and_a_timeout_is_retried() {
        let (settings, mut bank) = at_rest();
        let op = Op::Read {
            id: 4,
            addr: 21,
            count: 3,
        };
        assert!(bank.queue_read(op.clone(), Ticket(5)));
        for _ in 0..settings.config().timing.retries {
            assert_eq!(
                bank.finish(0, &settings, op.clone(), Outcome::TimedOut, false),
                None
            );
            assert_eq!(bank.due_job(), Some(op.clone()), "tried again");
        }
        let answer = Packet::new(4, 0, &[1, 2, 3]).unwrap();
        let done = bank.finish(0, &settings, op, Outcome::Answered(answer.clone()), false);
        assert_eq!(
            done,
            Some(Finished {
                ticket: Ticket(5),
                id: 4,
                answer: Some(answer),
            })
        );
        assert_eq!(bank.due_job(), None);
    }

    #[test]
    fn present_angles_move_on_with_the_read_speed_at_the_time_asked() {
        let settings = powered();
        let bank = bank_read(&settings, 0, [2048; JOINTS], [1000, 0, 0, 0, 0, 0]);
        let at = |now_us| bank.present_angles(now_us, &settings)[0];
        assert_eq!(at(0), settings.angle(0, Steps(2048)));
        // 1000 steps/s for 10 ms: 10 steps further.
        assert_eq!(at(10_000), settings.angle(0, Steps(2058)));
        assert!(bank.joints_moving(0));
        assert!(bank.servo_moving(0, 0));
    }

    #[test]
    fn a_servo_that_misses_reads_is_lost_and_probed_only_now_and_then() {
        let (settings, mut bank) = at_rest();
        let misses = settings.config().timing.misses_before_lost;
        // One round at `now_us`: the servo at index `silent` times out.
        let round = |bank: &mut ServoBank, now_us: u64, silent: usize| {
            for _ in 0..SERVOS {
                let op = bank.next_refresh_op(&settings).unwrap();
                let i = settings
                    .config()
                    .servo_ids
                    .iter()
                    .position(|&id| id == op.id());
                let outcome = if i == Some(silent) {
                    Outcome::TimedOut
                } else {
                    Outcome::Answered(state(op.id(), 2048, 0, 2048))
                };
                bank.finish(now_us, &settings, op, outcome, false);
            }
        };
        let probes_in_six_rounds = |bank: &mut ServoBank, id: u8| {
            let ids: heapless::Vec<u8, 64> = (0..6 * 7)
                .map(|_| bank.next_refresh_op(&settings).unwrap().id())
                .collect();
            ids.iter().filter(|&&i| i == id).count()
        };
        // Joint 2's replies lost for a moment: it is read in every round, to be seen again.
        for _ in 0..misses {
            round(&mut bank, 4_000, 1);
        }
        assert!(!bank.health(1).unwrap().answering);
        assert_eq!(probes_in_six_rounds(&mut bank, 2), 6);
        // The gripper silent for over a second: probed only now and then.
        for k in 0..misses {
            round(&mut bank, 1_500_000 + u64::from(k), GRIPPER);
        }
        assert!(!bank.health(GRIPPER).unwrap().answering);
        assert!(probes_in_six_rounds(&mut bank, 7) <= 1);
    }

    #[test]
    fn a_reading_the_servo_cannot_have_made_is_not_believed() {
        let (settings, mut bank) = at_rest();
        assert!(bank.fresh(0, 0));
        // 4.4 ms later joint 1 reads 40 steps on: a servo turns that far.
        read(&mut bank, &settings, 4_400, 0, state(1, 2_088, 900, 2_500));
        assert!(bank.fresh(4_400, 0));
        assert_eq!(bank.take_jump(), None);
        // Then 0 (a reply with nothing in it): half a turn in 4.4 ms is not a reading.
        read(&mut bank, &settings, 8_800, 0, state(1, 0, 0, 2_500));
        assert_eq!(bank.take_jump(), Some(0));
        assert_eq!(bank.take_jump(), None, "taken once");
        assert!(!bank.fresh(8_800, 0), "not believed");
        assert_eq!(bank.unknown_joint(8_800), Some(0));
        assert_eq!(bank.observed(8_800, 0), None, "no goal is made from it");
        assert!(bank.joints_moving(8_800));
        // The next reading consistent with the last believed one is believed again.
        read(&mut bank, &settings, 13_200, 0, state(1, 2_120, 700, 2_500));
        assert!(bank.fresh(13_200, 0));
        // Across the encoder's wrap a step is a step.
        let mut bank = bank_read(
            &settings,
            0,
            [2048, 2048, 2048, 2048, 2048, 4095],
            [0; JOINTS],
        );
        read(&mut bank, &settings, 1_000, 5, state(6, 1, 0, 1));
        assert_eq!(bank.take_jump(), None);
    }

    #[test]
    fn a_joint_is_known_only_while_its_readings_are_fresh() {
        let (settings, mut bank) = at_rest();
        assert!(
            !bank.joints_moving(FRESH_STATE_US),
            "every joint at rest on its reading"
        );
        assert_eq!(bank.unknown_joint(FRESH_STATE_US), None);
        // 50 ms and a bit without a reading: nobody knows where the arm is.
        assert_eq!(bank.unknown_joint(FRESH_STATE_US + 1), Some(0));
        assert!(bank.joints_moving(FRESH_STATE_US + 1), "is moving says yes");
        assert_eq!(bank.observed(ESTIMATE_HORIZON_US + 1, 0), None);
        // All but joint 4 read again: joint 4 is the one unknown.
        for i in (0..SERVOS).filter(|&i| i != 3) {
            let id = settings.config().servo_ids[i];
            read(&mut bank, &settings, 60_000, i, state(id, 2048, 0, 2048));
        }
        assert_eq!(bank.unknown_joint(60_000), Some(3));
        assert!(bank.joints_moving(60_000));
        // A goal sent but not reached yet: not at rest on it.
        reread(&mut bank, &settings, 70_000);
        assert!(!bank.joints_moving(70_000));
        bank.send_goals(70_000, &settings, Goals::one(0, goal(2_300)))
            .unwrap();
        assert!(bank.joints_moving(70_000));
    }

    #[test]
    fn a_written_goal_is_followed_by_the_servos_profile() {
        let (settings, mut bank) = at_rest();
        let holding = Motion {
            millisteps: 2_048_000,
            millisteps_per_s: 0,
        };
        assert_eq!(
            bank.commanded(0, 0),
            Some(holding),
            "the goal it held, taken over"
        );
        bank.send_goals(0, &settings, Goals::one(0, goal(2_300)))
            .unwrap();
        assert_eq!(bank.commanded(0, 0), Some(holding), "not written yet");
        assert!(bank.take_goal_write(1_000, &settings).is_some());
        // 500 steps/s at 2000 steps/s^2: 0.25 s to full speed, 62.5 steps; the write takes
        // a few hundred microseconds on the wire, and the servo acts on it at its next control
        // step.
        let m = bank.commanded(1_000 + 250_000 + 1_000, 0).unwrap();
        assert!((m.millisteps - 2_110_500).abs() < 1_500, "{m:?}");
        assert_eq!(m.millisteps_per_s, 500_000);
        let end = bank.commanded(2_000_000, 0).unwrap();
        assert_eq!(end.millisteps, 2_300_000, "on its goal");
        assert_eq!(end.millisteps_per_s, 0);
        // Released, it holds no goal: nothing to work out.
        assert!(bank.set_torque(&settings, 0, false));
        assert_eq!(bank.commanded(2_000_000, 0), None);
    }
}
