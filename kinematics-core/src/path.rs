//! Straight-line Cartesian motion (move mode 1, jog coord): the position moves along the line,
//! the orientation turns about the one axis of the shortest rotation, and every step is solved
//! with the previous step as seed, so the arm stays on one branch. Where a step would move a
//! joint more than the per-step limit (next to a singularity joints speed up), the step is
//! halved, down to 1/64: the path slows there instead of flailing. A step that has no solution,
//! or that still jumps at 1/64 (a branch switch, e.g. through the wrist singularity), stops the
//! path instead of being executed.

use crate::fixed::{Angle, ratio};
use crate::transform::{LEN_PER_TENTH_MM, Rotation, Transform};
use crate::{IkError, JointAngles, Kinematics, Pose};

/// Default for [`LinearPath::with_max_joint_step`]: 5 deg, a few interpolation periods of a joint
/// at full speed; ordinary steps of a few millimetres need well under 2 deg.
pub const DEFAULT_MAX_JOINT_STEP_CENTIDEG: i32 = 500;

/// A step may be halved this many times (to 1/64) to keep joints within the per-step limit.
const SPLIT_BITS: u32 = 6;

/// Most steps in a path (2^20: 100 m at 0.1 mm per step), keeping the interpolation in `i64`.
const MAX_STEPS: i64 = 1 << 20;

/// Rotation allowed per step for each 0.1 mm of step length: 0.1 deg, i.e. a 1 mm step may turn
/// 1 deg (the end moves about 1 mm per degree at the flange's 57 mm lever).
const CENTIDEG_PER_TENTH_MM_STEP: i64 = 10;

/// Why a linear move stops (protocol 0x07 codes in [`PathError::protocol_code`]).
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
}

impl PathError {
    /// The 0x07 error code: 33 for a branch jump, 34 for an unreachable step.
    pub fn protocol_code(&self) -> u8 {
        match self {
            Self::BranchJump { .. } => 33,
            Self::StepUnreachable(_) => 34,
        }
    }
}

/// A straight line from a start configuration to a target pose (in the model's selected tool and
/// world frames), in equal steps (split near singularities); yields each step's joint angles,
/// the last one solving the target itself.
#[derive(Clone, Copy, Debug)]
pub struct LinearPath {
    start: Transform,
    target: Transform,
    /// Unit axis (Q30) and angle of the rotation from the start to the target orientation,
    /// expressed in the start frame.
    axis: [i64; 3],
    angle: Angle,
    previous: JointAngles,
    /// Progress and length of the line in 1/64 steps.
    done: i64,
    total: i64,
    max_joint_step_centideg: i32,
    stopped: bool,
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
        let target = Transform::from_pose(target);
        kin.inverse_transform(&target, start)?;
        let from = kin.forward_transform(start);
        let (axis, angle) = from
            .rotation
            .transpose()
            .mul(&target.rotation)
            .to_axis_angle();
        let step_tenth_mm = i64::from(step_tenth_mm.max(1));
        let [dx, dy, dz] = [0, 1, 2].map(|i| {
            target.position.get(i).copied().unwrap_or(0)
                - from.position.get(i).copied().unwrap_or(0)
        });
        let distance_tenth_mm = crate::fixed::sqrt(dx * dx + dy * dy + dz * dz) / LEN_PER_TENTH_MM;
        let by_distance = div_ceil(distance_tenth_mm, step_tenth_mm);
        let by_rotation = div_ceil(
            i64::from(angle.to_centideg().abs()),
            step_tenth_mm * CENTIDEG_PER_TENTH_MM_STEP,
        );
        let steps = by_distance.max(by_rotation).clamp(1, MAX_STEPS);
        Ok(Self {
            start: from,
            target,
            axis,
            angle,
            previous: *start,
            done: 0,
            total: steps << SPLIT_BITS,
            max_joint_step_centideg: DEFAULT_MAX_JOINT_STEP_CENTIDEG,
            stopped: false,
        })
    }

    /// The same path with a different largest joint change per step, centidegrees.
    #[must_use]
    pub fn with_max_joint_step(mut self, centideg: i32) -> Self {
        self.max_joint_step_centideg = centideg;
        self
    }

    /// The pose (full precision) at `at` 1/64 steps along the line.
    fn waypoint(&self, at: i64) -> Transform {
        if at >= self.total {
            return self.target;
        }
        let lerp = |i: usize| {
            let a = self.start.position.get(i).copied().unwrap_or(0);
            let b = self.target.position.get(i).copied().unwrap_or(0);
            a + ratio((b - a) * at, self.total)
        };
        let turn = Angle(ratio(i64::from(self.angle.0) * at, self.total) as i32);
        Transform {
            rotation: self
                .start
                .rotation
                .mul(&Rotation::about_axis(&self.axis, turn)),
            position: [lerp(0), lerp(1), lerp(2)],
        }
    }

    /// Solves and returns the next step's joint angles (a whole step, or the largest part of one
    /// that keeps every joint within the per-step limit); `None` once the target was reached or
    /// after an error (which ends the path).
    pub fn next(&mut self, kin: &Kinematics) -> Option<Result<JointAngles, PathError>> {
        if self.stopped || self.done >= self.total {
            return None;
        }
        let mut size = 1 << SPLIT_BITS;
        let result = loop {
            let at = (self.done + size).min(self.total);
            let q = match kin.inverse_transform(&self.waypoint(at), &self.previous) {
                Ok(q) => q,
                Err(e) => break Err(PathError::StepUnreachable(e)),
            };
            match self.jumping_joint(&q) {
                None => {
                    self.done = at;
                    self.previous = q;
                    break Ok(q);
                }
                Some(_) if size > 1 => size /= 2,
                Some(joint) => break Err(PathError::BranchJump { joint }),
            }
        };
        self.stopped = result.is_err();
        Some(result)
    }

    /// The first joint that moves more than the per-step limit from the previous step.
    fn jumping_joint(&self, q: &JointAngles) -> Option<usize> {
        q.0.iter().zip(self.previous.0.iter()).position(|(a, b)| {
            (i64::from(*a) - i64::from(*b)).abs() > i64::from(self.max_joint_step_centideg)
        })
    }

    /// Whole steps in the path (more calls of [`LinearPath::next`] where steps get split).
    pub fn total_steps(&self) -> u32 {
        u32::try_from(self.total >> SPLIT_BITS).unwrap_or(u32::MAX)
    }

    /// Whole steps not yet taken, rounded up (0 once done or stopped).
    pub fn remaining_steps(&self) -> u32 {
        if self.stopped {
            return 0;
        }
        let left = div_ceil(self.total - self.done, 1 << SPLIT_BITS);
        u32::try_from(left).unwrap_or(u32::MAX)
    }

    /// The joint angles of the last step taken (the start before the first step).
    pub fn current(&self) -> JointAngles {
        self.previous
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
    fn error_codes_match_the_protocol() {
        assert_eq!(PathError::BranchJump { joint: 3 }.protocol_code(), 33);
        assert_eq!(
            PathError::StepUnreachable(IkError::Unreachable).protocol_code(),
            34
        );
        assert_eq!(IkError::PROTOCOL_CODE, 32);
    }
}
