//! Telling a stream of targets from separate moves, and learning the stream's period.

/// Longest gap between two targets of one stream, microseconds: 160 ms, a 10 Hz stream
/// arriving late by more than half a period. A target after a longer gap is a new move.
pub const STREAM_GAP_MAX_US: u64 = 160_000;

/// A stream is over when no target came for twice its period and this much more, microseconds.
const STREAM_END_SLACK_US: u64 = 10_000;

/// When the targets of a stream arrive.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct StreamClock {
    last_us: Option<u64>,
    period_us: u64,
}

impl StreamClock {
    /// Notes a target arriving at `now_us`; returns the stream's period in microseconds if it
    /// continues a stream (it came within [`STREAM_GAP_MAX_US`] of the previous one).
    pub fn arrival(&mut self, now_us: u64) -> Option<u64> {
        let gap = self.last_us.map(|t| now_us.saturating_sub(t));
        self.last_us = Some(now_us);
        match gap {
            Some(gap) if gap <= STREAM_GAP_MAX_US => {
                // A quarter of each new gap: steady against jitter, follows a rate change
                // within a few targets.
                self.period_us = if self.period_us == 0 {
                    gap
                } else {
                    (3 * self.period_us + gap) / 4
                };
                Some(self.period_us.max(1))
            }
            _ => {
                self.period_us = 0;
                None
            }
        }
    }

    /// Forgets the stream: the next target starts anew.
    pub fn reset(&mut self) {
        *self = Self::default();
    }
}

/// True once a stream with period `period_us` whose last target came at `last_us` is over.
pub fn stream_ended(now_us: u64, last_us: u64, period_us: u64) -> bool {
    now_us > last_us + 2 * period_us + STREAM_END_SLACK_US
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_steady_rate_is_a_stream_and_a_pause_starts_anew() {
        let mut c = StreamClock::default();
        assert_eq!(c.arrival(0), None);
        assert_eq!(c.arrival(20_000), Some(20_000));
        assert_eq!(c.arrival(44_000), Some(21_000));
        assert_eq!(c.arrival(44_000 + STREAM_GAP_MAX_US + 1), None);
        assert_eq!(c.arrival(300_000), Some(300_000 - 204_001));
        assert!(!stream_ended(40_000, 0, 20_000));
        assert!(stream_ended(60_000, 0, 20_000));
    }
}
