//! Following a sequence of joint targets (a host's stream, or the points of a Cartesian path)
//! without stopping between them.
//!
//! A target comes with the time until it is to be passed (a path's interpolation period, or
//! for a stream the time to the target's beat on the stream's own clock, [`super::stream`]).
//! Each joint gets the goal speed that carries it from where it is now to the target in that
//! time, so it passes the target just as it heads for the next one. Its goal lies beyond the
//! target by the distance the servo needs to brake from that speed (plus a quarter period for a
//! late next leg and a step for rounding), so the servo never starts braking while targets keep
//! coming; the last target of a sequence is the goal itself. A path's legs come one period
//! apart; a stream's come when its targets and beats do ([`Clock`]), and where each joint is
//! then is worked out for that time.

use protocol_core::units::{Centideg, Steps};

use crate::config::{JOINTS, STEPS_PER_TURN};
use crate::context::Context;
use crate::safety::{Goal, Goals};
use crate::settings::Settings;

/// How much of the difference between where a joint was expected to be and where its state
/// read (with its speed) puts it is corrected per target: a quarter. The read is whole steps
/// and a few milliseconds old, so trusting it fully makes the joints jitter by half a step
/// (0.15 mm at the flange); the rest of a real difference is corrected at the next targets.
const CORRECTION: (i64, i64) = (1, 4);

/// Slowest goal speed towards the last target of a sequence, steps per second: the last
/// target is where the joints stop, so each one heads there from where it really is, and a
/// joint a step or two away gets there within a few hundredths of a second instead of crawling
/// there at the speed its last step of the sequence happened to need.
const FINAL_SPEED_MIN_STEPS_PER_S: i64 = 50;

/// How the joints change speed between targets.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Pace {
    /// Each joint at the servos' full acceleration: a stream, where each joint follows its
    /// own targets.
    Free,
    /// All joints over the same time, each at the acceleration its change of speed needs: a
    /// Cartesian path, where a joint that got to its new speed sooner than the others would
    /// pull the end off the path.
    Together,
}

/// When the legs of a sequence come.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Clock {
    /// One period apart (a path's points): where the joints are is where the previous leg
    /// took them.
    Periodic,
    /// At their own times (a stream's, when its targets and its beats come): where the joints
    /// are is worked out for the time the leg is given, and each keeps its speed past the
    /// target for a quarter of the stream's `period_us`, should the next leg be late.
    Timed {
        /// The stream's period, microseconds.
        period_us: u64,
    },
}

/// One target of a sequence and how to get there.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct Leg {
    /// The joint positions to pass, thousandths of a step ([`millisteps`]).
    pub target: [i64; JOINTS],
    /// Time until the target is to be passed, microseconds.
    pub period_us: u64,
    /// When the legs come.
    pub clock: Clock,
    /// No joint faster than this, steps per second.
    pub speed_cap_steps_per_s: u32,
    /// How the joints change speed.
    pub pace: Pace,
    /// The sequence ends here: stop at `target`.
    pub last: bool,
}

/// The previous leg, as given.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
struct Given {
    /// When, monotonic microseconds.
    at_us: u64,
    /// Where each joint was taken to be then, thousandths of a step.
    from: [i64; JOINTS],
    /// Where each joint should be one period later, thousandths of a step.
    expected: [i64; JOINTS],
    /// The speed each joint was given, steps per second (signed), as computed.
    speeds: [i64; JOINTS],
    /// The same as the whole-step speed register it went out as (signed).
    rates: [i64; JOINTS],
    /// Each joint's goal, thousandths of a step.
    goals: [i64; JOINTS],
    /// Each joint's speed before (steps per second, signed) and its acceleration to the
    /// new one (steps per second squared).
    ramps: [(i64, i64); JOINTS],
}

impl Given {
    /// Where joint `j` should be at `now_us`: on at its speed from where it was, no further
    /// than its goal (where the servo stops).
    fn expected_at(&self, now_us: u64, j: usize) -> Option<i64> {
        let (from, rate, goal) = (*self.from.get(j)?, *self.rates.get(j)?, *self.goals.get(j)?);
        let (speed_before, accel) = *self.ramps.get(j)?;
        let elapsed = now_us.saturating_sub(self.at_us).min(1 << 32) as i64;
        let on = from + covered(speed_before, rate, accel, elapsed);
        Some(match rate.signum() {
            1 => on.min(goal.max(from)),
            -1 => on.max(goal.min(from)),
            _ => from,
        })
    }
}

/// How far a servo goes in `elapsed_us` (thousandths of a step) once told `speed` (steps per
/// second, signed) while at `speed_before`: it changes speed at `accel` (steps per second
/// squared), so a joint speeding up covers less than the new speed alone would take it (at a
/// 50 Hz sine's turn, a fifth of a step a period: the follower's reads then made up for it a
/// quarter at a time, and the joints trailed their targets by up to 0.07 deg).
fn covered(speed_before: i64, speed: i64, accel: i64, elapsed_us: i64) -> i64 {
    let change = speed - speed_before;
    let ramp_us = change.abs().saturating_mul(1_000_000) / accel.max(1);
    if elapsed_us >= ramp_us {
        (speed * elapsed_us - change * ramp_us / 2) / 1000
    } else {
        // Still changing speed: at `speed_before`, plus half the acceleration's share.
        (speed_before * elapsed_us + change * elapsed_us / ramp_us.max(1) * elapsed_us / 2) / 1000
    }
}

/// Follows a sequence of targets. See the [module doc](self).
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct Follower {
    last: Option<Given>,
}

/// Joint angles as positions, thousandths of a step.
pub fn millisteps(settings: &Settings, angles: &[Centideg; JOINTS]) -> [i64; JOINTS] {
    let config = settings.config();
    core::array::from_fn(|j| {
        let angle = angles.get(j).copied().unwrap_or_default();
        config.angle_to_millisteps(j, i32::from(angle.0))
    })
}

impl Follower {
    /// The goals that carry the joints to `leg`'s target in its period and on (see the
    /// [module doc](self)), from where the joints are at the step's time.
    pub fn goals_towards(&mut self, cx: &Context<'_>, leg: &Leg) -> Goals {
        let (bank, settings) = (&*cx.bank, cx.settings);
        let Leg {
            target,
            period_us,
            clock,
            speed_cap_steps_per_s,
            pace,
            last,
        } = *leg;
        let config = settings.config();
        let full = i64::from(config.motion.servo_accel_steps_per_s2.max(100));
        let period = period_us.max(1) as i64;
        let (timed, late_us) = match clock {
            Clock::Periodic => (false, period),
            Clock::Timed { period_us } => (true, period_us.max(1) as i64),
        };
        let cap = i64::from(speed_cap_steps_per_s.max(1));
        // Every joint that holds torque follows, whether or not its latest reads came back: it
        // still hears the goals, and one left without them would run on to its last goal.
        let driven: [bool; JOINTS] = core::array::from_fn(|j| bank.holds_torque(j));
        let to: [i64; JOINTS] = core::array::from_fn(|j| {
            let exact = target.get(j).copied().unwrap_or_default();
            if last {
                // A servo at rest holds a whole step: head for that one.
                i64::from(goal_position(settings, j, exact).0) * 1000
            } else {
                exact
            }
        });
        // Where each joint is now: where it should be by the previous target, corrected by a
        // recent reading ([`ServoBank::observed`](crate::bank::ServoBank::observed)); the first
        // and the last target start from the reading itself. A joint without a recent reading
        // goes by what it was told: its reads being late must not make its goal.
        let from: [i64; JOINTS] = core::array::from_fn(|j| {
            let measured = bank.observed(cx.now_us, j).map(|m| m.millisteps);
            let told = || bank.motion(cx.now_us, j).map_or(0, |m| m.millisteps);
            let should = |g: &Given| {
                if timed {
                    g.expected_at(cx.now_us, j)
                } else {
                    g.expected.get(j).copied()
                }
            };
            match &self.last {
                Some(g) if !last => {
                    let e = should(g).unwrap_or_else(told);
                    measured.map_or(e, |m| e + (m - e) * CORRECTION.0 / CORRECTION.1)
                }
                Some(g) => measured.or_else(|| should(g)).unwrap_or_else(told),
                None => measured.unwrap_or_else(told),
            }
        });
        let before: [i64; JOINTS] = match &self.last {
            Some(g) => g.speeds,
            None => core::array::from_fn(|j| {
                bank.observed(cx.now_us, j)
                    .or_else(|| bank.motion(cx.now_us, j))
                    .map_or(0, |m| m.millisteps_per_s / 1000)
            }),
        };
        // Thousandths of a step per microsecond = steps per millisecond: times 1000 is steps/s.
        let speeds: [i64; JOINTS] = core::array::from_fn(|j| {
            let (f, t) = (
                from.get(j).copied().unwrap_or(0),
                to.get(j).copied().unwrap_or(0),
            );
            match ((t - f) * 1000 / period).clamp(-cap, cap) {
                v if last && t != f => {
                    (t - f).signum() * v.abs().max(FINAL_SPEED_MIN_STEPS_PER_S.min(cap))
                }
                0 => (t - f).signum(),
                v => v,
            }
        });
        let change = |j: usize| {
            (speeds.get(j).copied().unwrap_or(0) - before.get(j).copied().unwrap_or(0)).abs()
        };
        // The time every joint takes to change its speed: the largest change at full
        // acceleration (at least a millisecond, the servos' control period).
        let largest = (0..JOINTS)
            .filter(|&j| driven.get(j).copied().unwrap_or(false))
            .map(change)
            .max()
            .unwrap_or(0);
        let together_us = (largest * 1_000_000 / full).max(1_000);
        let mut goals = Goals::NONE;
        let mut expected = to;
        let mut rates = [0; JOINTS];
        let mut goal_at = to;
        let mut ramps = [(0, 1); JOINTS];
        for j in 0..JOINTS {
            if !driven.get(j).copied().unwrap_or(false) {
                continue;
            }
            let speed = speeds.get(j).copied().unwrap_or(0);
            let accel_register = match pace {
                Pace::Together => (change(j) * 1_000_000 / together_us)
                    .div_euclid(100)
                    .clamp(1, i64::from(config.servo_accel_register()))
                    as u8,
                _ => config.servo_accel_register(),
            };
            let accel = i64::from(accel_register) * 100;
            // Braking distance, a quarter period for a late target, and one whole step so that
            // rounding the goal to a step never puts it short of the target.
            let beyond = if last || speed == 0 {
                0
            } else {
                speed * speed.abs() * 1000 / (2 * accel)
                    + speed * late_us / 4000
                    + speed.signum() * 1000
            };
            let speed_register = speed.unsigned_abs().max(1) as u16;
            let f = from.get(j).copied().unwrap_or(0);
            let rate = speed.signum() * i64::from(speed_register);
            let speed_before = before.get(j).copied().unwrap_or(0);
            if !last && let Some(e) = expected.get_mut(j) {
                // Where the joint is one period from now at its whole-step speed: rounding the
                // speed never adds up. (A path's legs leave out the ramp to it: with it, arcs
                // at 100 % kept to their circle three times better, but a Cartesian jog and an
                // arc at 50 % went 17 to 19 % further off.)
                *e = f + rate * period / 1000;
            }
            if let Some(r) = ramps.get_mut(j) {
                *r = (speed_before, accel);
            }
            let t = to.get(j).copied().unwrap_or(f);
            let goal = Goal {
                position: goal_position(settings, j, t + beyond),
                speed_steps_per_s: speed_register,
                accel: accel_register,
            };
            if let Some(r) = rates.get_mut(j) {
                *r = rate;
            }
            if let Some(g) = goal_at.get_mut(j) {
                *g = i64::from(goal.position.0) * 1000;
            }
            goals.set(j, Some(goal));
        }
        self.last = Some(Given {
            at_us: cx.now_us,
            from,
            expected,
            speeds,
            rates,
            goals: goal_at,
            ramps,
        });
        goals
    }
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

#[cfg(test)]
mod tests {
    use super::*;
    use crate::bank::test_support::{at_rest, bank_read, miss, powered};

    const PERIOD_US: u64 = 20_000;

    fn leg(target: [Centideg; JOINTS], last: bool) -> Leg {
        Leg {
            target: millisteps(&powered(), &target),
            period_us: PERIOD_US,
            clock: Clock::Periodic,
            speed_cap_steps_per_s: 3_000,
            pace: Pace::Free,
            last,
        }
    }

    #[test]
    fn a_joint_gets_the_speed_to_its_target_and_a_goal_a_braking_distance_beyond() {
        let (settings, mut bank) = at_rest();
        let config = settings.config();
        let cx = Context::new(0, &mut bank, &settings);
        let mut target = [Centideg(0); JOINTS];
        target[0] = settings.angle(0, Steps(2_068));
        let goals = Follower::default().goals_towards(&cx, &leg(target, false));
        let to = config.angle_to_millisteps(0, i32::from(target[0].0));
        let speed = (to - 2_048_000) * 1000 / PERIOD_US as i64;
        let g = goals.get(0).unwrap();
        assert_eq!(i64::from(g.speed_steps_per_s), speed, "there in one period");
        assert_eq!(
            g.accel,
            config.servo_accel_register(),
            "free pace: full acceleration"
        );
        let braking = speed * speed * 1000 / (2 * i64::from(g.accel) * 100);
        assert!(
            i64::from(g.position.0) * 1000 >= to + braking,
            "the goal lies beyond the target by at least the braking distance: {g:?}"
        );
        assert_eq!(
            goals.get(1).unwrap().position,
            Steps(2_048),
            "a joint that stays"
        );
    }

    #[test]
    fn the_next_target_starts_from_where_the_joint_should_be_and_the_last_is_the_goal() {
        let (settings, mut bank) = at_rest();
        let cx = Context::new(0, &mut bank, &settings);
        let mut follower = Follower::default();
        let mut target = [Centideg(0); JOINTS];
        target[0] = settings.angle(0, Steps(2_068));
        let first = follower
            .goals_towards(&cx, &leg(target, false))
            .get(0)
            .unwrap();
        // The read still says 2048 (a few ms old): the follower expects the joint 20 steps on
        // and asks for the next 20 steps, not for 40.
        target[0] = settings.angle(0, Steps(2_088));
        let second = follower
            .goals_towards(&cx, &leg(target, false))
            .get(0)
            .unwrap();
        let diff = i32::from(second.speed_steps_per_s) - i32::from(first.speed_steps_per_s);
        assert!(diff.abs() < 300, "{first:?} then {second:?}");
        let last = follower
            .goals_towards(&cx, &leg(target, true))
            .get(0)
            .unwrap();
        assert_eq!(
            last.position,
            Steps(2_088),
            "the last target is the goal itself"
        );
        assert!(last.speed_steps_per_s >= 50);
    }

    #[test]
    fn a_joint_changing_speed_covers_what_its_ramp_allows() {
        // From rest to 1 140 steps/s (100 deg/s) at 11 400 steps/s^2: 100 ms of ramp.
        assert_eq!(
            covered(0, 1_140, 11_400, 100_000),
            57_000,
            "half way at the ramp's end"
        );
        assert_eq!(covered(0, 1_140, 11_400, 300_000), 57_000 + 228_000);
        assert_eq!(
            covered(0, 1_140, 11_400, 50_000),
            14_250,
            "a quarter of it by half time"
        );
        // A change of 65 steps/s (a 50 Hz sine's turn): a fifth of a step short in a period.
        assert_eq!(covered(1_000, 1_065, 11_400, 20_000) - 1_065 * 20, -186);
        // Slowing down: further than the new speed alone.
        assert!(covered(-1_000, -900, 11_400, 20_000) < -900 * 20);
        assert_eq!(
            covered(500, 500, 11_400, 20_000),
            10_000,
            "no change, no ramp"
        );
    }

    #[test]
    fn a_joint_whose_reads_are_lost_still_follows_from_where_it_should_be() {
        let settings = powered();
        let mut bank = bank_read(&settings, 0, [2_048; JOINTS], [0; JOINTS]);
        let mut follower = Follower::default();
        let mut target = [Centideg(0); JOINTS];
        target[2] = settings.angle(2, Steps(2_068));
        let first = {
            let cx = Context::new(0, &mut bank, &settings);
            follower.goals_towards(&cx, &leg(target, false))
        };
        // Joint 3's next reads are lost (three in a row: it counts as not answering), and the
        // others' reads are too old to say where anything is now.
        miss(&mut bank, &settings, 10_000, 2, 3);
        target[2] = settings.angle(2, Steps(2_088));
        let cx = Context::new(PERIOD_US + 30_000, &mut bank, &settings);
        let goals = follower.goals_towards(&cx, &leg(target, false));
        let (g1, g2) = (first.get(2).unwrap(), goals.get(2).unwrap());
        // It still gets its goal (without one it would run on to the last, a braking distance
        // beyond the last target), at the speed of the path from where it should be: 20 steps
        // a period, as before, not the catching up an old reading would ask for.
        let diff = i32::from(g2.speed_steps_per_s) - i32::from(g1.speed_steps_per_s);
        assert!(diff.abs() < 50, "{g1:?} then {g2:?}");
        assert!(g2.position.0 > 2_088, "{g2:?}");
        // The last target is its goal, whatever its reads.
        let last = follower.goals_towards(&cx, &leg(target, true));
        assert_eq!(last.get(2).unwrap().position, Steps(2_088));
    }
}
