//! Braking: the goals that bring every moving joint to rest as fast as the servos can, all
//! joints together along the path they were on.

use protocol_core::units::{Centideg, Steps};

use crate::bank::Motion;
use crate::config::{JOINTS, STEPS_PER_TURN};
use crate::context::Context;
use crate::safety::{Goal, Goals};

/// Time from computing a goal to the servo acting on it, in microseconds: a transaction may be
/// on the wire (up to about 0.6 ms), then the gap and the SYNC WRITE itself (about 0.7 ms).
pub const GOAL_LATENCY_US: u64 = 1_500;

/// Goal speed of a stopping joint that is (nearly) at rest, steps per second: lets it settle
/// on its goal at once (a moving joint keeps its own speed: its goal lies exactly where its
/// ramp ends, so a higher goal speed never speeds it up).
const SETTLE_SPEED_STEPS_PER_S: u64 = 50;

/// A stop: one goal per joint and when the last joint comes to rest.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct Braking {
    /// The stopping goal of each joint that holds torque.
    pub goals: Goals,
    /// Where each joint comes to rest (its present angle if it holds no torque).
    pub rest: [Centideg; JOINTS],
    /// Time from now until every joint is at rest, microseconds.
    pub duration_us: u64,
}

impl Braking {
    /// The stop of the arm at the step's time.
    ///
    /// The fastest joint brakes at the servos' full deceleration `a`
    /// ([`crate::config::MotionLimits::servo_accel_steps_per_s2`]), so it stops after
    /// `T = v_max / a`; every other joint brakes at `a * |v_j| / v_max` over the same `T`
    /// (acceleration registers in 100 steps/s^2 units express every such value), so all joints
    /// stop together, along the path they were on: a Cartesian jog or line keeps its pose while
    /// it stops, and no joint overshoots and swings back. Each goal lies where its joint comes
    /// to rest: where it is now ([`moving_now`]: what it was told, or a recent reading further
    /// along), plus what it covers until the goal arrives ([`GOAL_LATENCY_US`]) and while
    /// braking (`v_j * T / 2`). A stop is kept within the joint's limits, but a joint already
    /// past a limit (the user just tightened it) stays where it is rather than being dragged
    /// back.
    pub fn of(cx: &Context<'_>) -> Self {
        let (bank, settings) = (&*cx.bank, cx.settings);
        let config = settings.config();
        let a = i64::from(config.motion.servo_accel_steps_per_s2.max(1));
        // Every joint that holds torque, including one whose latest reads were lost: it still
        // hears the stop, and without a goal it would run on to its last one.
        let moving: [Option<Motion>; JOINTS] =
            core::array::from_fn(|j| bank.holds_torque(j).then(|| moving_now(cx, j)).flatten());
        let speed = |m: &Option<Motion>| m.map_or(0, |m| m.millisteps_per_s / 1000);
        let v_max = moving.iter().map(|m| speed(m).abs()).max().unwrap_or(0);
        let brake_us = v_max * 1_000_000 / a;
        let mut goals = Goals::NONE;
        let mut rest: [Centideg; JOINTS] = core::array::from_fn(|j| {
            let at = moving
                .get(j)
                .copied()
                .flatten()
                .map_or_else(|| bank.estimated_millisteps(cx.now_us, j), |m| m.millisteps);
            config.millisteps_to_angle(j, at)
        });
        for (j, m) in moving.iter().enumerate() {
            let Some(m) = m else {
                continue;
            };
            let v = m.millisteps_per_s / 1000;
            let stop = rest_steps(m, brake_us);
            let now = rest.get(j).copied().unwrap_or_default();
            let mut angle = settings.angle(j, stop);
            if let Some(limit) = settings.limit(j) {
                angle = angle.clamp(limit.min.min(now), limit.max.max(now));
            }
            let accel = if v_max == 0 {
                config.servo_accel_register()
            } else {
                ((a * v.abs() + v_max * 100 - 1) / (v_max * 100)).clamp(1, 254) as u8
            };
            let goal = Goal {
                position: settings.goal_steps(j, angle),
                speed_steps_per_s: v
                    .unsigned_abs()
                    .clamp(SETTLE_SPEED_STEPS_PER_S, u64::from(u16::MAX))
                    as u16,
                accel,
            };
            goals.set(j, Some(goal));
            if let Some(r) = rest.get_mut(j) {
                *r = angle;
            }
        }
        Self {
            goals,
            rest,
            duration_us: GOAL_LATENCY_US + brake_us as u64,
        }
    }

    /// Sends the stop, one joint at a time: a joint whose stop the safety check refuses (it
    /// stands outside its limits after being moved by hand) keeps its previous goal, and the
    /// others still stop.
    pub fn send(&self, cx: &mut Context<'_>) {
        for (j, goal) in self.goals.iter() {
            let _ = cx.send_goals(Goals::one(j, goal));
        }
    }
}

/// Where servo `index` is and how fast it moves at the step's time, as a stop brakes it: what
/// it was told ([`crate::bank::ServoBank::commanded`]: where its own profile has carried it
/// with its last goal) and what its latest reading says if that is recent
/// ([`crate::bank::ServoBank::observed`]), whichever is further along its way when both are
/// known. A stop never turns a joint back: a reading that waited, or one the joint has sped
/// away from since, lags behind it; a goal the servo missed leaves the command behind it. A
/// joint at rest is where its reading says. Without a recent reading the command alone
/// decides, never an old reading carried on at its old speed; without either, the joint rests
/// on its last goal.
fn moving_now(cx: &Context<'_>, index: usize) -> Option<Motion> {
    let told = cx.bank.commanded(cx.now_us, index);
    let seen = cx.bank.observed(cx.now_us, index);
    match (told, seen) {
        (Some(t), Some(s)) => {
            let way = match t.millisteps_per_s.signum() {
                0 => s.millisteps_per_s.signum(),
                w => w,
            };
            let seen_ahead = (s.millisteps - t.millisteps) * way > 0;
            Some(if way == 0 || seen_ahead { s } else { t })
        }
        (told, seen) => told.or(seen).or_else(|| cx.bank.motion(cx.now_us, index)),
    }
}

/// Where a servo moving as `m` comes to rest when it brakes evenly for `brake_us`: plus what
/// it covers until the goal arrives ([`GOAL_LATENCY_US`]) and while braking (`v * brake / 2`).
fn rest_steps(m: &Motion, brake_us: i64) -> Steps {
    let v = m.millisteps_per_s / 1000;
    let travel_millisteps = v * (GOAL_LATENCY_US as i64 + brake_us / 2) / 1000;
    let stop = (m.millisteps + travel_millisteps + 500).div_euclid(1000);
    Steps(stop.clamp(0, i64::from(STEPS_PER_TURN) - 1) as i16)
}

/// The goal that stops servo `index` (the gripper, or one joint on its own) at the servos' full
/// deceleration, where it comes to rest ([`moving_now`]); `None` if it holds no torque.
pub fn stop_one(cx: &Context<'_>, index: usize) -> Option<Goal> {
    if !cx.bank.holds_torque(index) {
        return None;
    }
    let m = moving_now(cx, index)?;
    let config = cx.settings.config();
    let a = i64::from(config.motion.servo_accel_steps_per_s2.max(1));
    let v = m.millisteps_per_s / 1000;
    let brake_us = v.abs() * 1_000_000 / a;
    Some(Goal {
        position: rest_steps(&m, brake_us),
        speed_steps_per_s: v
            .unsigned_abs()
            .clamp(SETTLE_SPEED_STEPS_PER_S, u64::from(u16::MAX)) as u16,
        accel: config.servo_accel_register(),
    })
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::bank::test_support::{bank_read, miss, powered, read, state};

    #[test]
    fn every_joint_brakes_in_proportion_to_its_speed_so_all_stop_together() {
        let settings = powered();
        let config = settings.config();
        let mut bank = bank_read(&settings, 0, [2_048; JOINTS], [2_000, 1_000, -500, 0, 0, 0]);
        let cx = Context::new(0, &mut bank, &settings);
        let stop = Braking::of(&cx);
        let a = i64::from(config.motion.servo_accel_steps_per_s2);
        let brake_us = 2_000 * 1_000_000 / a;
        assert_eq!(stop.duration_us, GOAL_LATENCY_US + brake_us as u64);
        let goal = |j: usize| stop.goals.get(j).unwrap();
        // The fastest joint at full deceleration, the others at their share of it.
        assert_eq!(i64::from(goal(0).accel), (a + 99) / 100);
        assert_eq!(i64::from(goal(1).accel), (a / 2 + 99) / 100);
        assert_eq!(i64::from(goal(2).accel), (a / 4 + 99) / 100);
        // Each comes to rest where its speed carries it: latency plus half the braking time.
        for (j, v) in [(0, 2_000), (1, 1_000), (2, -500)] {
            let travel = v * (GOAL_LATENCY_US as i64 + brake_us / 2) / 1_000;
            let rest = (2_048_000 + travel + 500).div_euclid(1_000);
            assert_eq!(i64::from(goal(j).position.0), rest, "joint {}", j + 1);
            assert_eq!(stop.rest[j], settings.angle(j, Steps(rest as i16)));
        }
        assert_eq!(goal(3).position, Steps(2_048), "a joint at rest stays");
        assert_eq!(goal(3).speed_steps_per_s, 50, "and settles at once");
    }

    #[test]
    fn a_lone_servo_stops_at_full_deceleration() {
        let settings = powered();
        let mut bank = bank_read(&settings, 0, [2_048; JOINTS], [0, 0, 0, 0, 1_140, 0]);
        let cx = Context::new(0, &mut bank, &settings);
        let g = stop_one(&cx, 4).unwrap();
        assert_eq!(g.accel, settings.config().servo_accel_register());
        assert_eq!(g.speed_steps_per_s, 1_140);
        assert!(g.position.0 > 2_048 + 50, "{g:?}");
    }

    #[test]
    fn a_joint_whose_reads_are_late_brakes_from_where_it_was_told_to_be() {
        let settings = powered();
        let mut bank = bank_read(&settings, 0, [2_048; JOINTS], [0; JOINTS]);
        // Joint 1 told to 3000 at 1000 steps/s, speeding up at 2000 steps/s^2.
        let goal = Goal {
            position: Steps(3_000),
            speed_steps_per_s: 1_000,
            accel: 20,
        };
        bank.send_goals(0, &settings, Goals::one(0, goal)).unwrap();
        assert!(bank.take_goal_write(0, &settings).is_some());
        // Read once at 100 ms (10 steps on, at 200 steps/s), then its reads are lost.
        read(
            &mut bank,
            &settings,
            100_000,
            0,
            state(1, 2_058, 200, 3_000),
        );
        miss(&mut bank, &settings, 200_000, 0, 3);
        let cx = Context::new(300_000, &mut bank, &settings);
        let told = cx.bank.commanded(300_000, 0).unwrap();
        assert!(told.millisteps > 2_130_000, "90 steps on by now: {told:?}");
        let stop = Braking::of(&cx);
        let g = stop.goals.get(0).unwrap();
        // Where it rests lies ahead of where it was told to be, by what it covers braking from
        // 600 steps/s: never behind it (the old reading carried on at its old speed said
        // 2098, and the joint would have turned back).
        assert!(
            i64::from(g.position.0) * 1000 > told.millisteps + 15_000,
            "{g:?} behind {told:?}"
        );
        assert!(g.speed_steps_per_s >= 590, "{g:?}");
        // A lone servo's stop the same (the gripper, joint brake 0x55).
        let one = stop_one(&cx, 0).unwrap();
        assert!(
            i64::from(one.position.0) * 1000 > told.millisteps,
            "{one:?}"
        );
    }
}
