//! Cartesian paths: where the end goes (a [`Path`]: a straight [`Line`], a [`Ray`] along a base
//! axis, a [`Turn`] about one, an [`Arc`](arc::Arc) through three poses) and how joint angles follow it
//! ([`PathWalker`], and [`check_path`] to walk a whole path coarsely before moving).
//!
//! A path is a pose for every point along it, measured in micrometres of travel, a degree of
//! rotation counting as a millimetre ([`Path::length_um`]). The walker solves each point with the
//! previous one as seed, so the arm stays on one branch. Where a step would move a joint more
//! than the per-step limit (next to a singularity joints speed up), the step is halved, down to
//! 1/64: the path slows there instead of flailing. A step that has no solution, or that still
//! jumps at 1/64 (a branch switch, e.g. through the wrist singularity), stops the path instead of
//! being executed. [`LinearPath`] is a line walked in equal steps.

pub mod arc;

use crate::fixed::{Angle, ratio};
use crate::ik::IkError;
use crate::model::Kinematics;
use crate::pose::{JointAngles, Pose};
use crate::transform::{LEN_PER_TENTH_MM, Rotation, Transform};

/// Default for [`LinearPath::with_max_joint_step`]: 5 deg, a few interpolation periods of a joint
/// at full speed; ordinary steps of a few millimetres need well under 2 deg.
pub const DEFAULT_MAX_JOINT_STEP_CENTIDEG: i32 = 500;

/// A step may be halved this many times (to 1/64) to keep joints within the per-step limit.
const SPLIT_BITS: u32 = 6;

/// Internal length units per micrometre of path.
const LEN_PER_UM: i64 = LEN_PER_TENTH_MM / 100;

/// Path micrometres per centidegree of rotation: a degree of rotation counts as a millimetre of
/// travel (the end moves about 1 mm per degree at the flange's 57 mm lever).
const UM_PER_CENTIDEG: i64 = 10;

/// Longest open-ended path ([`Ray`], [`Turn`]): 2 m or 2000 deg, far beyond the arm's reach, so
/// a jog always ends at the workspace edge or a limit first.
pub const OPEN_PATH_UM: i64 = 2_000_000;

/// Why a path stops (protocol 0x07 codes in [`PathError::protocol_code`]).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum PathError {
    /// The nearest solution of a step, even split to 1/64, moves a joint by more than the
    /// per-step limit from the previous step (a branch switch, or a singularity on the line).
    BranchJump {
        /// 0-based joint that would jump.
        joint: usize,
    },
    /// A step has no solution at all (out of reach or limits on the way).
    StepUnreachable(IkError),
    /// The three points of an arc define no circle: two of them coincide, or they lie on one
    /// line ([`Arc::through`](arc::Arc::through)).
    NoCircle,
}

impl PathError {
    /// The 0x07 error code: 33 when there is no continuous path (a branch jump, or an arc
    /// through points that define no circle), 34 for an unreachable step.
    pub fn protocol_code(&self) -> u8 {
        match self {
            Self::BranchJump { .. } | Self::NoCircle => 33,
            Self::StepUnreachable(_) => 34,
        }
    }
}

/// A Cartesian path of the end (in the model's selected tool and world frames).
pub trait Path {
    /// Length in micrometres of travel, a degree of rotation counting as a millimetre.
    fn length_um(&self) -> i64;
    /// The pose `at_um` along the path (0 = start; at or beyond the length, the end).
    fn pose_at(&self, at_um: i64) -> Transform;
}

/// A straight line: the position moves along the segment, the orientation turns about the one
/// axis of the shortest rotation, both in proportion.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct Line {
    start: Transform,
    target: Transform,
    /// Unit axis (Q30) and angle of the rotation from the start to the target orientation,
    /// expressed in the start frame.
    axis: [i64; 3],
    angle: Angle,
    length_um: i64,
}

impl Line {
    /// The line from the end pose at joint angles `start` to `target`. Fails with the target's
    /// [`IkError`] (protocol error 32) if the target has no solution.
    pub fn new(kin: &Kinematics, start: &JointAngles, target: &Pose) -> Result<Self, IkError> {
        let target = Transform::from_pose(target);
        kin.inverse_transform(&target, start)?;
        Ok(Self::between(kin.forward_transform(start), target))
    }

    /// The line between two transforms (no reachability check).
    pub fn between(start: Transform, target: Transform) -> Self {
        let (axis, angle) = start
            .rotation
            .transpose()
            .mul(&target.rotation)
            .to_axis_angle();
        let [dx, dy, dz] = [0, 1, 2].map(|i| {
            target.position.get(i).copied().unwrap_or(0)
                - start.position.get(i).copied().unwrap_or(0)
        });
        let distance_um = crate::fixed::sqrt(dx * dx + dy * dy + dz * dz) / LEN_PER_UM;
        let rotation_um = i64::from(angle.to_centideg().abs()) * UM_PER_CENTIDEG;
        Self {
            start,
            target,
            axis,
            angle,
            length_um: distance_um.max(rotation_um),
        }
    }
}

impl Path for Line {
    fn length_um(&self) -> i64 {
        self.length_um
    }

    fn pose_at(&self, at_um: i64) -> Transform {
        if at_um >= self.length_um {
            return self.target;
        }
        let at = at_um.max(0);
        let lerp = |i: usize| {
            let a = self.start.position.get(i).copied().unwrap_or(0);
            let b = self.target.position.get(i).copied().unwrap_or(0);
            a + ratio((b - a) * at, self.length_um)
        };
        let turn = Angle(ratio(i64::from(self.angle.0) * at, self.length_um) as i32);
        Transform {
            rotation: self
                .start
                .rotation
                .mul(&Rotation::about_axis(&self.axis, turn)),
            position: [lerp(0), lerp(1), lerp(2)],
        }
    }
}

/// An open-ended straight line along a base axis (x, y or z of the reference frame), the
/// orientation kept: a Cartesian jog (0x30, 0x32).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct Ray {
    start: Transform,
    axis: usize,
    sign: i64,
}

impl Ray {
    /// From `start` along base axis `axis` (0 x, 1 y, 2 z), positive if `positive`.
    pub fn new(start: Transform, axis: usize, positive: bool) -> Self {
        Self {
            start,
            axis,
            sign: if positive { 1 } else { -1 },
        }
    }
}

impl Path for Ray {
    fn length_um(&self) -> i64 {
        OPEN_PATH_UM
    }

    fn pose_at(&self, at_um: i64) -> Transform {
        let mut pose = self.start;
        if let Some(v) = pose.position.get_mut(self.axis) {
            *v += self.sign * at_um.clamp(0, OPEN_PATH_UM) * LEN_PER_UM;
        }
        pose
    }
}

/// An open-ended rotation about a base axis (x, y or z of the reference frame), the position
/// kept: a rotation jog (0x31).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct Turn {
    start: Transform,
    axis: [i64; 3],
    sign: i64,
}

impl Turn {
    /// From `start` about base axis `axis` (0 x, 1 y, 2 z), positive (right-handed) if
    /// `positive`.
    pub fn new(start: Transform, axis: usize, positive: bool) -> Self {
        let mut unit = [0; 3];
        if let Some(v) = unit.get_mut(axis) {
            *v = crate::fixed::ONE;
        }
        Self {
            start,
            axis: unit,
            sign: if positive { 1 } else { -1 },
        }
    }
}

impl Path for Turn {
    fn length_um(&self) -> i64 {
        OPEN_PATH_UM
    }

    fn pose_at(&self, at_um: i64) -> Transform {
        // One micrometre is a millidegree: 2^32 / 360 000 angle units.
        let millideg = self.sign * at_um.clamp(0, OPEN_PATH_UM);
        let turn = Angle(ratio(millideg << 32, 360_000) as i32);
        Transform {
            rotation: Rotation::about_axis(&self.axis, turn).mul(&self.start.rotation),
            position: self.start.position,
        }
    }
}

/// Joint angles following a [`Path`]: each advance solves the next point with the previous one
/// as seed, halving the advance (down to 1/64) while a joint would move more than the limit.
#[derive(Clone, Copy, Debug)]
pub struct PathWalker<P> {
    path: P,
    previous: JointAngles,
    done_um: i64,
    stopped: bool,
}

impl<P: Path> PathWalker<P> {
    /// A walker at the start of `path`, the arm at joint angles `start` (which should put the
    /// end at the path's start).
    pub fn new(path: P, start: JointAngles) -> Self {
        Self {
            path,
            previous: start,
            done_um: 0,
            stopped: false,
        }
    }

    /// Moves up to `advance_um` along the path: returns the new joint angles and how far it got;
    /// `None` at the end of the path or after an error (which ends the path). While a joint
    /// would move more than `slow_step_centideg` from the previous point the advance is halved
    /// (down to 1/64), so the path slows where joints would have to hurry; a point that still
    /// moves a joint more than `jump_step_centideg` is a branch jump ([`PathError::BranchJump`]).
    pub fn advance(
        &mut self,
        kin: &Kinematics,
        advance_um: i64,
        slow_step_centideg: i32,
        jump_step_centideg: i32,
    ) -> Option<Result<(JointAngles, i64), PathError>> {
        let length = self.path.length_um();
        if self.stopped || self.done_um >= length {
            return None;
        }
        // max/min rather than clamp, which asserts its bounds (a panic path); here 1 <= the rest.
        let mut size = advance_um.max(1).min(length - self.done_um);
        let mut splits = 0;
        let result = loop {
            let at = self.done_um + size;
            let q = match kin.inverse_transform(&self.path.pose_at(at), &self.previous) {
                Ok(q) => q,
                Err(e) => break Err(PathError::StepUnreachable(e)),
            };
            let (joint, step) = self.largest_step(&q);
            if step > i64::from(slow_step_centideg) && splits < SPLIT_BITS && size > 1 {
                size = (size / 2).max(1);
                splits += 1;
            } else if step > i64::from(jump_step_centideg) {
                break Err(PathError::BranchJump { joint });
            } else {
                let taken = at - self.done_um;
                self.done_um = at;
                self.previous = q;
                break Ok((q, taken));
            }
        };
        self.stopped = result.is_err();
        Some(result)
    }

    /// The joint that moves most from the previous point, and by how much (centidegrees).
    fn largest_step(&self, q: &JointAngles) -> (usize, i64) {
        q.0.iter()
            .zip(self.previous.0.iter())
            .map(|(a, b)| (i64::from(*a) - i64::from(*b)).abs())
            .enumerate()
            .max_by_key(|&(_, step)| step)
            .unwrap_or((0, 0))
    }

    /// How far along the path the walker is, micrometres.
    pub fn done_um(&self) -> i64 {
        self.done_um
    }

    /// What is left of the path, micrometres (0 once done or stopped).
    pub fn remaining_um(&self) -> i64 {
        if self.stopped {
            0
        } else {
            (self.path.length_um() - self.done_um).max(0)
        }
    }

    /// The joint angles of the last point reached (the start before the first advance).
    pub fn current(&self) -> JointAngles {
        self.previous
    }

    /// The path being walked.
    pub fn path(&self) -> &P {
        &self.path
    }
}

/// Walks all of `path` from the joint angles `start` in at most `checkpoints` equal steps, as
/// a check before the arm moves: gives the joint angles at the end of the path, or the first
/// [`PathError`] on the way (a point with no solution, or a step that still turns a joint by
/// more than `jump_step_centideg` when split to 1/64). Coarse on purpose (one solution per
/// checkpoint): a path that only grazes the workspace's edge between two checkpoints is still
/// stopped by the walker that carries it out.
pub fn check_path<P: Path>(
    kin: &Kinematics,
    path: P,
    start: JointAngles,
    checkpoints: u32,
    jump_step_centideg: i32,
) -> Result<JointAngles, PathError> {
    let step_um = div_ceil(path.length_um(), i64::from(checkpoints.max(1))).max(1);
    let mut walker = PathWalker::new(path, start);
    while let Some(step) = walker.advance(kin, step_um, jump_step_centideg, jump_step_centideg) {
        step?;
    }
    Ok(walker.current())
}

/// A straight line from a start configuration to a target pose in equal steps (split near
/// singularities); yields each step's joint angles, the last one solving the target itself.
#[derive(Clone, Copy, Debug)]
pub struct LinearPath {
    walker: PathWalker<Line>,
    step_um: i64,
    max_joint_step_centideg: i32,
}

impl LinearPath {
    /// A path from the end pose at `start` to `target` in steps of at most `step_tenth_mm` of
    /// travel and at most 0.1 deg of rotation per 0.1 mm of step length; at least one step.
    /// Fails with the target's [`IkError`] (protocol error 32) if the target has no solution.
    pub fn new(
        kin: &Kinematics,
        start: &JointAngles,
        target: &Pose,
        step_tenth_mm: i32,
    ) -> Result<Self, IkError> {
        let line = Line::new(kin, start, target)?;
        let most_um = i64::from(step_tenth_mm.max(1)) * 100;
        let steps = div_ceil(line.length_um(), most_um).max(1);
        Ok(Self {
            step_um: div_ceil(line.length_um(), steps).max(1),
            walker: PathWalker::new(line, *start),
            max_joint_step_centideg: DEFAULT_MAX_JOINT_STEP_CENTIDEG,
        })
    }

    /// The same path with a different largest joint change per step, centidegrees.
    #[must_use]
    pub fn with_max_joint_step(mut self, centideg: i32) -> Self {
        self.max_joint_step_centideg = centideg;
        self
    }

    /// Solves and returns the next step's joint angles (a whole step, or the largest part of one
    /// that keeps every joint within the per-step limit); `None` once the target was reached or
    /// after an error (which ends the path).
    pub fn next(&mut self, kin: &Kinematics) -> Option<Result<JointAngles, PathError>> {
        let limit = self.max_joint_step_centideg;
        self.walker
            .advance(kin, self.step_um, limit, limit)
            .map(|r| r.map(|(q, _)| q))
    }

    /// Whole steps in the path (more calls of [`LinearPath::next`] where steps get split).
    pub fn total_steps(&self) -> u32 {
        let steps = div_ceil(self.walker.path().length_um(), self.step_um).max(1);
        u32::try_from(steps).unwrap_or(u32::MAX)
    }

    /// Whole steps not yet taken, rounded up (0 once done or stopped).
    pub fn remaining_steps(&self) -> u32 {
        u32::try_from(div_ceil(self.walker.remaining_um(), self.step_um)).unwrap_or(u32::MAX)
    }

    /// The joint angles of the last step taken (the start before the first step).
    pub fn current(&self) -> JointAngles {
        self.walker.current()
    }
}

/// a / b rounded up, for a >= 0 and b > 0.
fn div_ceil(a: i64, b: i64) -> i64 {
    ratio(a + b - 1, b)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::transform::Rotation;

    fn start() -> JointAngles {
        JointAngles([1_000, -3_000, -6_000, 1_500, 2_000, 500])
    }

    fn pose_of(kin: &Kinematics, q: &JointAngles) -> Transform {
        kin.forward_transform(q)
    }

    /// Angle between two rotations, centidegrees.
    fn angle_between(a: &Rotation, b: &Rotation) -> i32 {
        a.transpose().mul(b).to_axis_angle().1.to_centideg().abs()
    }

    #[test]
    fn position_follows_the_line_with_fixed_orientation() {
        let kin = Kinematics::new();
        let from = kin.forward(&start());
        let to = Pose {
            x: from.x - 400,
            y: from.y + 300,
            z: from.z - 200,
            ..from
        };
        let mut path = LinearPath::new(&kin, &start(), &to, 20).unwrap();
        // 53.9 mm in 2 mm steps.
        assert_eq!(path.total_steps(), 27);
        let mut last = None;
        while let Some(step) = path.next(&kin) {
            let q = step.unwrap();
            let t = pose_of(&kin, &q);
            // Distance from the line, in 0.1 mm: |(p - a) x d| / |d| with d = (-400, 300, -200).
            let [px, py, pz] = t.position.map(|v| v as f64 / LEN_PER_TENTH_MM as f64);
            let (ax, ay, az) = (px - from.x as f64, py - from.y as f64, pz - from.z as f64);
            let (dx, dy, dz) = (-400.0, 300.0, -200.0);
            let cross = ((ay * dz - az * dy).powi(2)
                + (az * dx - ax * dz).powi(2)
                + (ax * dy - ay * dx).powi(2))
            .sqrt();
            assert!(
                cross / 538.5 < 1.0,
                "{:.2} (0.1 mm) off the line at {q:?}",
                cross / 538.5
            );
            assert!(angle_between(&t.rotation, &Transform::from_pose(&from).rotation) <= 3);
            last = Some(q);
        }
        assert_eq!(path.remaining_steps(), 0);
        let end = kin.forward(&last.unwrap());
        assert!(
            (end.x - to.x).abs() <= 1 && (end.y - to.y).abs() <= 1 && (end.z - to.z).abs() <= 1,
            "{end:?}"
        );
    }

    #[test]
    fn orientation_turns_along_the_shortest_rotation() {
        let kin = Kinematics::new();
        let from = kin.forward(&start());
        let to = Pose {
            rx: from.rx + 2_000,
            ry: from.ry - 1_500,
            rz: from.rz + 1_000,
            ..from
        };
        let (r0, r1) = (
            Transform::from_pose(&from).rotation,
            Transform::from_pose(&to).rotation,
        );
        let total = angle_between(&r0, &r1);
        let mut path = LinearPath::new(&kin, &start(), &to, 10).unwrap();
        assert_eq!(path.total_steps() as i32, (total + 99) / 100);
        let mut previous_turn = 0;
        while let Some(step) = path.next(&kin) {
            let t = pose_of(&kin, &step.unwrap());
            let (done, left) = (
                angle_between(&r0, &t.rotation),
                angle_between(&t.rotation, &r1),
            );
            // On the geodesic: the two parts add up to the whole, and progress is monotonic.
            assert!(
                (done + left - total).abs() <= 4,
                "{done} + {left} vs {total}"
            );
            assert!(done >= previous_turn);
            previous_turn = done;
            let p = t.to_pose();
            assert!(
                (p.x - from.x).abs() <= 1 && (p.y - from.y).abs() <= 1 && (p.z - from.z).abs() <= 1
            );
        }
    }

    #[test]
    fn leaving_the_stretched_zero_pose_slows_down_instead_of_jumping() {
        // Straight down from the upright arm: q3 grows like the square root of the distance,
        // so the first 2 mm step alone would bend the elbow by 16 deg.
        let kin = Kinematics::new();
        let zero = JointAngles::default();
        let from = kin.forward(&zero);
        let to = Pose {
            z: from.z - 500,
            ..from
        };
        let mut path = LinearPath::new(&kin, &zero, &to, 20).unwrap();
        assert_eq!(path.total_steps(), 25);
        let (mut calls, mut previous) = (0, zero);
        while let Some(step) = path.next(&kin) {
            let q = step.unwrap();
            assert!(
                q.0.iter()
                    .zip(previous.0.iter())
                    .all(|(a, b)| (a - b).abs() <= DEFAULT_MAX_JOINT_STEP_CENTIDEG)
            );
            let p = kin.forward(&q);
            assert!(
                (p.x - from.x).abs() <= 1 && (p.y - from.y).abs() <= 1,
                "{p:?}"
            );
            assert!(p.z <= kin.forward(&previous).z, "z went up: {p:?}");
            previous = q;
            calls += 1;
        }
        assert!(calls > 25, "{calls}");
        assert_eq!(kin.forward(&previous).z, to.z);
    }

    #[test]
    fn unreachable_target_is_refused_up_front() {
        let kin = Kinematics::new();
        let far = Pose {
            x: 4_000,
            y: 0,
            z: 2_000,
            ..Pose::default()
        };
        assert_eq!(
            LinearPath::new(&kin, &start(), &far, 20).err(),
            Some(IkError::Unreachable)
        );
    }

    #[test]
    fn a_line_through_the_shoulder_cylinder_stops_with_an_error() {
        let kin = Kinematics::new();
        // Pointing down at x = 30 mm: the wrist passes 30 mm from the J1 axis, inside its
        // 63.4 mm dead cylinder, halfway between y = +150 and y = -150.
        let a = Pose {
            x: 300,
            y: 1_500,
            z: 2_000,
            rx: 18_000,
            ry: 0,
            rz: 0,
        };
        let b = Pose { y: -1_500, ..a };
        let q = kin.inverse(&a, &JointAngles::default()).unwrap();
        let mut path = LinearPath::new(&kin, &q, &b, 20).unwrap();
        let mut error = None;
        while let Some(step) = path.next(&kin) {
            match step {
                Ok(q) => {
                    let p = kin.forward(&q);
                    assert!(
                        (p.x - 300).abs() <= 2 && (p.z - 2_000).abs() <= 2,
                        "left the line: {p:?}"
                    );
                }
                Err(e) => error = Some(e),
            }
        }
        let error = error.unwrap();
        assert!(matches!(error.protocol_code(), 33 | 34), "{error:?}");
        assert_eq!(path.remaining_steps(), 0);
        assert!(path.next(&kin).is_none());
    }

    #[test]
    fn a_tight_joint_step_limit_reports_a_jump() {
        let kin = Kinematics::new();
        let from = kin.forward(&start());
        let to = Pose {
            z: from.z - 800,
            ..from
        };
        let mut path = LinearPath::new(&kin, &start(), &to, 400)
            .unwrap()
            .with_max_joint_step(10);
        assert!(matches!(
            path.next(&kin),
            Some(Err(PathError::BranchJump { .. }))
        ));
        assert_eq!(path.current(), start());
    }

    #[test]
    fn a_ray_moves_along_its_axis_and_a_turn_keeps_the_position() {
        let kin = Kinematics::new();
        let from = kin.forward_transform(&start());
        let ray = Ray::new(from, 2, false);
        let mut walker = PathWalker::new(ray, start());
        let mut went_um = 0;
        for _ in 0..10 {
            let (q, taken) = walker.advance(&kin, 1_000, 300, 500).unwrap().unwrap();
            went_um += taken;
            let p = kin.forward(&q);
            let f = from.to_pose();
            assert_eq!((p.x, p.y), (f.x, f.y), "{p:?}");
            assert!((i64::from(f.z - p.z) - went_um / 100).abs() <= 1, "{p:?}");
            assert!(angle_between(&kin.forward_transform(&q).rotation, &from.rotation) <= 2);
        }
        assert_eq!(walker.done_um(), 10_000);

        let turn = Turn::new(from, 2, true);
        let mut walker = PathWalker::new(turn, start());
        let (q, taken) = walker.advance(&kin, 5_000, 1_000, 1_000).unwrap().unwrap();
        assert_eq!(taken, 5_000);
        let t = kin.forward_transform(&q);
        let (p, f) = (t.to_pose(), from.to_pose());
        assert!((p.x - f.x).abs() <= 1 && (p.y - f.y).abs() <= 1 && (p.z - f.z).abs() <= 1);
        // 5 mm of path is 5 deg about the base z axis.
        assert!((angle_between(&t.rotation, &from.rotation) - 500).abs() <= 2);
    }

    #[test]
    fn a_walker_takes_less_than_asked_where_joints_would_move_too_far() {
        let kin = Kinematics::new();
        let zero = JointAngles::default();
        let from = kin.forward(&zero);
        let to = Pose {
            z: from.z - 500,
            ..from
        };
        let line = Line::new(&kin, &zero, &to).unwrap();
        // 412.67 mm down to 362.7 mm.
        assert_eq!(line.length_um(), 49_970);
        let mut walker = PathWalker::new(line, zero);
        let (_, taken) = walker.advance(&kin, 2_000, 500, 500).unwrap().unwrap();
        assert!(taken < 2_000, "{taken}");
        assert_eq!(walker.remaining_um(), 49_970 - taken);
    }

    #[test]
    fn error_codes_match_the_protocol() {
        assert_eq!(PathError::BranchJump { joint: 3 }.protocol_code(), 33);
        assert_eq!(
            PathError::StepUnreachable(IkError::Unreachable).protocol_code(),
            34
        );
        assert_eq!(IkError::PROTOCOL_CODE, 32);
    }
}
