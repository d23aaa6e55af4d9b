//! Planned joint moves: how fast each servo must go so that a joint-interpolated move arrives
//! everywhere at once (the servos' own ramps carry it out).

use protocol_core::units::Steps;

use crate::config::{AtomConfig, JOINTS};
use crate::safety::{Goal, Goals};

/// A move waits at most this long beyond its planned duration before it is declared done
/// (a stalled or missing servo must not block the queue forever).
pub const MOVE_OVERTIME_US: u64 = 2_000_000;

/// A joint-interpolated move from `present` to `target`: every joint's speed and acceleration
/// are scaled by its share of the longest travel, so that all joints start and arrive together.
/// Returns the goals (gripper untouched) and the planned duration in microseconds.
pub fn plan_joint_move(
    config: &AtomConfig,
    present: &[Steps; JOINTS],
    target: &[Option<Steps>; JOINTS],
    speed_percent: u8,
) -> (Goals, u64) {
    let travel = |j: usize| -> u32 {
        match (target.get(j).copied().flatten(), present.get(j)) {
            (Some(t), Some(p)) => (i32::from(t.0) - i32::from(p.0)).unsigned_abs(),
            _ => 0,
        }
    };
    let longest = (0..JOINTS).map(travel).max().unwrap_or(0).max(1);
    let v_max = config.joint_speed_steps(speed_percent);
    let a_max = u32::from(config.joint_accel_register());
    let mut goals = Goals::NONE;
    for j in 0..JOINTS {
        if let Some(position) = target.get(j).copied().flatten() {
            let share = travel(j);
            goals.set(
                j,
                Some(Goal {
                    position,
                    speed_steps_per_s: (v_max * share / longest).clamp(1, u32::from(u16::MAX))
                        as u16,
                    accel: (a_max * share / longest).clamp(1, 254) as u8,
                }),
            );
        }
    }
    // Trapezoid: travel / v + v / a (the ramp up and down add one ramp's time).
    let accel_steps = a_max * 100;
    let duration_us = u64::from(longest) * 1_000_000 / u64::from(v_max)
        + u64::from(v_max) * 1_000_000 / u64::from(accel_steps.max(1));
    (goals, duration_us)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn joints_are_scaled_to_arrive_together() {
        let cfg = AtomConfig::default();
        let present = [Steps(2048); JOINTS];
        let target = [
            Some(Steps(3048)),
            Some(Steps(1548)),
            Some(Steps(2048)),
            None,
            Some(Steps(2298)),
            Some(Steps(2048)),
        ];
        let (goals, duration) = plan_joint_move(&cfg, &present, &target, 100);
        let speed = |j: usize| u32::from(goals.get(j).unwrap().speed_steps_per_s);
        let v_max = cfg.joint_speed_steps(100);
        assert_eq!(speed(0), v_max);
        assert_eq!(speed(1), v_max / 2);
        assert_eq!(speed(4), v_max / 4);
        assert_eq!(
            speed(2),
            1,
            "a joint that stays put never gets speed 0 (= full speed)"
        );
        assert!(goals.get(3).is_none());
        // 1000 steps at 1706 steps/s plus one ramp.
        assert!((500_000..1_500_000).contains(&duration), "{duration}");
    }

    #[test]
    fn lower_speed_percent_is_slower() {
        let cfg = AtomConfig::default();
        let present = [Steps(2048); JOINTS];
        let target = [Some(Steps(3048)); JOINTS];
        let (_, fast) = plan_joint_move(&cfg, &present, &target, 100);
        let (_, slow) = plan_joint_move(&cfg, &present, &target, 10);
        assert!(slow > 3 * fast, "{slow} vs {fast}");
    }
}
