//! Cartesian paths walked by the firmware: straight lines (send coords mode 1), circular arcs
//! (0x8B, 0x8C) and Cartesian jogs (0x31, 0x32) alike.
//!
//! Every interpolation period the runner moves along its [`Path`] at a speed that ramps up from
//! rest, cruises and (for a path with an end) ramps down to arrive at rest, solves the joint
//! angles there ([`PathWalker`]) and hands them to the follower, which makes every joint reach
//! them one period later. Where joints would have to move faster than the speed allows (next to
//! a singularity), the walker takes a shorter step and the path slows there.

use kinematics_core::fixed::checked_div_i128;
use kinematics_core::{Arc, Kinematics, Line, Path, PathError, PathWalker, Ray, Transform, Turn};
use protocol_core::command::Pose;
use protocol_core::units::Centideg;

use crate::cartesian;
use crate::config::{JOINTS, STEPS_PER_TURN};
use crate::error::AtomError;
use crate::settings::Settings;

use super::follow::millisteps;

/// Micrometres per tenth of a millimetre.
const UM_PER_TENTH_MM: i64 = 100;
/// Path micrometres per centidegree of rotation ([`kinematics_core::path`]'s measure).
const UM_PER_CENTIDEG: i64 = 10;

/// A point of a path that moves a joint more than this from the previous point is a branch
/// jump (error 33), however slowly the path goes: 5 deg in one interpolation period.
const JUMP_STEP_CENTIDEG: i32 = kinematics_core::path::DEFAULT_MAX_JOINT_STEP_CENTIDEG;

/// Points at which an arc is solved before it starts ([`plan_arc`]): 32, a few milliseconds
/// of inverse kinematics on the Atom, one every 6 mm of a 200 mm arc.
const ARC_CHECKPOINTS: u32 = 32;

/// Largest joint turn between two checkpoints of an arc that is not a branch flip: 45 deg (a
/// flip turns a joint by about 180 deg; 1/32 of an arc turns none by more than a few degrees
/// away from singularities, and a step is split up to 64 times near them).
const ARC_CHECK_JUMP_CENTIDEG: i32 = 4_500;

/// The paths the Atom walks.
// One path is walked at a time, held in place (no allocator): the arc's size costs nothing.
#[allow(clippy::large_enum_variant)]
#[derive(Clone, Copy, Debug)]
pub enum AnyPath {
    /// A straight line to a pose.
    Line(Line),
    /// A Cartesian jog along a base axis.
    Ray(Ray),
    /// A rotation jog about a base axis.
    Turn(Turn),
    /// A circular arc through three poses.
    Arc(Arc),
}

impl Path for AnyPath {
    fn length_um(&self) -> i64 {
        match self {
            Self::Line(p) => p.length_um(),
            Self::Ray(p) => p.length_um(),
            Self::Turn(p) => p.length_um(),
            Self::Arc(p) => p.length_um(),
        }
    }

    fn pose_at(&self, at_um: i64) -> Transform {
        match self {
            Self::Line(p) => p.pose_at(at_um),
            Self::Ray(p) => p.pose_at(at_um),
            Self::Turn(p) => p.pose_at(at_um),
            Self::Arc(p) => p.pose_at(at_um),
        }
    }
}

/// The next point of a path.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Step {
    /// Not due yet.
    Wait,
    /// The joint angles one period from now; `last` at the end of the path.
    Point {
        /// Joint angles.
        angles: [Centideg; JOINTS],
        /// The end of the path.
        last: bool,
    },
}

/// A path being walked. See the [module doc](self).
#[derive(Clone, Copy, Debug)]
pub struct PathRunner {
    walker: PathWalker<AnyPath>,
    /// Cruising speed along the path, micrometres per second.
    cruise_um_per_s: i64,
    /// Speed of the last step, micrometres per second.
    speed_um_per_s: i64,
    /// When the next point is due.
    next_us: u64,
    /// Joint speed at the speed asked for, steps per second.
    joint_speed_cap: u32,
    /// The joint angles last handed out.
    latest: [Centideg; JOINTS],
}

impl PathRunner {
    /// A straight line from the joint angles `from` to `pose` at `speed_percent`.
    pub fn line(
        settings: &Settings,
        now_us: u64,
        from: &[Centideg; JOINTS],
        pose: &protocol_core::command::Pose,
        speed_percent: u8,
    ) -> Result<Self, AtomError> {
        let start = cartesian::joints(from);
        let line = Line::new(settings.cart().model(), &start, &cartesian::to_kin(pose))?;
        let cruise = linear_speed_um_per_s(settings, speed_percent);
        Ok(Self::new(
            settings,
            now_us,
            AnyPath::Line(line),
            from,
            cruise,
            speed_percent,
        ))
    }

    /// A circular arc from the joint angles `from` through `via` to `end` at `speed_percent`,
    /// checked whole first ([`plan_arc`]).
    pub fn arc(
        settings: &Settings,
        now_us: u64,
        from: &[Centideg; JOINTS],
        via: &Pose,
        end: &Pose,
        speed_percent: u8,
    ) -> Result<Self, AtomError> {
        let (arc, _) = plan_arc(settings, from, via, end)?;
        let cruise = linear_speed_um_per_s(settings, speed_percent);
        Ok(Self::new(
            settings,
            now_us,
            AnyPath::Arc(arc),
            from,
            cruise,
            speed_percent,
        ))
    }

    /// A Cartesian jog from the joint angles `from`: `axis` 0..2 along x, y, z, 3..5 about
    /// the base x, y, z axes.
    pub fn jog(
        settings: &Settings,
        now_us: u64,
        from: &[Centideg; JOINTS],
        axis: usize,
        positive: bool,
        speed_percent: u8,
    ) -> Self {
        let start = settings
            .cart()
            .model()
            .forward_transform(&cartesian::joints(from));
        let (path, cruise) = if axis < 3 {
            let ray = AnyPath::Ray(Ray::new(start, axis, positive));
            (ray, linear_speed_um_per_s(settings, speed_percent))
        } else {
            let turn = AnyPath::Turn(Turn::new(start, axis - 3, positive));
            let cdeg_per_s = i64::from(settings.config().motion.rotation_speed_centideg_per_s)
                * i64::from(speed_percent.clamp(1, 100))
                / 100;
            (turn, cdeg_per_s * UM_PER_CENTIDEG)
        };
        Self::new(settings, now_us, path, from, cruise, speed_percent)
    }

    fn new(
        settings: &Settings,
        now_us: u64,
        path: AnyPath,
        from: &[Centideg; JOINTS],
        cruise_um_per_s: i64,
        speed_percent: u8,
    ) -> Self {
        Self {
            walker: PathWalker::new(path, cartesian::joints(from)),
            cruise_um_per_s: cruise_um_per_s.max(1),
            speed_um_per_s: 0,
            next_us: now_us,
            joint_speed_cap: settings.config().joint_speed_steps(speed_percent),
            latest: *from,
        }
    }

    /// The next point if it is due at `now_us`; an error ends the path (no solution on the
    /// way, or a jump the joints cannot make).
    pub fn step(&mut self, now_us: u64, settings: &Settings) -> Result<Step, AtomError> {
        if now_us < self.next_us {
            return Ok(Step::Wait);
        }
        let period_us = settings.config().timing.interpolation_period_us.max(1);
        self.next_us = now_us + period_us;
        let period = period_us as i64;
        let accel =
            i64::from(settings.config().motion.linear_accel_decimm_per_s2) * UM_PER_TENTH_MM;
        let remaining = self.walker.remaining_um();
        // Speed up by one period's acceleration, cruise, and slow down by one period's
        // acceleration per period so that the path ends at rest: with steps of `v P` and a
        // speed falling by `a P` per step, the distance left d covers v = sqrt((aP/2)^2 + 2ad)
        // - aP/2.
        let per_period = accel * period / 1_000_000;
        let stopping =
            kinematics_core::fixed::sqrt(per_period * per_period / 4 + 2 * accel * remaining)
                - per_period / 2;
        let speed = (self.speed_um_per_s + per_period)
            .min(self.cruise_um_per_s)
            .min(stopping)
            // Never stall short of the end.
            .max(per_period.min(self.cruise_um_per_s))
            .max(1);
        let advance = (speed * period / 1_000_000).max(1);
        // The most a joint may turn in one period at the speed asked for.
        let max_step = (i64::from(self.joint_speed_cap) * 36_000 * period
            / (i64::from(STEPS_PER_TURN) * 1_000_000))
            .clamp(1, i64::from(i32::MAX)) as i32;
        let model: &Kinematics = settings.cart().model();
        match self
            .walker
            .advance(model, advance, max_step, JUMP_STEP_CENTIDEG)
        {
            None => Ok(Step::Point {
                angles: self.latest,
                last: true,
            }),
            Some(Err(e)) => Err(e.into()),
            Some(Ok((q, taken))) => {
                self.speed_um_per_s = taken * 1_000_000 / period;
                let last = self.walker.remaining_um() == 0;
                self.latest = if last {
                    let end = self.walker.path().pose_at(i64::MAX);
                    nearest_on_steps(settings, &cartesian::angles(&q), &end)
                } else {
                    cartesian::angles(&q)
                };
                Ok(Step::Point {
                    angles: self.latest,
                    last,
                })
            }
        }
    }

    /// The fastest a joint may move on this path, steps per second.
    pub fn joint_speed_cap(&self) -> u32 {
        self.joint_speed_cap
    }

    /// A pose on the part of the path not walked yet, halfway along it: where an arc that was
    /// interrupted still has to pass to stay on its circle.
    pub fn halfway_ahead(&self) -> Pose {
        let path = self.walker.path();
        let at = self.walker.done_um() + self.walker.remaining_um() / 2;
        cartesian::from_kin(&path.pose_at(at).to_pose())
    }

    /// What is left of the path, micrometres.
    pub fn remaining_um(&self) -> i64 {
        self.walker.remaining_um()
    }
}

/// The arc from the joint angles `from` through `via` to `end`, and the joint angles it ends
/// at, checked whole before anything moves: `via` and `end` must solve (error 32), the three
/// poses must define a circle (33), and the arc is walked with the inverse kinematics at
/// [`ARC_CHECKPOINTS`] points (34 where it leaves the workspace or the joint limits, 33 where
/// the arm would have to flip branch).
pub fn plan_arc(
    settings: &Settings,
    from: &[Centideg; JOINTS],
    via: &Pose,
    end: &Pose,
) -> Result<(Arc, [Centideg; JOINTS]), AtomError> {
    let model = settings.cart().model();
    let start = cartesian::joints(from);
    let (via, end) = (
        Transform::from_pose(&cartesian::to_kin(via)),
        Transform::from_pose(&cartesian::to_kin(end)),
    );
    model.inverse_transform(&via, &start)?;
    model.inverse_transform(&end, &start)?;
    let arc = Arc::through(model.forward_transform(&start), via, end)
        .ok_or(AtomError::Path(PathError::NoCircle))?;
    let q = kinematics_core::check_path(
        model,
        AnyPath::Arc(arc),
        start,
        ARC_CHECKPOINTS,
        ARC_CHECK_JUMP_CENTIDEG,
    )?;
    Ok((arc, cartesian::angles(&q)))
}

/// Cartesian speed at `speed_percent`, micrometres per second.
fn linear_speed_um_per_s(settings: &Settings, speed_percent: u8) -> i64 {
    i64::from(settings.config().motion.linear_speed_decimm_per_s)
        * i64::from(speed_percent.clamp(1, 100))
        / 100
        * UM_PER_TENTH_MM
}

/// Of the joint angles on whole encoder steps around `q` (each joint's step below or above),
/// the ones whose end pose comes nearest `end`: a servo at rest holds a whole step, and which
/// way each joint rounds moves the end by up to a few tenths of a millimetre.
fn nearest_on_steps(
    settings: &Settings,
    q: &[Centideg; JOINTS],
    end: &Transform,
) -> [Centideg; JOINTS] {
    let model = settings.cart().model();
    let below = millisteps(settings, q).map(|m| m.div_euclid(1000));
    let mut best = (i128::MAX, *q);
    for choice in 0u32..(1 << JOINTS) {
        let angles: [Centideg; JOINTS] = core::array::from_fn(|j| {
            let step = below.get(j).copied().unwrap_or(0) + i64::from((choice >> j) & 1);
            let step = step.clamp(0, i64::from(STEPS_PER_TURN) - 1) as i16;
            settings.angle(j, protocol_core::units::Steps(step))
        });
        if settings.check_angles(&angles.map(Some)).is_err() {
            continue;
        }
        let at = model.forward_transform(&cartesian::joints(&angles));
        let miss = pose_error(&at, end);
        if miss < best.0 {
            best = (miss, angles);
        }
    }
    best.1
}

/// A squared distance between two poses: position (internal length units) plus orientation
/// (rotation-matrix entries, weighted so that a degree counts about as much as a millimetre).
fn pose_error(a: &Transform, b: &Transform) -> i128 {
    let position: i128 = a
        .position
        .iter()
        .zip(&b.position)
        .map(|(x, y)| i128::from(x - y).pow(2))
        .sum();
    let rotation: i128 = (0..3)
        .flat_map(|r| (0..3).map(move |c| (r, c)))
        .map(|(r, c)| i128::from(a.rotation.at(r, c) - b.rotation.at(r, c)).pow(2))
        .sum();
    // Internal lengths: 16 000 per mm; rotation entries: 2^30 per unit, a degree = 0.0175.
    // (16 000 / (0.0175 * 2^30))^2 = 1 / 1 370 000 scales a degree to a millimetre.
    // Not `/`: the compiler's 128-bit division is wrong on the ESP32 (checked_div_i128).
    position + checked_div_i128(rotation, 1_370_000).unwrap_or(0)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::bank::test_support::powered;
    use protocol_core::units::DeciMm;

    /// A pose of the arm away from its singularities.
    const FROM: [Centideg; JOINTS] = [
        Centideg(1_000),
        Centideg(-3_000),
        Centideg(-6_000),
        Centideg(2_000),
        Centideg(4_500),
        Centideg(1_000),
    ];

    #[test]
    fn a_line_speeds_up_a_period_at_a_time_and_ends_on_its_pose() {
        let settings = powered();
        let start = settings.cart().forward(&FROM);
        let end = Pose {
            x: DeciMm(start.x.0 - 300),
            ..start
        };
        let mut runner = PathRunner::line(&settings, 0, &FROM, &end, 100).unwrap();
        let period = settings.config().timing.interpolation_period_us;
        let mut now = 0;
        let mut steps = std::vec::Vec::new();
        let last = loop {
            let Step::Point { angles, last } = runner.step(now, &settings).unwrap() else {
                panic!("a point every period");
            };
            assert_eq!(runner.step(now + period - 1, &settings), Ok(Step::Wait));
            steps.push(runner.speed_um_per_s);
            if last {
                break angles;
            }
            now += period;
            assert!(steps.len() < 1_000, "the line ends");
        };
        assert!(
            steps[0] < steps[1] && steps[1] < steps[2],
            "ramps up: {steps:?}"
        );
        let reached = settings.cart().forward(&last);
        for (a, b) in reached.to_array().iter().zip(end.to_array()) {
            assert!(
                (i32::from(*a) - i32::from(b)).abs() <= 3,
                "{reached:?} vs {end:?}"
            );
        }
    }

    #[test]
    fn an_arc_without_a_circle_is_refused_before_anything_moves() {
        let settings = powered();
        let start = settings.cart().forward(&FROM);
        let on_the_line = |dx: i16| Pose {
            x: DeciMm(start.x.0 - dx),
            ..start
        };
        assert_eq!(
            plan_arc(&settings, &FROM, &on_the_line(100), &on_the_line(200)).map(|_| ()),
            Err(AtomError::Path(PathError::NoCircle))
        );
    }
}
