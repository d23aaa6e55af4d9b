//! Following a sequence of joint targets (a host's stream, or the points of a Cartesian path)
//! without stopping between them.
//!
//! A target comes with the time until the next one is due (the stream's period, or the path's
//! interpolation period). Each joint gets the goal speed that carries it from where it is now
//! to the target in that time, so it passes the target just as the next one arrives. Its goal
//! lies beyond the target by the distance the servo needs to brake from that speed (plus a
//! quarter period for a late target), so the servo never starts braking while targets keep
//! coming; the last target of a sequence is the goal itself.

use protocol_core::units::{Centideg, Steps};

use crate::bank::ServoBank;
use crate::config::{JOINTS, SERVOS, STEPS_PER_TURN};
use crate::safety::{Goal, GoalSet};
use crate::settings::Settings;

/// The goals that carry the joints to `target` in `period_us` and on (see the
/// [module doc](self)), no joint faster than `speed_cap_steps_per_s`. `last`: the sequence
/// ends here, stop at `target`.
pub fn goals_towards(
    bank: &ServoBank,
    settings: &Settings,
    target: &[Centideg; JOINTS],
    period_us: u64,
    speed_cap_steps_per_s: u32,
    last: bool,
) -> GoalSet {
    let config = settings.config();
    let a = i64::from(config.motion.servo_accel_steps_per_s2.max(1));
    let period = period_us.max(1) as i64;
    let cap = i64::from(speed_cap_steps_per_s.max(1));
    let mut goals: GoalSet = [None; SERVOS];
    for (j, slot) in goals.iter_mut().take(JOINTS).enumerate() {
        if !bank.health(j).is_some_and(|h| h.answering) {
            continue;
        }
        let angle = target.get(j).copied().unwrap_or_default();
        let to = config.angle_to_millisteps(j, i32::from(angle.0));
        let from = bank.estimated_millisteps(j);
        // Thousandths of a step per microsecond = steps per millisecond: times 1000 is steps/s.
        let speed = ((to - from) * 1000 / period).clamp(-cap, cap);
        let beyond = if last {
            0
        } else {
            speed * speed.abs() * 1000 / (2 * a) + speed * period / 4000
        };
        let position = goal_position(settings, j, to + beyond);
        *slot = Some(Goal {
            position,
            speed_steps_per_s: speed.unsigned_abs().max(1) as u16,
            accel: config.servo_accel_register(),
        });
    }
    goals
}

/// The encoder goal nearest `millisteps` that lies within joint `j`'s limits.
fn goal_position(settings: &Settings, j: usize, millisteps: i64) -> Steps {
    let steps = (millisteps + 500)
        .div_euclid(1000)
        .clamp(0, i64::from(STEPS_PER_TURN) - 1);
    let mut angle = settings.angle(j, Steps(steps as i16));
    if let Some(limit) = settings.limit(j) {
        angle = angle.clamp(limit.min, limit.max);
    }
    settings.goal_steps(j, angle)
}
