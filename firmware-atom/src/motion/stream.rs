//! Telling a stream of targets from separate moves, and learning the stream's period.
//!
//! A host on a busy machine does not send like a metronome: a target comes late, a few are
//! missing, or several are held up and arrive back to back. The period is therefore the mean
//! gap over the last [`PERIOD_WINDOW`] targets (a late target or a burst leaves it almost
//! unchanged, where a running average of single gaps jumped), and the stream is only over when
//! no target can continue it any more ([`STREAM_GAP_MAX_US`]): a late target is not its end.

/// Longest gap between two targets of one stream, microseconds: 160 ms, a 10 Hz stream
/// arriving late by more than half a period. A target after a longer gap is a new move.
pub const STREAM_GAP_MAX_US: u64 = 160_000;

/// How many gaps between targets the stream's period is the mean of: 8, 160 ms of a 50 Hz
/// stream. Long enough that one late target moves the period by an eighth of its lateness,
/// short enough that a change of rate is learned within eight targets.
pub const PERIOD_WINDOW: usize = 8;

/// When the targets of a stream arrive.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct StreamClock {
    /// Arrival times of the stream's last targets, oldest first; `len` of them are set.
    arrivals: [u64; PERIOD_WINDOW + 1],
    len: usize,
}

impl StreamClock {
    /// Notes a target arriving at `now_us`; returns the stream's period in microseconds if it
    /// continues a stream (it came within [`STREAM_GAP_MAX_US`] of the previous one): the mean
    /// gap over the last [`PERIOD_WINDOW`] targets.
    pub fn arrival(&mut self, now_us: u64) -> Option<u64> {
        let continues = self
            .len
            .checked_sub(1)
            .and_then(|i| self.arrivals.get(i))
            .is_some_and(|&last| now_us.saturating_sub(last) <= STREAM_GAP_MAX_US);
        if !continues {
            self.reset();
            self.push(now_us);
            return None;
        }
        self.push(now_us);
        let first = self.arrivals.first().copied().unwrap_or(now_us);
        let gaps = (self.len.max(2) - 1) as u64;
        Some((now_us.saturating_sub(first) / gaps).max(1))
    }

    /// Keeps `now_us` as the newest arrival, dropping the oldest when the window is full.
    fn push(&mut self, now_us: u64) {
        if self.len == self.arrivals.len() {
            self.arrivals.rotate_left(1);
            self.len -= 1;
        }
        if let Some(slot) = self.arrivals.get_mut(self.len) {
            *slot = now_us;
            self.len += 1;
        }
    }

    /// Forgets the stream: the next target starts anew.
    pub fn reset(&mut self) {
        *self = Self::default();
    }
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

    #[test]
    fn a_steady_rate_is_a_stream_and_a_pause_starts_anew() {
        let mut c = StreamClock::default();
        assert_eq!(c.arrival(0), None);
        assert_eq!(c.arrival(20_000), Some(20_000));
        assert_eq!(c.arrival(44_000), Some(22_000));
        assert_eq!(c.arrival(44_000 + STREAM_GAP_MAX_US + 1), None);
        assert_eq!(c.arrival(300_000), Some(300_000 - 204_001));
        assert!(!stream_ended(40_000, 0));
        assert!(!stream_ended(STREAM_GAP_MAX_US, 0));
        assert!(stream_ended(STREAM_GAP_MAX_US + 1, 0));
    }

    #[test]
    fn a_late_target_or_a_burst_hardly_moves_the_period() {
        let mut c = StreamClock::default();
        let mut period = None;
        for k in 0..20u64 {
            period = c.arrival(k * 20_000);
        }
        assert_eq!(period, Some(20_000));
        // The next target is 40 ms late, the two held up behind it follow 1.3 ms apart, the
        // one after them is on time: the period is the stream's again.
        assert_eq!(c.arrival(20 * 20_000 + 40_000), Some(25_000));
        assert_eq!(c.arrival(20 * 20_000 + 41_300), Some(22_662));
        assert_eq!(c.arrival(20 * 20_000 + 42_600), Some(20_325));
        assert_eq!(c.arrival(23 * 20_000), Some(20_000));
    }

    #[test]
    fn the_period_follows_a_change_of_rate_within_the_window() {
        let mut c = StreamClock::default();
        let mut t = 0;
        for _ in 0..20 {
            t += 50_000;
            c.arrival(t);
        }
        let mut period = None;
        for _ in 0..PERIOD_WINDOW {
            t += 10_000;
            period = c.arrival(t);
        }
        assert_eq!(period, Some(10_000));
    }
}
