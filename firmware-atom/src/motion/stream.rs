//! Telling a stream of targets from separate moves, learning the stream's own clock, and
//! playing its targets back on that clock.
//!
//! A host on a busy machine does not send like a metronome: a target comes late, a few are
//! missing, or several are held up and arrive back to back. Each target was still meant for a
//! beat of a regular clock (the host's timer), so the Atom learns that clock from the arrivals
//! ([`StreamClock::arrival`]):
//!
//! * each target gets its **beat**: the one after the newest target's nearest its arrival
//!   time, unless its own value clearly says another (the stream's motion, continued from the
//!   two newest targets, puts it a beat or more further on, or a beat earlier: missing
//!   targets, or one held up). So a target a period late is not taken for a missing one, nor
//!   the first of a burst for the newest;
//! * the **phase** (when the newest beat was due) and the **period** follow the targets that
//!   come on time for their beat, each moving them by its lateness times a gain: at first
//!   those of a least-squares line through the arrivals so far, then [`GAIN_MIN`] (a 32nd for
//!   the phase, a 4096th for the period). A target 10 ms late moves the phase by 0.3 ms, a
//!   missing one not at all; the phase wanders by 0.45 ms (RMS) when targets are late by
//!   0..10 ms at random;
//! * a target that comes back to back with the previous one, long before its beat could be due
//!   (held up in a burst its value cannot tell: the arm at rest), starts its beat from now;
//!   [`RESYNC`] in a row much earlier than their beats at a steady pace (the stream got
//!   faster), or as many much later than their value's beat (a first period guessed from one
//!   late gap), set the clock anew.
//!
//! Each target is then to be passed one period (and [`SLACK_US`]) after its beat was due, not
//! one period after it happened to arrive: the joints pass the targets on the stream's own,
//! steady clock, and head for each one at the beat before it ([`StreamClock::aim`]).
//! When a beat's target has not arrived by then (it is late, or missing) they head for where
//! the stream's own motion puts it: the parabola through the three kept targets nearest it
//! ([`CURVE_POINTS`]), continued past the newest for at most [`BRIDGE_US`]; between two that
//! arrived, the same parabola fills the gap. A late target that then arrives corrects the aim.
//!
//! That is right for a host that sends late what it meant for a beat, and wrong for one that
//! samples its motion when it gets to send (a loop calling `send_angles`): a target 10 ms late
//! is then 10 ms of motion further on, and read as a beat's it throws the joints off the path
//! (and its value made the clock count beats that never were). Which of the two a stream does
//! is judged from its values ([`super::timing`]); a stream sampled when sent has no beats: its
//! period follows the mean gap over the last [`GAP_WINDOW`] arrivals ([`ARRIVAL_PERIOD_FADE`]),
//! and each target is passed one period (and [`SLACK_US`]) after its own arrival, bridged past
//! the newest at the stream's speed for one period ([`StreamClock::aim`]).
//!
//! The stream is only over when no target can continue it any more ([`STREAM_GAP_MAX_US`]).

use super::timing::{Stamped, Timing, TimingJudge};
use crate::config::JOINTS;

/// Longest gap between two targets of one stream, microseconds: 160 ms, a 10 Hz stream
/// arriving late by more than half a period. A target after a longer gap is a new move.
pub const STREAM_GAP_MAX_US: u64 = 160_000;

/// The least of the gains the clock learns with ([`StreamClock::arrival`]): a target's
/// lateness against its beat moves the phase by a 32nd of it and the period by a 4096th. The
/// first targets of a stream move them by more (a least-squares fit of the arrivals so far),
/// down to these. With arrivals late by 0..10 ms at random the phase then wanders by 0.45 ms
/// (RMS), 0.9 ms at 0..20 ms (the estimator alone, 3 000 beats); a mean of the last 8 gaps,
/// as before, moved each target's time by its whole lateness.
pub const GAIN_MIN: ((i64, i64), (i64, i64)) = ((1, 32), (1, 4_096));

/// How many targets in a row that do not fit the clock (each more than three quarters of a
/// period late for the beat its value says, or as much early), a steady gap apart, set it
/// anew: 3.
const RESYNC: u32 = 3;

/// Fixed point of the clock's times: 1/256 of a microsecond.
const Q: i64 = 256;

/// Longest the joints follow the stream's own motion past its newest target's time when no
/// newer target comes (bridged, [`StreamClock::aim`]), microseconds: 40 ms, a missing target
/// or two at 50 Hz. Then they run on to their goals just past the bridge and wait there. A
/// stream that stops for good therefore carries the joints on by this much of its motion
/// (and the servos' braking distance) before they come back to its last target.
pub const BRIDGE_US: u64 = 40_000;

/// Shortest period a stream can have, microseconds: 4 ms (a send_angles frame takes 1.6 ms on
/// the host's line at 115 200 baud). Targets closer together were held up and came in a burst.
const PERIOD_MIN_US: u64 = 4_000;

/// How early against its beat a target must come to be taken for one held up in a burst (or
/// the start of a faster rate), and how late for one held up before it was sent: three
/// quarters of a period. A target up to a period late at random (which puts it up to half a
/// period early or late against the mean) is neither; its lateness teaches the clock up to
/// this much.
const EARLY: (i64, i64) = (3, 4);

/// Least motion per beat, summed over the joints (thousandths of a step), for a target's value
/// to tell which beat it belongs to: 2 steps. A slower stream's beats look alike.
const MOTION_MIN_MILLISTEPS: i64 = 2_000;

/// Most beats a target's value is compared with: 8 (160 ms at 50 Hz).
const BEATS_MAX: i64 = 8;

/// How many recent targets are kept: the three the curve goes through ([`CURVE_POINTS`]), and
/// one more for a gap between them.
const KEPT: usize = 4;

/// Where a target arriving now falls on the stream's clock.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct Beat {
    /// Its beat, counted from the stream's first target.
    pub beat: u32,
    /// The stream's period, microseconds.
    pub period_us: u64,
}

/// What the joints head for next: a beat's target and when to be there.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct Aim {
    /// The beat.
    pub beat: u32,
    /// When to pass its target (monotonic microseconds).
    pub reach_us: u64,
    /// The target, thousandths of a step: arrived, or bridged.
    pub at: [i64; JOINTS],
}

/// Targets in a row that do not fit the clock.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
struct Misfits {
    count: u32,
    gaps_us: u64,
    beats: u64,
}

impl Misfits {
    /// Counts one more, `gap_us` after the previous target and `beats` on: the period they
    /// make together once there are [`RESYNC`] of them.
    fn add(&mut self, gap_us: u64, beats: i64) -> Option<u64> {
        if gap_us < PERIOD_MIN_US {
            return None;
        }
        self.count += 1;
        self.gaps_us += gap_us;
        self.beats += beats.max(1) as u64;
        if self.count < RESYNC {
            return None;
        }
        let period = self.gaps_us / self.beats.max(1);
        *self = Self::default();
        Some(period.max(PERIOD_MIN_US))
    }
}

/// How many gaps between targets the period of a stream played after its arrivals is the mean
/// of: 8, 160 ms of a 50 Hz stream. One target sampled 10 ms late moves it by 1.25 ms.
const GAP_WINDOW: usize = 8;

/// How slowly the period of a stream played after its arrivals follows its mean gap: an
/// eighth of the difference per target. Each target is passed a period after it arrived, so
/// a period that moved with every gap (0..20 ms of late sampling moves the mean of 8 by up to
/// 2.5 ms) would move the joints' timing with it: a 2 deg spike on the bench.
const ARRIVAL_PERIOD_FADE: i64 = 8;

/// The latest arrivals of a stream, for its mean gap.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
struct Gaps {
    /// Arrival times, oldest first; `len` of them are set.
    arrivals: [u64; GAP_WINDOW + 1],
    len: usize,
}

impl Gaps {
    /// Keeps `now_us` as the newest arrival; returns the mean gap over the window so far
    /// (`None` before two arrivals).
    fn push(&mut self, now_us: u64) -> Option<u64> {
        if self.len == self.arrivals.len() {
            self.arrivals.rotate_left(1);
            self.len -= 1;
        }
        if let Some(slot) = self.arrivals.get_mut(self.len) {
            *slot = now_us;
            self.len += 1;
        }
        let first = *self.arrivals.first()?;
        let gaps = self.len.checked_sub(1).filter(|&g| g > 0)? as u64;
        Some(now_us.saturating_sub(first) / gaps)
    }
}

/// When the targets of a stream are due, and the latest of them. See the [module doc](self).
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct StreamClock {
    /// The newest targets, by beat, oldest first; `kept` are set.
    samples: [Stamped; KEPT],
    kept: usize,
    /// When the last target arrived; `None` before the first.
    last_us: Option<u64>,
    /// The newest target's beat.
    beat: u32,
    /// When it was due, and the period, 1/[`Q`] microseconds.
    due_q: i64,
    period_q: i64,
    /// How many on-time targets the clock has learned from since it started: its gains.
    learned: i64,
    /// Targets in a row that came too early for their beat (a faster stream), and too late
    /// for the beat their value says (a clock gone wrong).
    early: Misfits,
    late: Misfits,
    /// Which times the targets belong to.
    judge: TimingJudge,
    /// The latest arrivals: the period of a stream played after its arrivals.
    gaps: Gaps,
}

impl StreamClock {
    /// Notes a target `at` (thousandths of a step) arriving at `now_us`; returns its beat if
    /// it continues a stream (it came within [`STREAM_GAP_MAX_US`] of the previous one).
    ///
    /// Its beat is the one after the newest target's nearest to its arrival, unless its value
    /// clearly says another (`beat_by_value`). A target within three quarters of a period of
    /// that beat's time teaches the clock: the phase and the period move by its lateness times
    /// the gains (least squares over the targets so far, down to [`GAIN_MIN`]). One later
    /// than that (its value says it was held up) teaches nothing; one back to back with the
    /// previous and much earlier (a burst) starts its beat from now. [`RESYNC`] much earlier
    /// at a steady pace, or much later, in a row set the clock anew.
    pub fn arrival(&mut self, now_us: u64, at: [i64; JOINTS]) -> Option<Beat> {
        let now = now_us.min(i64::MAX as u64 / Q as u64) as i64 * Q;
        let Some(last_us) = self
            .last_us
            .filter(|&last| now_us.saturating_sub(last) <= STREAM_GAP_MAX_US)
        else {
            self.reset();
            self.last_us = Some(now_us);
            self.due_q = now;
            self.keep(at);
            return None;
        };
        let gap = now_us.saturating_sub(last_us);
        self.last_us = Some(now_us);
        let mean_gap = self.gaps.push(now_us).unwrap_or(gap);
        if self.learned > 0 && self.judge.timing() == Timing::Arrivals {
            // Sampled when sent: its value says nothing of a beat, and its arrival is its
            // time. The clock's period is the mean gap, its phase this arrival (a stream that
            // goes back to its beats starts from there), its beat the nearest by the gap.
            let mean = mean_gap.clamp(PERIOD_MIN_US, STREAM_GAP_MAX_US) as i64 * Q;
            self.period_q += (mean - self.period_q) / ARRIVAL_PERIOD_FADE;
            let period = self.period_us();
            let step = ((gap + period / 2) / period).clamp(1, BEATS_MAX as u64);
            self.beat = self.beat.saturating_add(step as u32);
            self.due_q = now;
            self.keep(at);
            return Some(self.current());
        }
        if self.learned == 0 {
            // The second target: the first period is its gap.
            self.restart(now, gap);
            self.beat = 1;
            self.keep(at);
            return Some(self.current());
        }
        let period = self.period_q.max(1);
        let since = now - self.due_q;
        // The beat it came on by its time: the nearest one after the newest target's.
        let by_time = (since + period / 2).div_euclid(period).clamp(1, BEATS_MAX);
        let step = self.beat_by_value(&at, by_time).unwrap_or(by_time);
        let due = self.due_q + step * period;
        let late = now - due;
        self.beat = self.beat.saturating_add(step as u32);
        if late < -period * EARLY.0 / EARLY.1 && gap < PERIOD_MIN_US {
            // Back to back with the previous one, long before its beat could be due: held up
            // behind others (a burst the values cannot tell, the arm at rest). Its beat starts
            // from now.
            self.due_q = now;
            self.late = Misfits::default();
        } else if late > period * EARLY.0 / EARLY.1 {
            // Its own value says it is an older beat's, held up: the clock goes on by it
            // (its beat was due in the past) but learns nothing from its time.
            self.due_q = due;
            self.early = Misfits::default();
            if let Some(p) = self.late.add(gap, step) {
                self.restart(now, p);
            }
        } else {
            if late < -period * EARLY.0 / EARLY.1 {
                // Early at a steady pace: taught with its lateness clamped, and counted (the
                // stream may have got faster).
                if let Some(p) = self.early.add(gap, step) {
                    self.restart(now, p);
                    self.keep(at);
                    return Some(self.current());
                }
            } else {
                self.early = Misfits::default();
            }
            self.late = Misfits::default();
            self.learned = (self.learned + 1).min(1 << 16);
            let ((an, ad), (bn, bd)) = gains(self.learned);
            let bound = period * EARLY.0 / EARLY.1;
            let late = late.clamp(-bound, bound);
            self.due_q = due + late * an / ad;
            self.period_q = (period + late * bn / bd / step).max(PERIOD_MIN_US as i64 * Q);
        }
        self.keep(at);
        Some(self.current())
    }

    /// Starts the clock anew with its newest beat due `now` (1/[`Q`] us) and `period_us`.
    fn restart(&mut self, now: i64, period_us: u64) {
        self.due_q = now;
        self.period_q = period_us.clamp(PERIOD_MIN_US, STREAM_GAP_MAX_US) as i64 * Q;
        self.learned = 2;
        self.early = Misfits::default();
        self.late = Misfits::default();
    }

    /// How many beats on from the newest target `at` belongs, by its value: the target the
    /// stream's motion (the line through the two newest targets) puts nearest it, among the
    /// beats from the next one to the one after `by_time` (the beat its arrival time says).
    /// `None` when the stream barely moves (its beats look alike: the time decides) or the
    /// value does not clearly say otherwise than the time.
    fn beat_by_value(&self, at: &[i64; JOINTS], by_time: i64) -> Option<i64> {
        let kept = self.samples.get(..self.kept)?;
        let newest = kept.last()?;
        let before = kept.iter().rev().nth(1)?;
        let span = i64::from(newest.beat.checked_sub(before.beat)?).max(1);
        // The stream's motion per beat, and how far `at` is from where it puts beat `k`.
        let per_beat: [i64; JOINTS] = core::array::from_fn(|j| {
            let (n, b) = (
                newest.at.get(j).copied().unwrap_or(0),
                before.at.get(j).copied().unwrap_or(0),
            );
            (n - b) / span
        });
        let motion: i64 = per_beat.iter().map(|d| d.abs()).sum();
        if motion < MOTION_MIN_MILLISTEPS {
            return None;
        }
        let off = |k: i64| -> i64 {
            (0..JOINTS)
                .map(|j| {
                    let n = newest.at.get(j).copied().unwrap_or(0);
                    let d = per_beat.get(j).copied().unwrap_or(0);
                    (at.get(j).copied().unwrap_or(0) - n - d * k).abs()
                })
                .sum()
        };
        let last = (by_time + 1).min(BEATS_MAX);
        let best = (1..=last).min_by_key(|&k| off(k))?;
        (off(best) + motion / 2 < off(by_time)).then_some(best)
    }

    fn current(&self) -> Beat {
        Beat {
            beat: self.beat,
            period_us: self.period_us(),
        }
    }

    /// Keeps the newest target, for bridging, and weighs the one before it for its timing.
    fn keep(&mut self, at: [i64; JOINTS]) {
        if self.kept == self.samples.len() {
            self.samples.rotate_left(1);
            self.kept -= 1;
        }
        if let Some(slot) = self.samples.get_mut(self.kept) {
            *slot = Stamped {
                beat: self.beat,
                arrived_us: self.last_us.unwrap_or(0),
                at,
            };
            self.kept += 1;
        }
        if let Some([before, middle, after]) = self
            .kept
            .checked_sub(3)
            .and_then(|first| self.samples.get(first..self.kept))
            .and_then(|three| <&[Stamped; 3]>::try_from(three).ok())
        {
            self.judge.weigh(before, middle, after);
        }
    }

    /// The stream's period, microseconds.
    pub fn period_us(&self) -> u64 {
        (self.period_q / Q).max(1) as u64
    }

    /// What to head for from `now_us`: the first beat whose target is to be passed `lead_us`
    /// or more from now, and that target as it arrived; between two that arrived (one
    /// missing), on the curve through them ([`through`]); past the newest, on the same curve
    /// continued (bridged), but never more than [`BRIDGE_US`] past the newest target's time
    /// (or past its arrival, for one held up): then the point of the curve at that time, and
    /// no further. `None` before a target arrived, and once the bridge is over.
    ///
    /// A stream whose targets were sampled when sent ([`Timing::Arrivals`]) is played on
    /// their arrivals instead ([`aim_by_arrivals`](Self::aim_by_arrivals)).
    pub fn aim(&self, now_us: u64, lead_us: u64) -> Option<Aim> {
        let kept = self.samples.get(..self.kept).unwrap_or(&[]);
        if self.judge.timing() == Timing::Arrivals {
            return self.aim_by_arrivals(kept, now_us, lead_us);
        }
        let (oldest, newest) = (kept.first()?, kept.last()?);
        let period = self.period_q.max(1);
        let q = |t: u64| t.min(i64::MAX as u64 / Q as u64) as i64 * Q;
        let due = self.due_q + SLACK_US * Q;
        // reach(b) = due + (b - newest + 1) * period: the first beat passed at `t` or after.
        let wanted = q(now_us.saturating_add(lead_us));
        let beat = (i64::from(newest.beat) + (wanted - due + period - 1).div_euclid(period) - 1)
            .max(i64::from(oldest.beat));
        let reach = due + (beat - i64::from(newest.beat) + 1) * period;
        let last_us = self.last_us.unwrap_or(now_us);
        let limit = (due + period).max(q(last_us.saturating_add(lead_us))) + q(BRIDGE_US);
        if limit < wanted {
            // The bridge is over: the joints keep what they head for.
            return None;
        }
        let (beat, reach) = if reach <= limit {
            (beat * SCALE, reach)
        } else {
            // Bridged as far as it goes: the curve's point at the limit, part of a beat on.
            let newest = i64::from(newest.beat) * SCALE;
            (newest + (limit - due - period) * SCALE / period, limit)
        };
        Some(Aim {
            beat: beat.div_euclid(SCALE).clamp(0, i64::from(u32::MAX)) as u32,
            reach_us: (reach / Q).max(0) as u64,
            at: through(kept, beat),
        })
    }

    /// What to head for from `now_us` in a stream played on its arrivals: the first kept
    /// target to be passed `lead_us` or more from now, each one period (and [`SLACK_US`]) after
    /// it arrived, so the joints take as long from one target to the next as the targets took
    /// to come (a target sampled 10 ms late is 10 ms further on, and passed 10 ms later).
    /// Past the newest, on at the stream's speed for one period (a missing target; a host that
    /// samples late stalls for longer, and the joints would run on past its path): `None` once
    /// that is over.
    fn aim_by_arrivals(&self, kept: &[Stamped], now_us: u64, lead_us: u64) -> Option<Aim> {
        let newest = kept.last()?;
        let period = self.period_us();
        let reach = |s: &Stamped| s.arrived_us.saturating_add(period + SLACK_US as u64);
        let wanted = now_us.saturating_add(lead_us);
        if let Some(s) = kept.iter().find(|s| reach(s) >= wanted) {
            return Some(Aim {
                beat: s.beat,
                reach_us: reach(s),
                at: s.at,
            });
        }
        let newest_reach = reach(newest);
        // One period: the bridge of a stream played on its beats (40 ms) took a loaded
        // client's stalls up to 2.7 deg past its path (90th percentile 0.20 deg against 0.12).
        let limit = newest_reach.saturating_add(period);
        if limit < wanted {
            // The bridge is over: the joints keep what they head for.
            return None;
        }
        let reach_us = wanted.max(newest_reach.saturating_add(period)).min(limit);
        let on = reach_us.saturating_sub(newest_reach).min(period) as i64;
        // The stream's speed: over half a period at the least (two targets sent back to back
        // say little of it), or over all that is kept.
        let base = kept
            .iter()
            .rev()
            .skip(1)
            .find(|b| newest.arrived_us.saturating_sub(b.arrived_us) >= period / 2)
            .or_else(|| kept.first().filter(|b| b.arrived_us < newest.arrived_us));
        let at = match base {
            Some(base) => {
                let span = newest.arrived_us.saturating_sub(base.arrived_us).max(1) as i64;
                core::array::from_fn(|j| {
                    let (n, b) = (
                        newest.at.get(j).copied().unwrap_or(0),
                        base.at.get(j).copied().unwrap_or(0),
                    );
                    n + (n - b).saturating_mul(on) / span
                })
            }
            None => newest.at,
        };
        Some(Aim {
            beat: newest.beat.saturating_add(1),
            reach_us,
            at,
        })
    }

    /// Forgets the stream: the next target starts anew.
    pub fn reset(&mut self) {
        *self = Self::default();
    }
}

/// Where the stream's targets put beat `beat` / [`SCALE`] (a beat may be reached part of the
/// way): its own target if it arrived, otherwise the curve through the [`CURVE_POINTS`] kept
/// targets nearest it (the newer on a tie): between targets that arrived, it fills the gap;
/// past the newest, it goes on along the stream's own motion. `kept` is in beat order.
fn through(kept: &[Stamped], beat: i64) -> [i64; JOINTS] {
    let x = beat;
    if let Some(s) = kept.iter().find(|s| i64::from(s.beat) * SCALE == x) {
        return s.at;
    }
    let mut near: [Option<Stamped>; CURVE_POINTS] = [None; CURVE_POINTS];
    for s in kept.iter().rev() {
        let d = (i64::from(s.beat) * SCALE - x).abs();
        // Insert `s` where it belongs by distance; the farthest falls off.
        let mut carry = Some(*s);
        for slot in near.iter_mut() {
            let Some(c) = carry else { break };
            match slot {
                Some(o) if (i64::from(o.beat) * SCALE - x).abs() <= d => {}
                _ => carry = slot.replace(c),
            }
        }
    }
    let points = near.iter().flatten();
    core::array::from_fn(|j| {
        // Lagrange: the sum of each point's value times its basis polynomial at `x`.
        let mut sum = 0i64;
        for p in points.clone() {
            let (mut num, mut den) = (1i64, 1i64);
            for o in points.clone().filter(|o| o.beat != p.beat) {
                num = num.saturating_mul(x - i64::from(o.beat) * SCALE);
                den = den.saturating_mul((i64::from(p.beat) - i64::from(o.beat)) * SCALE);
            }
            if den != 0 {
                sum += p.at.get(j).copied().unwrap_or(0).saturating_mul(num) / den;
            }
        }
        sum
    })
}

/// How much later than one period after its beat (or its arrival) each target is to be
/// passed, microseconds: 1.5 ms, so that a target on time arrives before the joints head for
/// it (its arrival varies by a few hundred microseconds with the bus). On the bench 1.5 ms
/// gave the least residual of 1, 1.5 and 2 ms (50 Hz: 0.037, 0.030, 0.037 deg RMS).
const SLACK_US: i64 = 1_500;

/// Fixed point of a part of a beat: 1/1024.
const SCALE: i64 = 1024;

/// How many kept targets the curve through them ([`through`]) has: 3, a parabola. A missing
/// target between two that arrived is then off the stream's own curve by its third derivative
/// (0.006 deg for the benchmark's sine at 50 Hz) instead of half its curvature (0.06 deg).
const CURVE_POINTS: usize = 3;

/// The clock's gains after learning from `n` targets: those of a least-squares line through
/// them (phase `2(2n-1)/(n(n+1))`, period `6/(n(n+1))`), down to [`GAIN_MIN`].
fn gains(n: i64) -> ((i64, i64), (i64, i64)) {
    let n = n.max(2);
    let ((an, ad), (bn, bd)) = GAIN_MIN;
    let fit = n * (n + 1);
    let phase = if 2 * (2 * n - 1) * ad > an * fit {
        (2 * (2 * n - 1), fit)
    } else {
        (an, ad)
    };
    let period = if 6 * bd > bn * fit {
        (6, fit)
    } else {
        (bn, bd)
    };
    (phase, period)
}

/// True once a stream whose last target came at `last_us` is over: no target came for
/// [`STREAM_GAP_MAX_US`], so none can continue it. A target late by a few periods (a busy
/// host) is still followed; until it comes the joints go on to their goals just beyond the
/// last target.
pub fn stream_ended(now_us: u64, last_us: u64) -> bool {
    now_us > last_us + STREAM_GAP_MAX_US
}

#[cfg(test)]
mod tests {
    use super::*;

    const T: u64 = 20_000;

    /// Joint 1 at `per_beat` thousandths of a step a beat, on a curve (`bend` more each beat):
    /// beat `k`'s target.
    fn target(k: u64, per_beat: i64, bend: i64) -> [i64; JOINTS] {
        let k = k as i64;
        let mut at = [2_048_000; JOINTS];
        at[0] += per_beat * k + bend * k * k;
        at
    }

    /// A clock fed beats `0..n` of a 50 Hz stream moving 5 steps a beat, on time from `t0`.
    fn steady(n: u64) -> StreamClock {
        let mut c = StreamClock::default();
        for k in 0..n {
            c.arrival(1_000_000 + k * T, target(k, 5_000, 0));
        }
        c
    }

    #[test]
    fn a_steady_rate_is_a_stream_and_a_pause_starts_anew() {
        let mut c = StreamClock::default();
        assert_eq!(c.arrival(0, target(0, 0, 0)), None);
        assert_eq!(
            c.arrival(T, target(1, 0, 0)),
            Some(Beat {
                beat: 1,
                period_us: T
            })
        );
        let far = T + STREAM_GAP_MAX_US + 1;
        assert_eq!(c.arrival(far, target(2, 0, 0)), None, "a new move");
        assert!(!stream_ended(40_000, 0));
        assert!(!stream_ended(STREAM_GAP_MAX_US, 0));
        assert!(stream_ended(STREAM_GAP_MAX_US + 1, 0));
    }

    #[test]
    fn each_target_is_passed_one_period_after_its_beat_was_due() {
        let c = steady(40);
        let last = 1_000_000 + 39 * T;
        let aim = c.aim(last, T / 4).unwrap();
        assert_eq!(aim.beat, 39);
        assert_eq!(aim.reach_us, last + T + SLACK_US as u64);
        assert_eq!(aim.at, target(39, 5_000, 0));
        // Just before the next target is due the joints still head for this one; at its
        // time, for the next beat's.
        assert_eq!(c.aim(last + T - T / 2, T / 4).unwrap().beat, 39);
        assert_eq!(c.aim(aim.reach_us, T / 4).unwrap().beat, 40);
    }

    #[test]
    fn a_late_target_keeps_its_beat_and_hardly_moves_the_clock() {
        let mut c = steady(60);
        let beat = c.arrival(1_000_000 + 60 * T + 10_000, target(60, 5_000, 0));
        assert_eq!(beat.map(|b| b.beat), Some(60));
        assert!(beat.unwrap().period_us.abs_diff(T) < 20, "{beat:?}");
        // The next one on time: its target is passed on the same beat as without the late one.
        c.arrival(1_000_000 + 61 * T, target(61, 5_000, 0));
        let aim = c.aim(1_000_000 + 61 * T, T / 4).unwrap();
        assert!(
            aim.reach_us.abs_diff(1_000_000 + 62 * T + SLACK_US as u64) < 700,
            "{aim:?}"
        );
    }

    #[test]
    fn a_target_a_period_late_is_not_taken_for_a_missing_one() {
        let mut c = steady(60);
        // Beat 60 comes 19 ms late, just before beat 61 comes on time.
        let late = c.arrival(1_000_000 + 60 * T + 19_000, target(60, 5_000, 0));
        let next = c.arrival(1_000_000 + 61 * T + 200, target(61, 5_000, 0));
        assert_eq!((late.unwrap().beat, next.unwrap().beat), (60, 61));
    }

    #[test]
    fn a_target_early_at_a_steady_pace_is_no_burst() {
        let mut c = steady(200);
        // The clock has its beats 16 ms later than they are (a jittery start); beat 200 comes
        // on time, 20 ms after beat 199: early against the clock, but at a steady pace, so a
        // jittery host, not a burst. The phase moves by a 32nd of its lateness (clamped to
        // three quarters of a period), not to its arrival.
        let mut on_time = c;
        c.due_q += 16_000 * Q;
        on_time.arrival(1_000_000 + 200 * T, target(200, 5_000, 0));
        let b = c.arrival(1_000_000 + 200 * T, target(200, 5_000, 0));
        assert_eq!(b.map(|b| b.beat), Some(200));
        let moved_us = (c.due_q - on_time.due_q) / Q;
        assert!((15_000..=15_600).contains(&moved_us), "{moved_us} us");
    }

    #[test]
    fn a_missing_target_is_bridged_along_the_streams_own_curve() {
        let mut c = StreamClock::default();
        for k in 0..40 {
            c.arrival(1_000_000 + k * T, target(k, 5_000, 40));
        }
        // Beat 40 never comes. When the joints head for it, its target is where the curve
        // through the last three goes on to.
        let knot = c.aim(1_000_000 + 39 * T, T / 4).unwrap().reach_us;
        let bridged = c.aim(knot, T / 4).unwrap();
        assert_eq!(bridged.beat, 40);
        assert_eq!(
            bridged.at,
            target(40, 5_000, 40),
            "a parabola is exact here"
        );
        // Beat 41 arrives on time: it is beat 41 (not 40), and the gap is filled on the curve.
        let b = c.arrival(1_000_000 + 41 * T, target(41, 5_000, 40));
        assert_eq!(b.unwrap().beat, 41);
        assert!(
            b.unwrap().period_us.abs_diff(T) < 5,
            "the hole leaves the period"
        );
        let filled = c.aim(knot, T / 4).unwrap();
        assert_eq!(filled.beat, 40);
        assert_eq!(filled.at, target(40, 5_000, 40));
    }

    #[test]
    fn the_bridge_ends_after_its_time_and_a_stopped_stream_goes_no_further() {
        let c = steady(40);
        let newest_reach = c.aim(1_000_000 + 39 * T, T / 4).unwrap().reach_us;
        let end = newest_reach + BRIDGE_US;
        let mut t = newest_reach;
        let mut furthest = 0;
        while let Some(aim) = c.aim(t, T / 4) {
            assert!(aim.reach_us <= end, "{aim:?}");
            furthest = furthest.max(aim.at[0]);
            t = aim.reach_us;
        }
        // Two beats at 50 Hz, as the stream moved.
        assert_eq!(furthest, target(41, 5_000, 0)[0]);
        assert_eq!(c.aim(end, T / 4), None);
    }

    /// A clock fed `n` targets of a 50 Hz stream moving a step a millisecond, each sampled
    /// when it was sent, 0..10 ms late; returns it and the send times.
    fn sampled_late(n: u64) -> (StreamClock, Vec<u64>) {
        let mut c = StreamClock::default();
        let sent: Vec<u64> = (0..n)
            .map(|k| 1_000_000 + k * T + (k.wrapping_mul(0x9E37_79B9_7F4A_7C15) >> 40) % 10_000)
            .collect();
        for &at in &sent {
            c.arrival(at, target(at - 1_000_000, 1, 0));
        }
        (c, sent)
    }

    #[test]
    fn targets_sampled_late_are_passed_one_period_after_their_arrivals() {
        let (c, sent) = sampled_late(40);
        // Their values do not make beats: 40 targets, 39 beats on (the own clock, reading the
        // values as beats, counted 117 for 100).
        assert_eq!(c.samples.last().map(|s| s.beat), Some(39));
        assert!(c.period_us().abs_diff(T) < 1_000, "{}", c.period_us());
        // Each target is passed one period (and the slack) after it arrived, so the joints
        // take as long between two targets as the targets took to come: the stream's speed.
        let newest = *sent.last().unwrap();
        let aim = c.aim(newest, T / 4).unwrap();
        let pass = |s: u64| s + c.period_us() + SLACK_US as u64;
        let first = sent
            .iter()
            .copied()
            .find(|&s| pass(s) >= newest + T / 4)
            .unwrap();
        assert_eq!(aim.reach_us, pass(first));
        assert_eq!(aim.at, target(first - 1_000_000, 1, 0));
    }

    #[test]
    fn a_stream_sampled_late_is_bridged_at_its_own_speed() {
        // The two newest targets came 1 ms apart (one held up behind the other): the bridge
        // still goes on at the stream's speed, a step a millisecond, not at the speed those
        // two alone suggest.
        let (mut c, sent) = sampled_late(30);
        let newest = *sent.last().unwrap();
        c.arrival(newest + 1_000, target(newest + 1_000 - 1_000_000, 1, 0));
        let mut t = newest + 1_000;
        let mut aim = c.aim(t, T / 4).unwrap();
        while aim.beat <= c.samples.last().unwrap().beat {
            t = aim.reach_us;
            aim = c.aim(t, T / 4).unwrap();
        }
        let played = |s: &Stamped| s.arrived_us + c.period_us() + SLACK_US as u64;
        let last = c.samples.last().unwrap();
        let expected = last.at[0] + (aim.reach_us - played(last)) as i64;
        assert!(
            (aim.at[0] - expected).abs() < 2_000,
            "bridged to {} at {}, the stream's speed puts it at {expected}",
            aim.at[0],
            aim.reach_us
        );
    }

    #[test]
    fn targets_held_up_and_sent_in_a_burst_keep_their_beats() {
        let mut c = steady(200);
        // The host stalls for 100 ms: beats 200..=204 go out with beat 205 when it wakes,
        // 1.3 ms apart. Their values say which beats they are, and their lateness teaches the
        // clock nothing, but for beat 205's own (6.5 ms, the end of the burst).
        let wake = 1_000_000 + 205 * T;
        for (i, k) in (200..=205).enumerate() {
            let b = c.arrival(wake + i as u64 * 1_300, target(k, 5_000, 0));
            assert_eq!(b.map(|b| b.beat), Some(k as u32));
            assert!(b.unwrap().period_us.abs_diff(T) < 5, "{b:?}");
        }
        // The next one on time fits the clock as before.
        let b = c.arrival(1_000_000 + 206 * T, target(206, 5_000, 0));
        assert_eq!(b.map(|b| b.beat), Some(206));
        let aim = c.aim(1_000_000 + 206 * T, T / 4).unwrap();
        assert!(
            aim.reach_us.abs_diff(1_000_000 + 207 * T + SLACK_US as u64) < 300,
            "{aim:?}"
        );
    }

    #[test]
    fn the_period_follows_a_change_of_rate() {
        let mut c = StreamClock::default();
        let mut t = 0;
        for k in 0..20 {
            t += 50_000;
            c.arrival(t, target(k, 0, 0));
        }
        let mut period = None;
        for k in 20..30 {
            t += 10_000;
            period = c.arrival(t, target(k, 0, 0)).map(|b| b.period_us);
        }
        assert!(
            period.is_some_and(|p| p.abs_diff(10_000) < 500),
            "{period:?}"
        );
    }

    #[test]
    fn a_first_period_guessed_from_one_late_gap_is_set_right() {
        let mut c = StreamClock::default();
        // The first target came 15 ms late: the first gap is 5 ms.
        c.arrival(1_015_000, target(0, 5_000, 0));
        let mut last = None;
        for k in 1..30 {
            last = c.arrival(1_000_000 + k * T, target(k, 5_000, 0));
        }
        assert_eq!(last.map(|b| b.period_us), Some(T), "{last:?}");
    }
}
