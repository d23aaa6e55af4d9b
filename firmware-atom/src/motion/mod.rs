//! The motion controller: what the arm is doing and what it does next.
//!
//! * **Joint moves** (send angles, encoders, joint jogs, increments) are planned so that every
//!   joint arrives together ([`plan`]) and carried out by the servos' own ramps.
//! * **Cartesian paths** (straight lines, circular arcs, Cartesian jogs) are walked by the
//!   firmware every interpolation period ([`path`]) and followed by the joints ([`follow`]). An
//!   arc is walked whole with the inverse kinematics before it is accepted.
//! * **Streams**: in fresh mode, full targets that arrive within [`STREAM_GAP_MAX_US`] of each
//!   other (a ROS node sending `send_angles` on every joint state) are followed without
//!   stopping between them, each reached about one stream period after it arrived; a stream
//!   that stops (no target for [`STREAM_GAP_MAX_US`]: a late target is not its end) ends at
//!   its last target.
//! * **Braking**: stop, pause, jog stop, the jog watchdog and a new move that replaces a
//!   moving one bring every joint to rest at the servos' full deceleration, all joints along
//!   the path they were on ([`brake`]); a replacing move starts from rest.
//! * **Queue mode** (fresh mode off): up to [`MOTION_QUEUE`] moves wait their turn.
//! * **Jog watchdog**: a continuous jog stops when no host command has arrived for
//!   [`crate::TimingBudget::jog_watchdog_us`] (pymycobot has no keep-alive); the Basic's own
//!   liveness probe does not count.

mod brake;
mod follow;
mod path;
pub mod plan;
mod stream;

use heapless::Deque;
use protocol_core::command::Pose;
use protocol_core::units::Centideg;

use crate::bank::ServoBank;
use crate::config::JOINTS;
use crate::error::AtomError;
use crate::settings::Settings;
use brake::Braking;
pub use brake::stop_one;
use follow::{Follower, Pace};
pub use path::plan_arc;
use path::{PathRunner, Step};
pub use plan::{IN_POSITION_CENTIDEG, MOVE_OVERTIME_US, angles_match};
pub use stream::STREAM_GAP_MAX_US;
use stream::{StreamClock, stream_ended};

/// Motions waiting in queue mode (fresh mode 0). 16 moves: a script sending a short path
/// without waiting; more is refused (answer 0) rather than silently dropped.
pub const MOTION_QUEUE: usize = 16;

/// Longest a stop waits, beyond its computed duration, for the joints to report rest before
/// the move that replaces it starts anyway (a stalled servo must not block it).
const BRAKE_SETTLE_MAX_US: u64 = 200_000;

/// A continuous jog direction.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum JogDirection {
    /// Toward smaller values.
    Negative,
    /// Toward larger values.
    Positive,
}

/// How the end travels to a target.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Way {
    /// Every joint on its own, all arriving together.
    Joints,
    /// Along a straight line to this pose (send coords mode 1).
    Line(Pose),
    /// Along the circle through the pose it starts from, `via` and `end` (0x8B, 0x8C).
    Arc {
        /// A pose the arc passes through.
        via: Pose,
        /// Where the arc ends.
        end: Pose,
    },
}

impl Way {
    /// The pose a Cartesian path ends at.
    pub fn end_pose(&self) -> Option<Pose> {
        match self {
            Self::Joints => None,
            Self::Line(end) | Self::Arc { end, .. } => Some(*end),
        }
    }
}

/// A move to joint angles, and the way there.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct Target {
    /// Joint targets; `None` leaves a joint where it is going.
    pub angles: [Option<Centideg>; JOINTS],
    /// Speed, percent.
    pub speed_percent: u8,
    /// How the end gets there; for a Cartesian path `angles` solve its end pose.
    pub way: Way,
}

impl Target {
    /// A joint-interpolated move of the joints given in `angles`.
    pub fn joints(angles: [Option<Centideg>; JOINTS], speed_percent: u8) -> Self {
        Self {
            angles,
            speed_percent,
            way: Way::Joints,
        }
    }
}

/// Distance within which the arm counts as already at the start of an arc (0x8B), so no line
/// leads to it: 0.5 mm (5 wire units) and 0.5 deg (50).
const AT_ARC_START: (i32, i32) = (5, 50);

/// A continuous jog.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
enum Jog {
    /// Joint `joint` (0-based) toward its limit.
    Joint {
        joint: usize,
        direction: JogDirection,
    },
    /// The end along or about a base axis (0..2 x, y, z; 3..5 about x, y, z).
    Pose {
        axis: usize,
        direction: JogDirection,
    },
}

/// Something to start.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
enum Order {
    Move(Target),
    Jog { jog: Jog, speed_percent: u8 },
}

/// What the arm is doing.
// One instance lives in the Atom: the size of the path variant costs nothing extra.
#[allow(clippy::large_enum_variant)]
#[derive(Clone, Copy, Debug)]
enum Activity {
    /// Holding still.
    Idle,
    /// A planned joint move toward `target`, planned to take `duration_us` from `started_us`.
    Joint {
        target: [Centideg; JOINTS],
        speed_percent: u8,
        started_us: u64,
        duration_us: u64,
        jog: Option<Jog>,
    },
    /// A Cartesian path; `target` is where it ends (a line, an arc: `way`) or has got to (a
    /// jog: `way` is `None`).
    Path {
        runner: PathRunner,
        follower: Follower,
        target: [Centideg; JOINTS],
        way: Option<Way>,
        speed_percent: u8,
        jog: Option<Jog>,
    },
    /// Following a stream whose last target arrived at `last_us`.
    Stream {
        follower: Follower,
        target: [Centideg; JOINTS],
        speed_percent: u8,
        period_us: u64,
        last_us: u64,
    },
    /// Coming to rest at `rest` by `until_us`, then starting `then`.
    Braking {
        rest: [Centideg; JOINTS],
        until_us: u64,
        then: Option<Order>,
    },
}

/// The motion controller. See the [module doc](self).
#[derive(Clone, Debug)]
pub struct MotionController {
    activity: Activity,
    queue: Deque<Target, MOTION_QUEUE>,
    paused: Option<Target>,
    last_host_cmd_us: u64,
    clock: StreamClock,
}

impl Default for MotionController {
    fn default() -> Self {
        Self::new()
    }
}

impl MotionController {
    /// A controller holding still.
    pub fn new() -> Self {
        Self {
            activity: Activity::Idle,
            queue: Deque::new(),
            paused: None,
            last_host_cmd_us: 0,
            clock: StreamClock::default(),
        }
    }

    /// Notes that a host command arrived at `now_us`: a sign of life that keeps a jog going.
    pub fn note_host_command(&mut self, now_us: u64) {
        self.last_host_cmd_us = now_us;
    }

    /// Accepts a move: in fresh mode it starts now (following a stream, or replacing the
    /// current motion after braking), in queue mode it waits for the moves before it.
    pub fn submit(
        &mut self,
        now_us: u64,
        target: Target,
        bank: &mut ServoBank,
        settings: &Settings,
    ) -> Result<(), AtomError> {
        check(bank, settings, &target)?;
        if !settings.fresh_mode() {
            return if matches!(self.activity, Activity::Idle)
                && self.queue.is_empty()
                && self.paused.is_none()
            {
                self.start(now_us, Order::Move(target), bank, settings)
            } else {
                self.queue.push_back(target).map_err(|_| AtomError::Busy)
            };
        }
        self.queue.clear();
        self.paused = None;
        let full = full_angles(&target.angles);
        let period = match full {
            Some(_) => self.clock.arrival(now_us),
            None => {
                self.clock.reset();
                None
            }
        };
        match (full, period) {
            (Some(angles), Some(period_us)) => self.follow_stream(
                now_us,
                angles,
                target.speed_percent,
                period_us,
                bank,
                settings,
            ),
            _ => self.replace(now_us, Order::Move(target), bank, settings),
        }
    }

    /// Starts a continuous jog of joint `j` toward its limit. The same jog again only changes
    /// its speed; another motion is braked first.
    pub fn jog_joint(
        &mut self,
        now_us: u64,
        j: usize,
        direction: JogDirection,
        speed_percent: u8,
        bank: &mut ServoBank,
        settings: &Settings,
    ) -> Result<(), AtomError> {
        let end = jog_end(bank, settings, j, direction)?;
        let jog = Jog::Joint {
            joint: j,
            direction,
        };
        self.forget_plans();
        if let Activity::Joint {
            jog: Some(running), ..
        } = self.activity
            && running == jog
        {
            let mut angles = [None; JOINTS];
            if let Some(slot) = angles.get_mut(j) {
                *slot = Some(end);
            }
            return self.start_joint_move(
                now_us,
                Target::joints(angles, speed_percent),
                Some(jog),
                bank,
                settings,
            );
        }
        self.replace(now_us, Order::Jog { jog, speed_percent }, bank, settings)
    }

    /// Starts a continuous Cartesian jog: `axis` 0..2 along x, y, z, 3..5 about the base x, y,
    /// z axes. The same jog at the same speed again changes nothing; another motion is braked
    /// first.
    pub fn jog_pose(
        &mut self,
        now_us: u64,
        axis: usize,
        direction: JogDirection,
        speed_percent: u8,
        bank: &mut ServoBank,
        settings: &Settings,
    ) -> Result<(), AtomError> {
        if !bank.powered() {
            return Err(AtomError::PoweredOff);
        }
        let jog = Jog::Pose { axis, direction };
        self.forget_plans();
        if let Activity::Path {
            jog: Some(running),
            speed_percent: running_speed,
            ..
        } = self.activity
            && running == jog
            && running_speed == speed_percent
        {
            return Ok(());
        }
        self.replace(now_us, Order::Jog { jog, speed_percent }, bank, settings)
    }

    /// Stops the arm (0x29, 0x34 jog stop): brakes every joint and forgets queued and paused
    /// moves.
    pub fn stop(&mut self, now_us: u64, bank: &mut ServoBank, settings: &Settings) {
        self.forget_plans();
        self.brake(now_us, None, bank, settings);
    }

    /// Pauses the current move (0x26): brakes, and remembers the move for [`Self::resume`].
    pub fn pause(&mut self, now_us: u64, bank: &mut ServoBank, settings: &Settings) {
        let resumable = match self.activity {
            Activity::Joint {
                target,
                speed_percent,
                jog: None,
                ..
            }
            | Activity::Stream {
                target,
                speed_percent,
                ..
            } => Some(Target::joints(target.map(Some), speed_percent)),
            Activity::Path {
                runner,
                target,
                way: Some(way),
                speed_percent,
                ..
            } => Some(Target {
                angles: target.map(Some),
                speed_percent,
                way: rest_of(way, &runner),
            }),
            Activity::Braking {
                then: Some(Order::Move(t)),
                ..
            } => Some(t),
            _ => None,
        };
        if resumable.is_some() {
            self.paused = resumable;
        }
        self.clock.reset();
        self.brake(now_us, None, bank, settings);
    }

    /// Resumes a paused move (0x28); nothing to do if none is paused.
    pub fn resume(
        &mut self,
        now_us: u64,
        bank: &mut ServoBank,
        settings: &Settings,
    ) -> Result<(), AtomError> {
        match self.paused.take() {
            Some(t) => self.replace(now_us, Order::Move(t), bank, settings),
            None => Ok(()),
        }
    }

    /// Brakes and stays (a servo is about to be calibrated); queued moves wait.
    pub fn halt(&mut self, now_us: u64, bank: &mut ServoBank, settings: &Settings) {
        self.clock.reset();
        self.brake(now_us, None, bank, settings);
    }

    /// Forgets every motion without sending anything (the servos are about to be released).
    pub fn abandon(&mut self) {
        self.forget_plans();
        self.activity = Activity::Idle;
    }

    /// Forgets queued moves (0x05); the current one continues.
    pub fn clear_queue(&mut self) {
        self.queue.clear();
    }

    /// True while a move is paused.
    pub fn is_paused(&self) -> bool {
        self.paused.is_some()
    }

    /// True while a motion runs (planned, walked, streamed or braking).
    pub fn is_active(&self) -> bool {
        !matches!(self.activity, Activity::Idle)
    }

    /// The joint angles the arm is going to (the present angles when idle).
    pub fn planned_angles(&self, bank: &ServoBank, settings: &Settings) -> [Centideg; JOINTS] {
        match &self.activity {
            Activity::Idle => bank.present_angles(settings),
            Activity::Joint { target, .. }
            | Activity::Path { target, .. }
            | Activity::Stream { target, .. } => *target,
            Activity::Braking {
                rest,
                then: Some(Order::Move(t)),
                ..
            } => core::array::from_fn(|j| {
                let at_rest = rest.get(j).copied().unwrap_or_default();
                t.angles.get(j).copied().flatten().unwrap_or(at_rest)
            }),
            Activity::Braking { rest, .. } => *rest,
        }
    }

    /// The pose a straight line or an arc is going to, if one runs.
    pub fn planned_pose(&self) -> Option<Pose> {
        match &self.activity {
            Activity::Path { way, .. } => way.and_then(|w| w.end_pose()),
            Activity::Braking {
                then: Some(Order::Move(t)),
                ..
            } => t.way.end_pose(),
            _ => None,
        }
    }

    /// Accepts a circular arc (0x8B, 0x8C) through `via` to `end` at `speed_percent`: from
    /// `begin`, reached first along a straight line (unless the arm is there already), or from
    /// where the arm is. The whole arc is walked with the inverse kinematics before anything
    /// moves ([`plan_arc`]); in fresh mode it replaces the current motion, in queue mode its
    /// parts wait their turn.
    #[allow(clippy::too_many_arguments)]
    pub fn submit_arc(
        &mut self,
        now_us: u64,
        begin: Option<Pose>,
        via: Pose,
        end: Pose,
        speed_percent: u8,
        bank: &mut ServoBank,
        settings: &Settings,
    ) -> Result<(), AtomError> {
        if !bank.powered() {
            return Err(AtomError::PoweredOff);
        }
        // Where the arc starts from: where the arm comes to rest (fresh mode), or where the
        // moves before it end (queue mode).
        let mut from = if settings.fresh_mode() {
            bank.present_angles(settings)
        } else {
            self.queue
                .back()
                .and_then(|t| full_angles(&t.angles))
                .unwrap_or_else(|| self.planned_angles(bank, settings))
        };
        let mut parts: heapless::Vec<Target, 2> = heapless::Vec::new();
        if let Some(begin) = begin {
            let cart = settings.cart();
            let here =
                crate::cartesian::from_kin(&cart.model().forward(&crate::cartesian::joints(&from)));
            if !poses_within(&here, &begin, AT_ARC_START) {
                let angles = cart.inverse(&begin, &from)?;
                let line = Target {
                    angles: angles.map(Some),
                    speed_percent,
                    way: Way::Line(begin),
                };
                check(bank, settings, &line)?;
                parts.push(line).map_err(|_| AtomError::Busy)?;
                from = angles;
            }
        }
        let (_, angles) = plan_arc(settings, &from, &via, &end)?;
        let arc = Target {
            angles: angles.map(Some),
            speed_percent,
            way: Way::Arc { via, end },
        };
        check(bank, settings, &arc)?;
        parts.push(arc).map_err(|_| AtomError::Busy)?;
        let mut parts = parts.into_iter();
        let Some(first) = parts.next() else {
            return Ok(());
        };
        if settings.fresh_mode() {
            self.forget_plans();
            self.replace(now_us, Order::Move(first), bank, settings)?;
            for t in parts {
                self.queue.push_back(t).map_err(|_| AtomError::Busy)?;
            }
            return Ok(());
        }
        if MOTION_QUEUE - self.queue.len() < 1 + parts.len() {
            return Err(AtomError::Busy);
        }
        if matches!(self.activity, Activity::Idle) && self.queue.is_empty() && self.paused.is_none()
        {
            self.start(now_us, Order::Move(first), bank, settings)?;
        } else {
            self.queue.push_back(first).map_err(|_| AtomError::Busy)?;
        }
        for t in parts {
            self.queue.push_back(t).map_err(|_| AtomError::Busy)?;
        }
        Ok(())
    }

    /// Runs what is due at `now_us`: the jog watchdog, the next point of a path, the end of a
    /// stream or a stop, arrival, and the next queued move. An error (a path that cannot go
    /// on, a queued move that became impossible) has stopped the arm and is to be recorded.
    pub fn update(
        &mut self,
        now_us: u64,
        bank: &mut ServoBank,
        settings: &Settings,
    ) -> Result<(), AtomError> {
        let watchdog_us = settings.config().timing.jog_watchdog_us;
        if self.jogging() && now_us.saturating_sub(self.last_host_cmd_us) >= watchdog_us {
            self.stop(now_us, bank, settings);
            return Ok(());
        }
        let outcome = self.advance(now_us, bank, settings);
        if let Err(e) = outcome {
            self.forget_plans();
            self.brake(now_us, None, bank, settings);
            return Err(e);
        }
        if matches!(self.activity, Activity::Idle)
            && self.paused.is_none()
            && let Some(next) = self.queue.pop_front()
        {
            return self.start(now_us, Order::Move(next), bank, settings);
        }
        Ok(())
    }

    fn advance(
        &mut self,
        now_us: u64,
        bank: &mut ServoBank,
        settings: &Settings,
    ) -> Result<(), AtomError> {
        let period_us = settings.config().timing.interpolation_period_us;
        // What comes after the present activity, if it ends now.
        let mut next = None;
        let mut then = None;
        match &mut self.activity {
            Activity::Idle => {}
            Activity::Joint {
                target,
                started_us,
                duration_us,
                ..
            } => {
                let elapsed = now_us.saturating_sub(*started_us);
                if arrived(bank, settings, target) || elapsed > *duration_us + MOVE_OVERTIME_US {
                    next = Some(Activity::Idle);
                }
            }
            Activity::Path {
                runner,
                follower,
                target,
                jog,
                speed_percent,
                ..
            } => {
                if let Step::Point { angles, last } = runner.step(now_us, settings)? {
                    if jog.is_some() {
                        *target = angles;
                    }
                    let cap = runner.joint_speed_cap();
                    let goals = follower.goals_towards(
                        bank,
                        settings,
                        &angles,
                        period_us,
                        cap,
                        Pace::Together,
                        last,
                    );
                    bank.send_goals(settings, goals)?;
                    if last {
                        next = Some(arriving(now_us, angles, *speed_percent, period_us));
                    }
                }
            }
            Activity::Stream {
                follower,
                target,
                speed_percent,
                period_us: stream_period_us,
                last_us,
            } => {
                if stream_ended(now_us, *last_us) {
                    let cap = settings.config().joint_speed_steps(*speed_percent);
                    let goals = follower.goals_towards(
                        bank,
                        settings,
                        target,
                        *stream_period_us,
                        cap,
                        Pace::Free,
                        true,
                    );
                    bank.send_goals(settings, goals)?;
                    next = Some(arriving(now_us, *target, *speed_percent, *stream_period_us));
                }
            }
            Activity::Braking {
                until_us,
                then: after,
                ..
            } => {
                let settled = !bank.joints_moving() || now_us >= *until_us + BRAKE_SETTLE_MAX_US;
                if now_us >= *until_us && settled {
                    then = after.take();
                    next = Some(Activity::Idle);
                }
            }
        }
        if let Some(activity) = next {
            self.activity = activity;
        }
        match then {
            Some(order) => self.start(now_us, order, bank, settings),
            None => Ok(()),
        }
    }

    /// True while a continuous jog runs (the watchdog's concern).
    fn jogging(&self) -> bool {
        matches!(
            self.activity,
            Activity::Joint { jog: Some(_), .. } | Activity::Path { jog: Some(_), .. }
        )
    }

    /// Forgets queued and paused moves and any stream.
    fn forget_plans(&mut self) {
        self.queue.clear();
        self.paused = None;
        self.clock.reset();
    }

    /// Starts `order` now if the arm is still, or after braking if it moves.
    fn replace(
        &mut self,
        now_us: u64,
        order: Order,
        bank: &mut ServoBank,
        settings: &Settings,
    ) -> Result<(), AtomError> {
        if self.is_active() || bank.joints_moving() {
            self.brake(now_us, Some(order), bank, settings);
            Ok(())
        } else {
            self.start(now_us, order, bank, settings)
        }
    }

    /// Brakes every joint; `then` starts once the arm is at rest.
    fn brake(
        &mut self,
        now_us: u64,
        then: Option<Order>,
        bank: &mut ServoBank,
        settings: &Settings,
    ) {
        if !bank.powered() {
            self.activity = Activity::Idle;
            return;
        }
        let stop = Braking::of(bank, settings);
        stop.send(bank, settings);
        self.activity = Activity::Braking {
            rest: stop.rest,
            until_us: now_us + stop.duration_us,
            then,
        };
    }

    fn start(
        &mut self,
        now_us: u64,
        order: Order,
        bank: &mut ServoBank,
        settings: &Settings,
    ) -> Result<(), AtomError> {
        match order {
            Order::Move(target) => match target.way {
                Way::Line(_) | Way::Arc { .. } => self.start_path(now_us, target, bank, settings),
                Way::Joints => self.start_joint_move(now_us, target, None, bank, settings),
            },
            Order::Jog {
                jog: jog @ Jog::Joint { joint, direction },
                speed_percent,
            } => {
                let end = jog_end(bank, settings, joint, direction)?;
                let mut angles = [None; JOINTS];
                if let Some(slot) = angles.get_mut(joint) {
                    *slot = Some(end);
                }
                let target = Target::joints(angles, speed_percent);
                self.start_joint_move(now_us, target, Some(jog), bank, settings)
            }
            Order::Jog {
                jog: jog @ Jog::Pose { axis, direction },
                speed_percent,
            } => {
                if !bank.powered() {
                    return Err(AtomError::PoweredOff);
                }
                let present = bank.present_angles(settings);
                let positive = direction == JogDirection::Positive;
                let runner =
                    PathRunner::jog(settings, now_us, &present, axis, positive, speed_percent);
                self.activity = Activity::Path {
                    runner,
                    follower: Follower::default(),
                    target: present,
                    way: None,
                    speed_percent,
                    jog: Some(jog),
                };
                Ok(())
            }
        }
    }

    /// Sends the goals of a planned joint move now.
    fn start_joint_move(
        &mut self,
        now_us: u64,
        target: Target,
        jog: Option<Jog>,
        bank: &mut ServoBank,
        settings: &Settings,
    ) -> Result<(), AtomError> {
        check(bank, settings, &target)?;
        let steps = core::array::from_fn(|j| {
            target
                .angles
                .get(j)
                .copied()
                .flatten()
                .map(|a| settings.goal_steps(j, a))
        });
        let (goals, duration_us) = plan::plan_joint_move(
            settings.config(),
            &bank.present_steps(),
            &steps,
            target.speed_percent,
        );
        bank.send_goals(settings, goals)?;
        let present = bank.present_angles(settings);
        let full = core::array::from_fn(|j| {
            let holding = bank.last_goal(j).map(|g| settings.angle(j, g.position));
            target
                .angles
                .get(j)
                .copied()
                .flatten()
                .or(holding)
                .unwrap_or(present.get(j).copied().unwrap_or_default())
        });
        self.activity = Activity::Joint {
            target: full,
            speed_percent: target.speed_percent,
            started_us: now_us,
            duration_us,
            jog,
        };
        Ok(())
    }

    /// Starts the Cartesian path of `target` (a straight line or an arc) from the present
    /// position; `target.angles` solve its end.
    fn start_path(
        &mut self,
        now_us: u64,
        target: Target,
        bank: &mut ServoBank,
        settings: &Settings,
    ) -> Result<(), AtomError> {
        check(bank, settings, &target)?;
        let present = bank.present_angles(settings);
        let speed = target.speed_percent;
        let runner = match target.way {
            Way::Line(pose) => PathRunner::line(settings, now_us, &present, &pose, speed)?,
            Way::Arc { via, end } => {
                PathRunner::arc(settings, now_us, &present, &via, &end, speed)?
            }
            Way::Joints => return Err(AtomError::Invalid),
        };
        self.activity = Activity::Path {
            runner,
            follower: Follower::default(),
            target: core::array::from_fn(|j| {
                let here = present.get(j).copied().unwrap_or_default();
                target.angles.get(j).copied().flatten().unwrap_or(here)
            }),
            way: Some(target.way),
            speed_percent: target.speed_percent,
            jog: None,
        };
        Ok(())
    }

    /// Follows the next target of a stream that arrives every `period_us`.
    fn follow_stream(
        &mut self,
        now_us: u64,
        angles: [Centideg; JOINTS],
        speed_percent: u8,
        period_us: u64,
        bank: &mut ServoBank,
        settings: &Settings,
    ) -> Result<(), AtomError> {
        let mut follower = match self.activity {
            Activity::Stream { follower, .. } => follower,
            _ => Follower::default(),
        };
        let cap = settings.config().joint_speed_steps(speed_percent);
        let goals =
            follower.goals_towards(bank, settings, &angles, period_us, cap, Pace::Free, false);
        bank.send_goals(settings, goals)?;
        self.activity = Activity::Stream {
            follower,
            target: angles,
            speed_percent,
            period_us,
            last_us: now_us,
        };
        Ok(())
    }
}

/// The wait for a followed sequence's last target to be reached.
fn arriving(
    now_us: u64,
    target: [Centideg; JOINTS],
    speed_percent: u8,
    period_us: u64,
) -> Activity {
    Activity::Joint {
        target,
        speed_percent,
        started_us: now_us,
        duration_us: period_us,
        jog: None,
    }
}

/// What is left of a Cartesian path interrupted by a pause: the rest of a line is the same
/// line; the rest of an arc is an arc through a pose ahead on the same circle (a straight line
/// when less than 2 mm are left).
fn rest_of(way: Way, runner: &PathRunner) -> Way {
    match way {
        Way::Arc { end, .. } if runner.remaining_um() >= 2_000 => Way::Arc {
            via: runner.halfway_ahead(),
            end,
        },
        Way::Arc { end, .. } => Way::Line(end),
        other => other,
    }
}

/// True if two poses are within `(position, orientation)` wire units of each other (0.1 mm,
/// 0.01 deg; angles wrap at 360 deg).
fn poses_within(a: &Pose, b: &Pose, (position, orientation): (i32, i32)) -> bool {
    a.to_array()
        .iter()
        .zip(&b.to_array())
        .enumerate()
        .all(|(i, (x, y))| {
            let d = (i32::from(*x) - i32::from(*y)).abs();
            if i < 3 {
                d <= position
            } else {
                d.min(36_000 - d) <= orientation
            }
        })
}

/// Checks a target against power and limits without moving.
fn check(bank: &ServoBank, settings: &Settings, target: &Target) -> Result<(), AtomError> {
    if !bank.powered() {
        return Err(AtomError::PoweredOff);
    }
    settings.check_angles(&target.angles)
}

/// All six angles, if all are given.
fn full_angles(angles: &[Option<Centideg>; JOINTS]) -> Option<[Centideg; JOINTS]> {
    let mut full = [Centideg(0); JOINTS];
    for (slot, a) in full.iter_mut().zip(angles) {
        *slot = (*a)?;
    }
    Some(full)
}

/// The limit a jog of joint `j` in `direction` runs to. A joint already past that limit (the
/// user tightened it) would be dragged backwards, against the direction asked for: refused.
fn jog_end(
    bank: &ServoBank,
    settings: &Settings,
    j: usize,
    direction: JogDirection,
) -> Result<Centideg, AtomError> {
    if !bank.powered() {
        return Err(AtomError::PoweredOff);
    }
    let limit = settings.limit(j).ok_or(AtomError::Invalid)?;
    let end = match direction {
        JogDirection::Negative => limit.min,
        JogDirection::Positive => limit.max,
    };
    let present = bank.present_angles(settings).get(j).copied().unwrap_or(end);
    let beyond = match direction {
        JogDirection::Positive => present > end,
        JogDirection::Negative => present < end,
    };
    if beyond {
        Err(AtomError::JointLimit(j))
    } else {
        Ok(end)
    }
}

/// True if the joints that answer are within [`IN_POSITION_CENTIDEG`] of `target` and none of
/// them reports moving (a servo that does not answer cannot arrive: it is judged by the rest).
fn arrived(bank: &ServoBank, settings: &Settings, target: &[Centideg; JOINTS]) -> bool {
    let present = bank.present_angles(settings);
    let seen: [Centideg; JOINTS] = core::array::from_fn(|j| {
        if bank.health(j).is_some_and(|h| h.answering) {
            present.get(j).copied().unwrap_or_default()
        } else {
            target.get(j).copied().unwrap_or_default()
        }
    });
    angles_match(&seen, target) && !bank.joints_moving()
}
