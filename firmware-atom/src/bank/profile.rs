//! What a servo does with the goal it was sent, worked out from the goal alone: the STS servo's
//! own motion profile (`docs/servo-bus.md`), which carries its setpoint towards the goal
//! position at up to the goal speed, speeding up and slowing down at the acceleration
//! register's rate, and stops on the goal. A new goal continues the profile from where its
//! setpoint is and how fast it moves.
//!
//! This is where a joint is *told* to be, whatever its state reads say: a stop brakes from it
//! when the reads are late or missing, so that a joint whose last read is old is neither
//! braked back towards where it was then nor left running to its last goal.

/// Microseconds per second.
const US_PER_S: i64 = 1_000_000;

/// Most phases of one profile worked out (a reversal, slowing to the speed limit, speeding
/// up, cruising, braking, and an overshoot's way back), with room to spare.
const MAX_PHASES: usize = 12;

/// Bounds that keep every product below `i64::MAX` (whatever a reading said): positions within
/// 2^24 thousandths of a step (4 096 turns' worth of steps), speeds within 2^26 (67 000
/// steps/s), accelerations within 2^30, time within 2^36 us (19 hours: a profile is long over).
const POSITION_BOUND: i64 = 1 << 24;
const SPEED_BOUND: i64 = 1 << 26;
const ACCEL_BOUND: i64 = 1 << 30;
const TIME_BOUND_US: i64 = 1 << 36;

/// Where a servo's setpoint is and how fast it moves.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct Motion {
    /// Position, thousandths of a step.
    pub millisteps: i64,
    /// Speed, thousandths of a step per second (signed).
    pub millisteps_per_s: i64,
}

/// One goal a servo follows from the motion it had when the goal reached it.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct Segment {
    /// When the goal reached the servo, monotonic microseconds.
    pub start_us: u64,
    /// The setpoint's motion then.
    pub from: Motion,
    /// The goal position, thousandths of a step.
    pub goal_millisteps: i64,
    /// The goal speed, thousandths of a step per second (at least 1).
    pub speed_millisteps_per_s: i64,
    /// The acceleration, thousandths of a step per second squared (at least 1).
    pub accel_millisteps_per_s2: i64,
}

impl Segment {
    /// The setpoint's motion at `now_us` (its motion at the start before then).
    pub fn at(&self, now_us: u64) -> Motion {
        let goal = self.goal_millisteps.clamp(-POSITION_BOUND, POSITION_BOUND);
        let vmax = self.speed_millisteps_per_s.clamp(1, SPEED_BOUND);
        let a = self.accel_millisteps_per_s2.clamp(1, ACCEL_BOUND);
        let mut p = self.from.millisteps.clamp(-POSITION_BOUND, POSITION_BOUND);
        let mut v = self.from.millisteps_per_s.clamp(-SPEED_BOUND, SPEED_BOUND);
        let elapsed = now_us
            .saturating_sub(self.start_us)
            .min(TIME_BOUND_US as u64);
        let mut left = elapsed as i64;
        for _ in 0..MAX_PHASES {
            let e = goal - p;
            if left <= 0 || (e == 0 && v == 0) {
                break;
            }
            // Work towards the goal: `u` is the speed towards it (negative: away from it).
            let s = if e != 0 { e.signum() } else { -v.signum() };
            let (d, u) = (e.abs(), v * s);
            let phase = phase(d, u, vmax, a);
            let t = phase.duration_us.clamp(1, left);
            if t == phase.duration_us {
                // The phase ends exactly where it was worked out to end.
                p += s * phase.travel;
                v = s * phase.end_speed;
            } else {
                let dv = phase.accel.saturating_mul(t) / US_PER_S;
                let travel = (u + dv / 2).saturating_mul(t) / US_PER_S;
                p = p.saturating_add(s * travel);
                v = s * (u + dv);
            }
            p = p.clamp(-POSITION_BOUND, POSITION_BOUND);
            v = v.clamp(-SPEED_BOUND, SPEED_BOUND);
            left -= t;
        }
        Motion {
            millisteps: p,
            millisteps_per_s: v,
        }
    }
}

/// One phase of constant acceleration, towards the goal.
struct Phase {
    /// Acceleration towards the goal (negative: braking).
    accel: i64,
    /// How long it lasts, microseconds (at least 1).
    duration_us: i64,
    /// The speed towards the goal at its end.
    end_speed: i64,
    /// How far towards the goal it goes.
    travel: i64,
}

/// The phase a profile `d` from its goal, moving towards it at `u`, is in: at most `vmax`, and
/// `a` to change speed (all thousandths of steps, per second, per second squared; within the
/// bounds above, so no product overflows).
fn phase(d: i64, u: i64, vmax: i64, a: i64) -> Phase {
    let ceil_div = |n: i64, m: i64| (n + m.max(1) - 1) / m.max(1);
    if u < 0 {
        // Moving away: turn round.
        return Phase {
            accel: a,
            duration_us: ceil_div(-u * US_PER_S, a).max(1),
            end_speed: 0,
            travel: -(u * u) / (2 * a),
        };
    }
    if u > vmax {
        // Faster than allowed (a lower goal speed): slow down to it.
        return Phase {
            accel: -a,
            duration_us: ceil_div((u - vmax) * US_PER_S, a).max(1),
            end_speed: vmax,
            travel: (u * u - vmax * vmax) / (2 * a),
        };
    }
    if u > 0 && u * u * 9 >= 2 * a * d * 8 {
        // At the braking point (within an eighth: the phases before it end on whole
        // microseconds): brake onto the goal, at the rate that lands there if the servo can
        // brake that hard, else at its own and beyond it (turned round by the next phase).
        let need = u * u / (2 * d).max(1);
        if d > 0 && need * 8 <= a * 9 {
            return Phase {
                accel: -need,
                duration_us: ceil_div(2 * d * US_PER_S, u).max(1),
                end_speed: 0,
                travel: d,
            };
        }
        return Phase {
            accel: -a,
            duration_us: ceil_div(u * US_PER_S, a).max(1),
            end_speed: 0,
            travel: u * u / (2 * a),
        };
    }
    if u < vmax {
        // Speed up, to the limit or to where braking must start (w^2 = a d + u^2 / 2).
        let w = kinematics_core::fixed::sqrt(a * d + u * u / 2)
            .min(vmax)
            .max(u + 1);
        return Phase {
            accel: a,
            duration_us: ceil_div((w - u) * US_PER_S, a).max(1),
            end_speed: w,
            travel: (w * w - u * u) / (2 * a),
        };
    }
    // Cruise at the limit to the braking point.
    let cruise = (d - u * u / (2 * a)).max(0);
    Phase {
        accel: 0,
        duration_us: ceil_div(cruise * US_PER_S, u).max(1),
        end_speed: u,
        travel: cruise,
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn segment(from: i64, v: i64, goal: i64, speed: i64, accel: i64) -> Segment {
        Segment {
            start_us: 1_000,
            from: Motion {
                millisteps: from * 1000,
                millisteps_per_s: v * 1000,
            },
            goal_millisteps: goal * 1000,
            speed_millisteps_per_s: speed * 1000,
            accel_millisteps_per_s2: accel * 1000,
        }
    }

    #[test]
    fn a_move_from_rest_speeds_up_cruises_and_stops_on_its_goal() {
        // 1000 steps at 500 steps/s, 1000 steps/s^2: 0.5 s up (125 steps), 1.5 s cruise, 0.5 s
        // down.
        let s = segment(2_000, 0, 3_000, 500, 1_000);
        let at = |ms: u64| s.at(1_000 + ms * 1_000);
        assert_eq!(at(0).millisteps, 2_000_000);
        assert_eq!(at(500).millisteps_per_s, 500_000);
        assert!(
            (at(500).millisteps - 2_125_000).abs() <= 1_000,
            "{:?}",
            at(500)
        );
        assert!(
            (at(1_000).millisteps - 2_375_000).abs() <= 1_000,
            "{:?}",
            at(1_000)
        );
        assert_eq!(
            at(2_500),
            Motion {
                millisteps: 3_000_000,
                millisteps_per_s: 0
            }
        );
        assert_eq!(at(9_000).millisteps, 3_000_000, "and stays");
    }

    #[test]
    fn a_short_move_is_a_triangle_and_a_reversal_turns_round_first() {
        let s = segment(0, 0, 100, 3_000, 10_000);
        // 100 steps at 10 000 steps/s^2: up for 0.1 s to 1000 steps/s, down for 0.1 s.
        let top = s.at(1_000 + 100_000);
        assert!((top.millisteps_per_s - 1_000_000).abs() <= 2_000, "{top:?}");
        assert_eq!(s.at(1_000 + 200_100).millisteps, 100_000);
        // Moving away from the goal at 1000 steps/s: 0.1 s to turn round, 50 steps beyond.
        let back = segment(0, -1_000, 100, 3_000, 10_000);
        let turned = back.at(1_000 + 100_000);
        assert!((turned.millisteps + 50_000).abs() <= 100, "{turned:?}");
        assert_eq!(back.at(1_000 + 2_000_000).millisteps, 100_000);
    }

    #[test]
    fn a_lower_goal_speed_slows_the_profile_down() {
        let s = segment(0, 1_000, 10_000, 200, 1_000);
        let slowed = s.at(1_000 + 800_000);
        assert_eq!(slowed.millisteps_per_s, 200_000);
        // 0.8 s from 1000 to 200 steps/s: 480 steps.
        assert!((slowed.millisteps - 480_000).abs() <= 1_000, "{slowed:?}");
    }

    #[test]
    fn the_simulated_servo_follows_the_same_profile() {
        use protocol_core::servo::{Instruction, reg};
        use sim_hw::SimServo;
        let mut servo = SimServo::new(1, 2_048);
        let write = |servo: &mut SimServo, at_ns: u64, addr: u8, data: &[u8]| {
            let packet = Instruction::Write { addr, data }.to_packet(1).unwrap();
            servo.receive(&packet, at_ns);
        };
        write(&mut servo, 0, reg::TORQUE_ENABLE, &[1]);
        // Goal 2548 at 800 steps/s, register 30 (3000 steps/s^2); then, mid-way, back to 2300
        // at 400 steps/s, register 50.
        let block = |goal: u16, speed: u16, accel: u8| {
            let [g0, g1] = goal.to_le_bytes();
            let [s0, s1] = speed.to_le_bytes();
            [accel, g0, g1, 0, 0, s0, s1]
        };
        write(
            &mut servo,
            10_000_000,
            reg::ACCELERATION,
            &block(2_548, 800, 30),
        );
        let first = segment(2_048, 0, 2_548, 800, 3_000);
        let first = Segment {
            start_us: 10_000,
            ..first
        };
        let mut worst: f64 = 0.0;
        for ms in 11..300u64 {
            servo.advance(ms * 1_000_000);
            let model = first.at(ms * 1_000).millisteps as f64 / 1000.0;
            worst = worst.max((servo.setpoint_steps() - model).abs());
        }
        let turn_us = 300_000;
        let from = first.at(turn_us);
        write(
            &mut servo,
            turn_us * 1_000,
            reg::ACCELERATION,
            &block(2_300, 400, 50),
        );
        let second = Segment {
            start_us: turn_us,
            from,
            goal_millisteps: 2_300_000,
            speed_millisteps_per_s: 400_000,
            accel_millisteps_per_s2: 5_000_000,
        };
        for ms in 301..1_500u64 {
            servo.advance(ms * 1_000_000);
            let model = second.at(ms * 1_000).millisteps as f64 / 1000.0;
            worst = worst.max((servo.setpoint_steps() - model).abs());
        }
        // The servo steps its profile each millisecond; the model is continuous.
        assert!(
            worst < 1.0,
            "the model strays {worst:.2} steps from the servo"
        );
        assert_eq!(second.at(1_500_000).millisteps, 2_300_000);
    }
}
