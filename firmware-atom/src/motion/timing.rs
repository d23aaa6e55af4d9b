//! Which times a stream's targets belong to: the beats of a steady clock, or their arrivals.
//!
//! A host that is late to send does one of two things. Either it sends the target it meant
//! for the beat (a ROS node passing on a joint state that was made on time: the target is
//! *delivered late*), or it takes its target when it gets to send (a loop calling
//! `send_angles` with the motion's position now: the target is *sampled late*). A follower
//! that plays every target on the stream's steady clock undoes the first and is thrown off the
//! path by the second; one that plays each target one period after its arrival is the other
//! way round. The values tell which a stream does: each target lies on the straight line
//! through its neighbours when they are spaced by the times they belong to, and off it by
//! its speed times the timing error when spaced otherwise.
//!
//! [`TimingJudge`] compares each target between two others with that line twice, spaced by
//! their beats and by their arrivals, and keeps a fading sum of both distances (about the
//! last [`FADE`] targets). The stream goes on the other timing when that sum is clearly smaller
//! ([`CLEARLY`]); a stream that barely moves keeps the timing it has.

use crate::config::JOINTS;

/// Which times a stream's targets belong to.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub enum Timing {
    /// The beats of the stream's own steady clock, whenever they arrived (delivered late,
    /// missing, or held up in a burst): the first guess, right for a regular stream too.
    #[default]
    Beats,
    /// Their arrivals: the host sampled its motion when it sent.
    Arrivals,
}

/// A stream's target as the judge needs it: its beat, its arrival, its joint positions
/// (thousandths of a step).
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct Stamped {
    /// Its beat on the stream's clock.
    pub beat: u32,
    /// When it arrived, monotonic microseconds.
    pub arrived_us: u64,
    /// The joint positions, thousandths of a step.
    pub at: [i64; JOINTS],
}

/// How many targets the fading sums reach back, about: 8 (160 ms at 50 Hz). Each new distance
/// counts fully and the sum loses an eighth per target.
const FADE: i64 = 8;

/// How much smaller one timing's fading sum must be to take the stream over: half.
/// Targets on time fit both about equally; a stream stays on its timing until the other one
/// clearly fits better.
const CLEARLY: (i64, i64) = (1, 2);

/// Least fading sum, thousandths of a step, for the other timing to take over: 4 steps (a
/// target 2 ms off in a stream moving 1 000 steps/s). Less is rounding and the curve.
const EVIDENCE_MIN: i64 = 4_000;

/// Judges which times a stream's targets belong to. See the [module doc](self).
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct TimingJudge {
    /// Fading sums of the distances off the line, spaced by beats and by arrivals,
    /// thousandths of a step.
    off_beats: i64,
    off_arrivals: i64,
    timing: Timing,
}

impl TimingJudge {
    /// The timing the stream's targets so far fit.
    pub fn timing(&self) -> Timing {
        self.timing
    }

    /// Weighs the middle one of three consecutive targets `(before, middle, after)`, oldest
    /// first; returns the stream's timing.
    pub fn weigh(&mut self, before: &Stamped, middle: &Stamped, after: &Stamped) -> Timing {
        let beats = |s: &Stamped| i64::from(s.beat);
        let arrivals = |s: &Stamped| s.arrived_us.min(i64::MAX as u64) as i64;
        let off_beats = off_line(before, middle, after, beats);
        let off_arrivals = off_line(before, middle, after, arrivals);
        // Targets in a burst arrive together: spaced by arrivals, they have no line.
        let off_arrivals = off_arrivals.unwrap_or(off_beats.unwrap_or(0).saturating_mul(2));
        let Some(off_beats) = off_beats else {
            return self.timing;
        };
        self.off_beats = fade(self.off_beats, off_beats);
        self.off_arrivals = fade(self.off_arrivals, off_arrivals);
        let (ours, theirs) = match self.timing {
            Timing::Beats => (self.off_beats, self.off_arrivals),
            Timing::Arrivals => (self.off_arrivals, self.off_beats),
        };
        if ours >= EVIDENCE_MIN && theirs.saturating_mul(CLEARLY.1) < ours.saturating_mul(CLEARLY.0)
        {
            self.timing = match self.timing {
                Timing::Beats => Timing::Arrivals,
                Timing::Arrivals => Timing::Beats,
            };
        }
        self.timing
    }
}

/// The sum `sum` fades by one [`FADE`]th and takes `add`.
fn fade(sum: i64, add: i64) -> i64 {
    sum.saturating_sub(sum / FADE).saturating_add(add)
}

/// How far `middle` lies off the straight line through `before` and `after` when the three
/// are spaced by `time`, summed over the joints (thousandths of a step); `None` when `before`
/// and `after` have the same time.
fn off_line(
    before: &Stamped,
    middle: &Stamped,
    after: &Stamped,
    time: impl Fn(&Stamped) -> i64,
) -> Option<i64> {
    let (t0, t1, t2) = (time(before), time(middle), time(after));
    let span = t2.checked_sub(t0).filter(|&s| s > 0)?;
    let (w0, w2) = (t2.saturating_sub(t1), t1.saturating_sub(t0));
    // Positions are under 4.1 million thousandths of a step and spans of one stream under a
    // second: the products stay far inside i64 (saturating all the same).
    let off = (0..JOINTS)
        .map(|j| {
            let y = |s: &Stamped| s.at.get(j).copied().unwrap_or(0);
            let line = y(before)
                .saturating_mul(w0)
                .saturating_add(y(after).saturating_mul(w2))
                / span;
            y(middle).saturating_sub(line).saturating_abs()
        })
        .fold(0i64, i64::saturating_add);
    Some(off)
}

#[cfg(test)]
mod tests {
    use super::*;

    const T: u64 = 20_000;

    /// Joint 0 moving 1 000 steps/s (a step a millisecond) at time `t_us`.
    fn moving(t_us: u64) -> [i64; JOINTS] {
        let mut at = [2_048_000; JOINTS];
        at[0] += t_us as i64;
        at
    }

    /// Feeds `n` targets; target `k` is due at `k * T`, arrives `late(k)` after that, and
    /// carries the motion at `value(k, arrival)`.
    fn judge(n: u64, late: impl Fn(u64) -> u64, value: impl Fn(u64, u64) -> u64) -> Timing {
        let mut judge = TimingJudge::default();
        let stamped: Vec<Stamped> = (0..n)
            .map(|k| {
                let arrived_us = k * T + late(k);
                Stamped {
                    beat: k as u32,
                    arrived_us,
                    at: moving(value(k, arrived_us)),
                }
            })
            .collect();
        for w in stamped.windows(3) {
            judge.weigh(&w[0], &w[1], &w[2]);
        }
        judge.timing()
    }

    /// Lateness 0..10 ms, varying from target to target.
    fn jitter(k: u64) -> u64 {
        (k * 7_919) % 10_000
    }

    #[test]
    fn a_regular_stream_stays_on_its_beats() {
        assert_eq!(judge(50, |_| 0, |k, _| k * T), Timing::Beats);
        assert_eq!(judge(50, |_| 300, |_, a| a), Timing::Beats);
    }

    #[test]
    fn targets_delivered_late_belong_to_their_beats() {
        assert_eq!(judge(50, jitter, |k, _| k * T), Timing::Beats);
    }

    #[test]
    fn targets_sampled_late_belong_to_their_arrivals() {
        assert_eq!(judge(50, jitter, |_, arrived| arrived), Timing::Arrivals);
    }

    #[test]
    fn a_stream_that_starts_sampling_late_is_judged_anew() {
        let late = |k| if k < 30 { 0 } else { jitter(k) };
        assert_eq!(judge(60, late, |_, arrived| arrived), Timing::Arrivals);
        // ... and one that goes back to delivering late goes back to its beats.
        let mut judge = TimingJudge::default();
        let stamped: Vec<Stamped> = (0..90u64)
            .map(|k| {
                let arrived_us = k * T + jitter(k);
                let value = if k < 40 { arrived_us } else { k * T };
                Stamped {
                    beat: k as u32,
                    arrived_us,
                    at: moving(value),
                }
            })
            .collect();
        let mut seen = Vec::new();
        for w in stamped.windows(3) {
            seen.push(judge.weigh(&w[0], &w[1], &w[2]));
        }
        assert_eq!(seen.get(37), Some(&Timing::Arrivals));
        assert_eq!(judge.timing(), Timing::Beats);
    }

    #[test]
    fn a_burst_belongs_to_its_beats() {
        // Samples held up 60 ms, then sent 1.3 ms apart.
        let late = |k: u64| match k % 20 {
            10 => 60_000,
            11 => 41_300,
            12 => 22_600,
            _ => 0,
        };
        assert_eq!(judge(60, late, |k, _| k * T), Timing::Beats);
    }

    #[test]
    fn a_stream_at_rest_keeps_its_timing() {
        assert_eq!(judge(50, jitter, |_, _| 0), Timing::Beats);
    }
}
