//! The motion controller: what the arm is doing and what it does next.
//!
//! * **Joint moves** (send angles, encoders, joint jogs, increments) are planned so that every
//!   joint arrives together ([`plan`]) and carried out by the servos' own ramps.
//! * **Cartesian paths** (straight lines, circular arcs, Cartesian jogs) are walked by the
//!   firmware every interpolation period ([`path`]) and followed by the joints ([`follow`]). An
//!   arc is walked whole with the inverse kinematics before it is accepted.
//! * **Streams**: in fresh mode, full targets that arrive within [`STREAM_GAP_MAX_US`] of each
//!   other (a ROS node sending `send_angles` on every joint state) are followed without
//!   stopping between them ([`stream`]): the Atom learns the stream's own clock from the
//!   arrivals and passes each target one period after its beat was due, whenever it arrived,
//!   or, for a host that samples its motion when it sends ([`timing`]), one period after its
//!   arrival; a late or missing target is bridged along the stream's own motion for up to
//!   [`BRIDGE_US`] (one period on arrivals). A stream that stops (no target for [`STREAM_GAP_MAX_US`]: a late
//!   target is not its end) ends at its last target.
//! * **Braking**: stop, pause, jog stop, the jog watchdog and a new move that replaces a
//!   moving one bring every joint to rest at the servos' full deceleration, all joints along
//!   the path they were on ([`brake`]); a replacing move starts from rest.
//! * **Queue mode** (fresh mode off): up to [`MOTION_QUEUE`] moves wait their turn.
//! * **Collisions** ([`crate::collision`]): a detected collision brings the arm to rest like a
//!   stop, with the blocked joint's goal where it stands, and every new motion is refused with
//!   the collision's code until [`MotionController::unlock`] (0x08, 0x10).
//! * **Jog watchdog**: a continuous jog stops when no host command has arrived for
//!   [`crate::TimingBudget::jog_watchdog_us`] (pymycobot has no keep-alive); the Basic's own
//!   liveness probe does not count.

mod brake;
mod follow;
mod path;
pub mod plan;
mod stream;
mod timing;

use heapless::Deque;
use protocol_core::command::{MoveMode, Pose, PositionTarget};
use protocol_core::units::Centideg;

use crate::bank::ServoBank;
use crate::collision::{Collision, Kind};
use crate::config::JOINTS;
use crate::context::Context;
use crate::error::AtomError;
use crate::tolerance;
use brake::Braking;
pub use brake::stop_one;
use follow::{Clock, Follower, Leg, Pace, millisteps};
pub use path::plan_arc;
use path::{PathRunner, Step};
pub use plan::MOVE_OVERTIME_US;
use stream::{Aim, StreamClock, stream_ended};
pub use stream::{BRIDGE_US, STREAM_GAP_MAX_US};

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

    /// A joint-interpolated move of joint `j` alone to `angle`.
    pub fn joint(j: usize, angle: Centideg, speed_percent: u8) -> Self {
        let mut angles = [None; JOINTS];
        if let Some(slot) = angles.get_mut(j) {
            *slot = Some(angle);
        }
        Self::joints(angles, speed_percent)
    }
}

/// What the host asks the arm to do: every new motion enters through
/// [`MotionController::command`], the one place that checks the arm is powered.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Command {
    /// A move to joint angles (send angles, encoders, increments).
    Move(Target),
    /// A move of the end to `pose`: joint-interpolated or along a straight line (`mode`).
    ToPose {
        /// Where the end goes.
        pose: Pose,
        /// Speed, percent.
        speed_percent: u8,
        /// Joint interpolation (0) or a straight line (1).
        mode: MoveMode,
    },
    /// A circular arc through `via` to `end`, from `begin` (reached first along a line) or
    /// from where the arm is (0x8B, 0x8C).
    Arc {
        /// Where the arc starts; `None`: where the arm is.
        begin: Option<Pose>,
        /// A pose the arc passes through.
        via: Pose,
        /// Where the arc ends.
        end: Pose,
        /// Speed, percent.
        speed_percent: u8,
    },
    /// A continuous jog of joint `joint` (0-based) toward its limit.
    JogJoint {
        /// The joint, 0-based.
        joint: usize,
        /// Toward which limit.
        direction: JogDirection,
        /// Speed, percent.
        speed_percent: u8,
    },
    /// A continuous Cartesian jog: `axis` 0..2 along x, y, z, 3..5 about the base x, y, z.
    JogPose {
        /// The axis.
        axis: usize,
        /// Which way.
        direction: JogDirection,
        /// Speed, percent.
        speed_percent: u8,
    },
}

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
    /// Following a stream whose last target arrived at `last_us`, heading for `aim` (a beat's
    /// target, or one played after its arrival; `None` until the clock has one).
    Stream {
        follower: Follower,
        aim: Option<Aim>,
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
    /// Why new motion is refused until unlocked: a collision.
    lock: Option<AtomError>,
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
            lock: None,
        }
    }

    /// Notes that a host command arrived at `now_us`: a sign of life that keeps a jog going.
    pub fn note_host_command(&mut self, now_us: u64) {
        self.last_host_cmd_us = now_us;
    }

    /// Whether a new motion may start, checked before it is planned so that a refused command
    /// changes nothing: every new motion of the joints passes here (moves, paths, jogs,
    /// streams, resume, drags and goal-register writes). Refused while the arm is powered off,
    /// after a collision until [`MotionController::unlock`], and while a joint has no fresh
    /// reading ([`ServoBank::fresh`]: a motion planned from where the arm is must know where
    /// that is). (Every goal, braking included, then passes [`crate::safety::check`], which
    /// refuses any goal while powered off.)
    pub fn may_move(&self, cx: &Context<'_>) -> Result<(), AtomError> {
        if !cx.bank.powered() {
            return Err(AtomError::PoweredOff);
        }
        self.lock.map_or(Ok(()), Err)?;
        match cx.bank.unknown_joint(cx.now_us) {
            Some(j) => Err(AtomError::StateLost(j)),
            None => Ok(()),
        }
    }

    /// Accepts a new motion: refused unless [`MotionController::may_move`], then each kind of
    /// motion checks its own rules.
    pub fn command(&mut self, cx: &mut Context<'_>, command: Command) -> Result<(), AtomError> {
        self.may_move(cx)?;
        match command {
            Command::Move(target) => self.submit(cx, target),
            Command::ToPose {
                pose,
                speed_percent,
                mode,
            } => self.move_to_pose(cx, pose, speed_percent, mode),
            Command::Arc {
                begin,
                via,
                end,
                speed_percent,
            } => self.submit_arc(cx, begin, via, end, speed_percent),
            Command::JogJoint {
                joint,
                direction,
                speed_percent,
            } => self.jog_joint(cx, joint, direction, speed_percent),
            Command::JogPose {
                axis,
                direction,
                speed_percent,
            } => self.jog_pose(cx, axis, direction, speed_percent),
        }
    }

    /// Accepts a move: in fresh mode it starts now (following a stream, or replacing the
    /// current motion after braking), in queue mode it waits for the moves before it.
    fn submit(&mut self, cx: &mut Context<'_>, target: Target) -> Result<(), AtomError> {
        cx.settings.check_angles(&target.angles)?;
        if !cx.settings.fresh_mode() {
            return if self.idle_with_nothing_waiting() {
                self.start(cx, Order::Move(target))
            } else {
                self.queue.push_back(target).map_err(|_| AtomError::Busy)
            };
        }
        self.queue.clear();
        self.paused = None;
        let full = full_angles(&target.angles);
        let beat = match full {
            Some(angles) => self
                .clock
                .arrival(cx.now_us, millisteps(cx.settings, &angles)),
            None => {
                self.clock.reset();
                None
            }
        };
        match (full, beat) {
            (Some(angles), Some(beat)) => {
                self.follow_stream(cx, angles, target.speed_percent, beat.period_us)
            }
            _ => self.replace(cx, Order::Move(target)),
        }
    }

    /// Moves the end to `pose`: joint-interpolated (mode 0) or along a straight line (mode 1),
    /// the joint angles solved from where the arm is going.
    fn move_to_pose(
        &mut self,
        cx: &mut Context<'_>,
        pose: Pose,
        speed_percent: u8,
        mode: MoveMode,
    ) -> Result<(), AtomError> {
        let seed = self.planned_angles(cx);
        let angles = cx.settings.cart().inverse(&pose, &seed)?;
        let target = Target {
            angles: angles.map(Some),
            speed_percent,
            way: match mode {
                MoveMode::Linear => Way::Line(pose),
                MoveMode::Joint => Way::Joints,
            },
        };
        self.submit(cx, target)
    }

    /// Starts a continuous jog of joint `j` toward its limit. The same jog again only changes
    /// its speed; another motion is braked first.
    fn jog_joint(
        &mut self,
        cx: &mut Context<'_>,
        j: usize,
        direction: JogDirection,
        speed_percent: u8,
    ) -> Result<(), AtomError> {
        let end = jog_end(cx, j, direction)?;
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
            let target = Target::joint(j, end, speed_percent);
            return self.start_joint_move(cx, target, Some(jog));
        }
        self.replace(cx, Order::Jog { jog, speed_percent })
    }

    /// Starts a continuous Cartesian jog: `axis` 0..2 along x, y, z, 3..5 about the base x, y,
    /// z axes. The same jog at the same speed again changes nothing; another motion is braked
    /// first.
    fn jog_pose(
        &mut self,
        cx: &mut Context<'_>,
        axis: usize,
        direction: JogDirection,
        speed_percent: u8,
    ) -> Result<(), AtomError> {
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
        self.replace(cx, Order::Jog { jog, speed_percent })
    }

    /// Stops the arm (0x29, 0x34 jog stop): brakes every joint and forgets queued and paused
    /// moves.
    pub fn stop(&mut self, cx: &mut Context<'_>) {
        self.forget_plans();
        self.brake(cx, None);
    }

    /// Pauses the current move (0x26): brakes, and remembers the move for [`Self::resume`].
    pub fn pause(&mut self, cx: &mut Context<'_>) {
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
        self.brake(cx, None);
    }

    /// Resumes a paused move (0x28); nothing to do if none is paused.
    pub fn resume(&mut self, cx: &mut Context<'_>) -> Result<(), AtomError> {
        self.may_move(cx)?;
        match self.paused.take() {
            Some(t) => self.replace(cx, Order::Move(t)),
            None => Ok(()),
        }
    }

    /// Brakes and stays (a servo is about to be calibrated); queued moves wait.
    pub fn halt(&mut self, cx: &mut Context<'_>) {
        self.clock.reset();
        self.brake(cx, None);
    }

    /// Reacts to `collision`: every joint brakes as for a stop, the blocked joint's servo lets
    /// go and holds where it stands ([`Context::let_go_and_hold`]: it stops pressing), and new
    /// motion is refused with the collision's code until [`MotionController::unlock`].
    pub fn collided(&mut self, cx: &mut Context<'_>, collision: &Collision) {
        self.stop(cx);
        cx.let_go_and_hold(collision.joint);
        self.lock = Some(AtomError::Collision(collision.kind));
    }

    /// Allows motion again after a collision (0x08 clear error information, 0x10 power on).
    pub fn unlock(&mut self) {
        self.lock = None;
    }

    /// What a collision felt now would interrupt: a joint-space motion, a Cartesian one, or
    /// the arm holding still.
    pub fn collision_kind(&self) -> Kind {
        match self.activity {
            Activity::Idle => Kind::Holding,
            Activity::Path { .. } => Kind::CartesianMotion,
            Activity::Joint { .. } | Activity::Stream { .. } | Activity::Braking { .. } => {
                Kind::JointMotion
            }
        }
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

    /// True at `now_us` while the arm moves: a motion runs or a joint reports moving.
    pub fn is_moving(&self, bank: &ServoBank, now_us: u64) -> bool {
        self.is_active() || bank.joints_moving(now_us)
    }

    /// True if the arm is at `target` (angles, or a pose in the selected frames, within
    /// [`tolerance`]) and at rest (0x2A): pymycobot's `sync_send_angles` returns as soon as
    /// this says so, so a pose passed through on the way does not count.
    pub fn in_position(&self, cx: &Context<'_>, target: &PositionTarget) -> bool {
        let present = cx.present_angles();
        let near = match target {
            PositionTarget::Angles(a) => tolerance::angles_match(&present, a),
            PositionTarget::Coords(pose) => {
                tolerance::coords_match(&cx.settings.cart().forward(&present), pose)
            }
        };
        near && !self.is_moving(cx.bank, cx.now_us)
    }

    /// The joint angles the arm is going to (the present angles when idle).
    pub fn planned_angles(&self, cx: &Context<'_>) -> [Centideg; JOINTS] {
        match &self.activity {
            Activity::Idle => cx.present_angles(),
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

    /// The end pose the arm is going to: where a straight line or an arc ends, otherwise the
    /// pose of [`Self::planned_angles`] (the present pose when idle).
    pub fn planned_pose(&self, cx: &Context<'_>) -> Pose {
        let path_end = match &self.activity {
            Activity::Path { way, .. } => way.and_then(|w| w.end_pose()),
            Activity::Braking {
                then: Some(Order::Move(t)),
                ..
            } => t.way.end_pose(),
            _ => None,
        };
        path_end.unwrap_or_else(|| cx.settings.cart().forward(&self.planned_angles(cx)))
    }

    /// Accepts a circular arc (0x8B, 0x8C) through `via` to `end` at `speed_percent`: from
    /// `begin`, reached first along a straight line (unless the arm is there already), or from
    /// where the arm is. The whole arc is walked with the inverse kinematics before anything
    /// moves ([`plan_arc`]); in fresh mode it replaces the current motion, in queue mode its
    /// parts wait their turn.
    fn submit_arc(
        &mut self,
        cx: &mut Context<'_>,
        begin: Option<Pose>,
        via: Pose,
        end: Pose,
        speed_percent: u8,
    ) -> Result<(), AtomError> {
        let settings = cx.settings;
        // Where the arc starts from: where the arm comes to rest (fresh mode), or where the
        // moves before it end (queue mode).
        let mut from = if settings.fresh_mode() {
            cx.present_angles()
        } else {
            self.queue
                .back()
                .and_then(|t| full_angles(&t.angles))
                .unwrap_or_else(|| self.planned_angles(cx))
        };
        let mut parts: heapless::Vec<Target, 2> = heapless::Vec::new();
        if let Some(begin) = begin {
            let cart = settings.cart();
            if !tolerance::at_arc_start(&cart.forward(&from), &begin) {
                let angles = cart.inverse(&begin, &from)?;
                let line = Target {
                    angles: angles.map(Some),
                    speed_percent,
                    way: Way::Line(begin),
                };
                settings.check_angles(&line.angles)?;
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
        settings.check_angles(&arc.angles)?;
        parts.push(arc).map_err(|_| AtomError::Busy)?;
        let mut parts = parts.into_iter();
        let Some(first) = parts.next() else {
            return Ok(());
        };
        if settings.fresh_mode() {
            self.forget_plans();
            self.replace(cx, Order::Move(first))?;
            for t in parts {
                self.queue.push_back(t).map_err(|_| AtomError::Busy)?;
            }
            return Ok(());
        }
        if MOTION_QUEUE - self.queue.len() < 1 + parts.len() {
            return Err(AtomError::Busy);
        }
        if self.idle_with_nothing_waiting() {
            self.start(cx, Order::Move(first))?;
        } else {
            self.queue.push_back(first).map_err(|_| AtomError::Busy)?;
        }
        for t in parts {
            self.queue.push_back(t).map_err(|_| AtomError::Busy)?;
        }
        Ok(())
    }

    /// Runs what is due at the step's time: the jog watchdog, the next point of a path, the end
    /// of a stream or a stop, arrival, and the next queued move. An error (a path that cannot
    /// go on, a queued move that became impossible) has stopped the arm and is to be recorded.
    pub fn update(&mut self, cx: &mut Context<'_>) -> Result<(), AtomError> {
        self.watch_readings(cx)?;
        let watchdog_us = cx.settings.config().timing.jog_watchdog_us;
        if self.jogging() && cx.now_us.saturating_sub(self.last_host_cmd_us) >= watchdog_us {
            self.stop(cx);
            return Ok(());
        }
        let outcome = self.advance(cx);
        if let Err(e) = outcome {
            self.forget_plans();
            self.brake(cx, None);
            return Err(e);
        }
        if matches!(self.activity, Activity::Idle)
            && self.paused.is_none()
            && let Some(next) = self.queue.pop_front()
        {
            return self.start(cx, Order::Move(next));
        }
        Ok(())
    }

    /// Stops the motion (and forgets what waits) when a joint's readings stopped or jumped
    /// ([`ServoBank::unknown_joint`], [`ServoBank::take_jump`]): the arm does not go on from
    /// where it can only guess the joint is. The brake goes by what each joint was told
    /// ([`brake`]); a stop already under way goes on. The error is for 0x07.
    fn watch_readings(&mut self, cx: &mut Context<'_>) -> Result<(), AtomError> {
        let jumped = cx.bank.take_jump();
        let Some(j) = jumped.or_else(|| cx.bank.unknown_joint(cx.now_us)) else {
            return Ok(());
        };
        match self.activity {
            Activity::Idle if self.queue.is_empty() => Ok(()),
            Activity::Braking { then: None, .. } => Err(AtomError::StateLost(j)),
            _ => {
                self.forget_plans();
                self.brake(cx, None);
                Err(AtomError::StateLost(j))
            }
        }
    }

    fn advance(&mut self, cx: &mut Context<'_>) -> Result<(), AtomError> {
        let now_us = cx.now_us;
        let period_us = cx.settings.config().timing.interpolation_period_us;
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
                if arrived(cx, target) || elapsed > *duration_us + MOVE_OVERTIME_US {
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
                if let Step::Point { angles, last } = runner.step(now_us, cx.settings)? {
                    if jog.is_some() {
                        *target = angles;
                    }
                    let leg = Leg {
                        target: millisteps(cx.settings, &angles),
                        period_us,
                        clock: Clock::Periodic,
                        speed_cap_steps_per_s: runner.joint_speed_cap(),
                        pace: Pace::Together,
                        last,
                    };
                    let goals = follower.goals_towards(cx, &leg);
                    cx.send_goals(goals)?;
                    if last {
                        next = Some(arriving(now_us, angles, *speed_percent, period_us));
                    }
                }
            }
            Activity::Stream {
                follower,
                aim,
                target,
                speed_percent,
                period_us: stream_period_us,
                last_us,
            } => {
                let cap = cx.settings.config().joint_speed_steps(*speed_percent);
                if stream_ended(now_us, *last_us) {
                    let leg = Leg {
                        target: millisteps(cx.settings, target),
                        period_us: *stream_period_us,
                        clock: Clock::Timed {
                            period_us: *stream_period_us,
                        },
                        speed_cap_steps_per_s: cap,
                        pace: Pace::Free,
                        last: true,
                    };
                    let goals = follower.goals_towards(cx, &leg);
                    cx.send_goals(goals)?;
                    next = Some(arriving(now_us, *target, *speed_percent, *stream_period_us));
                } else if aim.is_none_or(|a| now_us >= a.reach_us)
                    && let Some(next_aim) = self.clock.aim(now_us, lead_us(*stream_period_us))
                    && Some(next_aim) != *aim
                {
                    // The beat is passed: on to the next one, arrived or bridged.
                    let leg = stream_leg(&next_aim, now_us, *stream_period_us, cap);
                    cx.send_goals(follower.goals_towards(cx, &leg))?;
                    *aim = Some(next_aim);
                }
            }
            Activity::Braking {
                until_us,
                then: after,
                ..
            } => {
                let settled = !cx.joints_moving() || now_us >= *until_us + BRAKE_SETTLE_MAX_US;
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
            Some(order) => self.start(cx, order),
            None => Ok(()),
        }
    }

    /// True while idle with no queued or paused move: a move in queue mode starts at once.
    fn idle_with_nothing_waiting(&self) -> bool {
        matches!(self.activity, Activity::Idle) && self.queue.is_empty() && self.paused.is_none()
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
    fn replace(&mut self, cx: &mut Context<'_>, order: Order) -> Result<(), AtomError> {
        if self.is_moving(cx.bank, cx.now_us) {
            self.brake(cx, Some(order));
            Ok(())
        } else {
            self.start(cx, order)
        }
    }

    /// Brakes every joint; `then` starts once the arm is at rest. A powered-off arm has
    /// nothing to brake.
    fn brake(&mut self, cx: &mut Context<'_>, then: Option<Order>) {
        if !cx.bank.powered() {
            self.activity = Activity::Idle;
            return;
        }
        let stop = Braking::of(cx);
        stop.send(cx);
        self.activity = Activity::Braking {
            rest: stop.rest,
            until_us: cx.now_us + stop.duration_us,
            then,
        };
    }

    fn start(&mut self, cx: &mut Context<'_>, order: Order) -> Result<(), AtomError> {
        match order {
            Order::Move(target) => match target.way {
                Way::Line(_) | Way::Arc { .. } => self.start_path(cx, target),
                Way::Joints => self.start_joint_move(cx, target, None),
            },
            Order::Jog {
                jog: jog @ Jog::Joint { joint, direction },
                speed_percent,
            } => {
                let end = jog_end(cx, joint, direction)?;
                let target = Target::joint(joint, end, speed_percent);
                self.start_joint_move(cx, target, Some(jog))
            }
            Order::Jog {
                jog: jog @ Jog::Pose { axis, direction },
                speed_percent,
            } => {
                let present = cx.present_angles();
                let positive = direction == JogDirection::Positive;
                let runner = PathRunner::jog(
                    cx.settings,
                    cx.now_us,
                    &present,
                    axis,
                    positive,
                    speed_percent,
                );
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
        cx: &mut Context<'_>,
        target: Target,
        jog: Option<Jog>,
    ) -> Result<(), AtomError> {
        let settings = cx.settings;
        settings.check_angles(&target.angles)?;
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
            &cx.bank.present_steps(),
            &steps,
            target.speed_percent,
        );
        cx.send_goals(goals)?;
        let present = cx.present_angles();
        let full = core::array::from_fn(|j| {
            let holding = cx.bank.last_goal(j).map(|g| settings.angle(j, g.position));
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
            started_us: cx.now_us,
            duration_us,
            jog,
        };
        Ok(())
    }

    /// Starts the Cartesian path of `target` (a straight line or an arc) from the present
    /// position; `target.angles` solve its end.
    fn start_path(&mut self, cx: &mut Context<'_>, target: Target) -> Result<(), AtomError> {
        let settings = cx.settings;
        settings.check_angles(&target.angles)?;
        let present = cx.present_angles();
        let speed = target.speed_percent;
        let now_us = cx.now_us;
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

    /// Follows a stream whose target `angles` just arrived (the clock has it): the joints head
    /// for the first beat still ahead ([`StreamClock::aim`]), unless they already do.
    fn follow_stream(
        &mut self,
        cx: &mut Context<'_>,
        angles: [Centideg; JOINTS],
        speed_percent: u8,
        period_us: u64,
    ) -> Result<(), AtomError> {
        let (mut follower, heading) = match self.activity {
            Activity::Stream { follower, aim, .. } => (follower, aim),
            _ => (Follower::default(), None),
        };
        let aim = self.clock.aim(cx.now_us, lead_us(period_us)).or(heading);
        if let Some(aim) = aim
            && heading != Some(aim)
        {
            let cap = cx.settings.config().joint_speed_steps(speed_percent);
            let leg = stream_leg(&aim, cx.now_us, period_us, cap);
            cx.send_goals(follower.goals_towards(cx, &leg))?;
        }
        self.activity = Activity::Stream {
            follower,
            aim,
            target: angles,
            speed_percent,
            period_us,
            last_us: cx.now_us,
        };
        Ok(())
    }
}

/// How far ahead of now a stream's joints aim at the least: a quarter period, so that a target
/// that arrives just before its beat is passed is not rushed to.
fn lead_us(period_us: u64) -> u64 {
    period_us / 4
}

/// The leg towards `aim` from `now_us` of a stream that comes every `period_us`, no joint
/// faster than `cap` steps/s.
fn stream_leg(aim: &Aim, now_us: u64, period_us: u64, cap: u32) -> Leg {
    Leg {
        target: aim.at,
        period_us: aim.reach_us.saturating_sub(now_us).max(1),
        clock: Clock::Timed { period_us },
        speed_cap_steps_per_s: cap,
        pace: Pace::Free,
        last: false,
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
fn jog_end(cx: &Context<'_>, j: usize, direction: JogDirection) -> Result<Centideg, AtomError> {
    let limit = cx.settings.limit(j).ok_or(AtomError::Invalid)?;
    let end = match direction {
        JogDirection::Negative => limit.min,
        JogDirection::Positive => limit.max,
    };
    let present = cx.present_angles().get(j).copied().unwrap_or(end);
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

/// True if every joint is within [`tolerance::IN_POSITION_CENTIDEG`] of `target` and its
/// latest fresh reading says it is at rest on its goal ([`Context::joints_moving`]): a joint
/// whose reads do not come back cannot arrive.
fn arrived(cx: &Context<'_>, target: &[Centideg; JOINTS]) -> bool {
    tolerance::angles_match(&cx.present_angles(), target) && !cx.joints_moving()
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::bank::test_support::{at_rest, read, reread, state};
    use crate::config::AtomConfig;
    use crate::settings::Settings;

    /// Moves the step's time on to `now_us`, the servos read again meanwhile (at rest where
    /// they were: they never move here).
    fn later(cx: &mut Context<'_>, now_us: u64) {
        cx.now_us = now_us;
        reread(cx.bank, cx.settings, now_us);
    }

    #[test]
    fn every_new_motion_is_refused_while_powered_off() {
        let settings = Settings::new(AtomConfig::default());
        let mut bank = ServoBank::new(&settings);
        let mut motion = MotionController::new();
        let cx = &mut Context::new(0, &mut bank, &settings);
        let pose = settings.cart().forward(&[Centideg(0); JOINTS]);
        let commands = [
            Command::Move(Target::joint(0, Centideg(1_000), 50)),
            Command::ToPose {
                pose,
                speed_percent: 50,
                mode: MoveMode::Linear,
            },
            Command::Arc {
                begin: None,
                via: pose,
                end: pose,
                speed_percent: 50,
            },
            Command::JogJoint {
                joint: 0,
                direction: JogDirection::Positive,
                speed_percent: 50,
            },
            Command::JogPose {
                axis: 2,
                direction: JogDirection::Negative,
                speed_percent: 50,
            },
        ];
        for command in commands {
            assert_eq!(motion.command(cx, command), Err(AtomError::PoweredOff));
        }
        assert!(!motion.is_active());
    }

    #[test]
    fn queue_mode_runs_the_moves_in_turn() {
        let (mut settings, mut bank) = at_rest();
        settings.set_fresh_mode(false);
        let mut motion = MotionController::new();
        let cx = &mut Context::new(0, &mut bank, &settings);
        let first = Target::joint(0, Centideg(1_000), 100);
        let second = Target::joint(1, Centideg(500), 100);
        assert_eq!(motion.command(cx, Command::Move(first)), Ok(()));
        assert_eq!(motion.command(cx, Command::Move(second)), Ok(()));
        assert_eq!(motion.planned_angles(cx)[0], Centideg(1_000));
        assert_eq!(
            motion.planned_angles(cx)[1],
            Centideg(0),
            "the second waits"
        );
        // The servos never report arriving here: the first move ends after its overtime.
        later(cx, 10 * MOVE_OVERTIME_US);
        assert_eq!(motion.update(cx), Ok(()));
        assert_eq!(motion.planned_angles(cx)[1], Centideg(500), "its turn");
        let held = settings.angle(0, settings.goal_steps(0, Centideg(1_000)));
        assert_eq!(motion.planned_angles(cx)[0], held, "joint 1 holds its goal");
    }

    #[test]
    fn a_fresh_move_replaces_a_running_one_after_braking() {
        let (settings, mut bank) = at_rest();
        let mut motion = MotionController::new();
        let cx = &mut Context::new(0, &mut bank, &settings);
        let first = Target::joint(0, Centideg(1_000), 100);
        let second = Target::joint(1, Centideg(500), 100);
        assert_eq!(motion.command(cx, Command::Move(first)), Ok(()));
        later(cx, 200_000);
        assert_eq!(motion.command(cx, Command::Move(second)), Ok(()));
        assert!(matches!(motion.activity, Activity::Braking { .. }));
        assert_eq!(motion.planned_angles(cx)[1], Centideg(500));
        later(cx, 400_000);
        assert_eq!(motion.update(cx), Ok(()));
        assert!(matches!(motion.activity, Activity::Joint { .. }), "started");
    }

    #[test]
    fn stop_brakes_and_forgets_the_queued_moves() {
        let (mut settings, mut bank) = at_rest();
        settings.set_fresh_mode(false);
        let mut motion = MotionController::new();
        let cx = &mut Context::new(0, &mut bank, &settings);
        for j in 0..3 {
            let target = Target::joint(j, Centideg(1_000), 100);
            assert_eq!(motion.command(cx, Command::Move(target)), Ok(()));
        }
        motion.stop(cx);
        assert!(matches!(
            motion.activity,
            Activity::Braking { then: None, .. }
        ));
        later(cx, 10 * MOVE_OVERTIME_US);
        assert_eq!(motion.update(cx), Ok(()));
        assert!(!motion.is_active(), "nothing queued starts");
    }

    #[test]
    fn a_jog_stops_when_the_host_falls_silent() {
        let (settings, mut bank) = at_rest();
        let mut motion = MotionController::new();
        let cx = &mut Context::new(0, &mut bank, &settings);
        let jog = Command::JogJoint {
            joint: 0,
            direction: JogDirection::Positive,
            speed_percent: 50,
        };
        motion.note_host_command(0);
        assert_eq!(motion.command(cx, jog), Ok(()));
        assert!(motion.jogging());
        let watchdog_us = settings.config().timing.jog_watchdog_us;
        later(cx, watchdog_us - 1);
        assert_eq!(motion.update(cx), Ok(()));
        assert!(motion.jogging());
        later(cx, watchdog_us);
        assert_eq!(motion.update(cx), Ok(()));
        assert!(
            matches!(motion.activity, Activity::Braking { .. }),
            "stopped"
        );
    }

    #[test]
    fn a_motion_stops_with_the_joints_error_when_its_readings_stop() {
        let (settings, mut bank) = at_rest();
        let mut motion = MotionController::new();
        let cx = &mut Context::new(0, &mut bank, &settings);
        let target = Target::joint(0, Centideg(3_000), 50);
        assert_eq!(motion.command(cx, Command::Move(target)), Ok(()));
        later(cx, 40_000);
        assert_eq!(motion.update(cx), Ok(()));
        // Joint 5 is read no more: 50 ms on, nobody knows where it is.
        cx.now_us = 40_000 + crate::bank::FRESH_STATE_US + 1;
        for i in (0..crate::config::SERVOS).filter(|&i| i != 4) {
            let id = settings.config().servo_ids[i];
            read(
                cx.bank,
                cx.settings,
                cx.now_us,
                i,
                state(id, 2_048, 0, 2_048),
            );
        }
        assert_eq!(motion.update(cx), Err(AtomError::StateLost(4)));
        assert!(
            matches!(motion.activity, Activity::Braking { then: None, .. }),
            "stopped"
        );
        // Nothing new starts meanwhile, and the error stays while it lasts.
        let again = Target::joint(1, Centideg(1_000), 50);
        assert_eq!(
            motion.command(cx, Command::Move(again)),
            Err(AtomError::StateLost(4))
        );
        assert_eq!(motion.update(cx), Err(AtomError::StateLost(4)));
        // Read again: the stop ends, and motion may start.
        later(cx, cx.now_us + 300_000);
        assert_eq!(motion.update(cx), Ok(()));
        assert!(!motion.is_active());
        assert_eq!(motion.command(cx, Command::Move(again)), Ok(()));
    }

    #[test]
    fn a_reading_that_jumps_stops_the_motion_and_one_at_rest_is_no_error() {
        let (settings, mut bank) = at_rest();
        let mut motion = MotionController::new();
        let cx = &mut Context::new(0, &mut bank, &settings);
        // Holding still, no fresh reading is no error: there is nothing to stop.
        later(cx, 0);
        cx.now_us = 200_000;
        assert_eq!(motion.update(cx), Ok(()));
        later(cx, 200_000);
        let target = Target::joint(0, Centideg(3_000), 50);
        assert_eq!(motion.command(cx, Command::Move(target)), Ok(()));
        later(cx, 204_000);
        assert_eq!(motion.update(cx), Ok(()));
        // Joint 2 reads 0 (a reply that says nothing) 4 ms after 2048: not a place it can be.
        read(cx.bank, cx.settings, 208_000, 1, state(2, 0, 0, 2_048));
        cx.now_us = 208_000;
        assert_eq!(motion.update(cx), Err(AtomError::StateLost(1)));
        assert!(matches!(motion.activity, Activity::Braking { .. }));
    }
}
