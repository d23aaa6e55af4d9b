//! Every "close enough" of the Atom in one place: when joints, poses and servos count as
//! being where they were sent.

use protocol_core::command::Pose;
use protocol_core::units::{Centideg, Steps};

use crate::config::JOINTS;

/// Joint-angle tolerance of "is in position" and of the end of a move: one degree, a little
/// more than the servo's dead band plus one encoder step.
pub const IN_POSITION_CENTIDEG: i32 = 100;

/// Pose tolerance of "is in position" for coordinates: 2 mm (20 wire units of 0.1 mm) and
/// 1 deg (100 wire units of 0.01 deg).
pub const IN_POSITION_POSE: (i32, i32) = (20, 100);

/// Distance within which the arm counts as already at the start of an arc (0x8B), so no line
/// leads to it: 0.5 mm (5 wire units) and 0.5 deg (50).
pub const AT_ARC_START: (i32, i32) = (5, 50);

/// Distance from its goal within which a servo counts as arrived: 10 steps, under one degree.
pub const IN_POSITION_STEPS: i32 = 10;

/// Largest difference between the goal a servo was sent and the goal register it reports
/// that still counts as the same goal: one step (the servo may round).
pub const GOAL_READBACK_STEPS: i32 = 1;

/// True if every joint of `present` is within [`IN_POSITION_CENTIDEG`] of `target`.
pub fn angles_match(present: &[Centideg; JOINTS], target: &[Centideg; JOINTS]) -> bool {
    present
        .iter()
        .zip(target)
        .all(|(p, t)| (i32::from(p.0) - i32::from(t.0)).abs() <= IN_POSITION_CENTIDEG)
}

/// True if two poses are within [`IN_POSITION_POSE`] of each other (is in position, 0x2A).
pub fn coords_match(a: &Pose, b: &Pose) -> bool {
    poses_within(a, b, IN_POSITION_POSE)
}

/// True if the arm at `here` counts as at an arc's start `begin` ([`AT_ARC_START`]).
pub fn at_arc_start(here: &Pose, begin: &Pose) -> bool {
    poses_within(here, begin, AT_ARC_START)
}

/// True if a servo at `position` counts as arrived at its goal `goal` ([`IN_POSITION_STEPS`]).
pub fn servo_at(goal: Steps, position: Steps) -> bool {
    steps_within(goal, position, IN_POSITION_STEPS)
}

/// True if a servo's reported goal register `reported` confirms the goal `sent`
/// ([`GOAL_READBACK_STEPS`]).
pub fn goal_confirmed(sent: Steps, reported: Steps) -> bool {
    steps_within(sent, reported, GOAL_READBACK_STEPS)
}

fn steps_within(a: Steps, b: Steps, tolerance: i32) -> bool {
    (i32::from(a.0) - i32::from(b.0)).abs() <= tolerance
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

#[cfg(test)]
mod tests {
    use super::*;
    use protocol_core::units::DeciMm;

    #[test]
    fn joints_match_within_one_degree() {
        let target = [Centideg(1_000); JOINTS];
        let mut present = target;
        present[2] = Centideg(1_100);
        assert!(angles_match(&present, &target));
        present[2] = Centideg(1_101);
        assert!(!angles_match(&present, &target));
    }

    #[test]
    fn poses_match_within_two_mm_and_one_degree_across_the_wrap() {
        let a = Pose {
            x: DeciMm(1_000),
            rz: Centideg(17_990),
            ..Pose::default()
        };
        let b = Pose {
            x: DeciMm(1_020),
            rz: Centideg(-17_950),
            ..Pose::default()
        };
        assert!(coords_match(&a, &b), "2 mm and 0.6 deg across +-180");
        assert!(!at_arc_start(&a, &b), "the arc start is stricter");
        let c = Pose {
            x: DeciMm(1_021),
            ..b
        };
        assert!(!coords_match(&a, &c));
    }

    #[test]
    fn a_servo_arrives_within_ten_steps_and_confirms_its_goal_within_one() {
        assert!(servo_at(Steps(2_048), Steps(2_058)));
        assert!(!servo_at(Steps(2_048), Steps(2_059)));
        assert!(goal_confirmed(Steps(2_048), Steps(2_047)));
        assert!(!goal_confirmed(Steps(2_048), Steps(2_046)));
    }
}
