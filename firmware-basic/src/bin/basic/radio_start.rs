//! The radio's start-up as the loop sees it: the driver starts on a thread of its own
//! (`network::start`) while the loop serves USB from boot, and the loop declares it failed if
//! it has not come up by [`RADIO_START_DEADLINE_US`]. Pure logic, tested on the host
//! (`cargo test -p firmware-basic --test board_logic`).

/// How long the radio may take to start, in microseconds. esp-radio's start-up takes well under
/// a second on a chip; a radio that has not come up by then never will (on an emulator whose
/// radio or interrupts are not modelled, it waits forever).
pub const RADIO_START_DEADLINE_US: u64 = 5_000_000;

/// Where the radio's start-up is.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum RadioStart {
    /// Starting on its own thread since `since_us`; USB is served meanwhile.
    Starting {
        /// When it began, microseconds.
        since_us: u64,
    },
    /// Started: Wi-Fi runs.
    Up,
    /// The driver refused to start (an error from esp-radio): USB only.
    Refused,
    /// Not up by the deadline: USB only until the next reset.
    TimedOut,
}

impl RadioStart {
    /// The start-up begins at `now_us`.
    pub const fn begin(now_us: u64) -> Self {
        Self::Starting { since_us: now_us }
    }

    /// The state at `now_us`, given what the start-up thread reported since the last call
    /// (`Some(true)`: up, `Some(false)`: refused). Once decided, it stays: a radio that comes
    /// up after its deadline is not used.
    #[must_use]
    pub fn poll(self, now_us: u64, outcome: Option<bool>) -> Self {
        let Self::Starting { since_us } = self else {
            return self;
        };
        match outcome {
            Some(true) => Self::Up,
            Some(false) => Self::Refused,
            None if now_us.saturating_sub(since_us) >= RADIO_START_DEADLINE_US => Self::TimedOut,
            None => self,
        }
    }

    /// True while the start-up is under way.
    pub fn starting(self) -> bool {
        matches!(self, Self::Starting { .. })
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_radio_that_never_answers_is_declared_failed_at_the_deadline() {
        let start = RadioStart::begin(1_000);
        let just_before = start.poll(1_000 + RADIO_START_DEADLINE_US - 1, None);
        assert!(just_before.starting());
        let at = just_before.poll(1_000 + RADIO_START_DEADLINE_US, None);
        assert_eq!(at, RadioStart::TimedOut);
        // A radio that comes up later is not used.
        assert_eq!(at.poll(u64::MAX, Some(true)), RadioStart::TimedOut);
    }

    #[test]
    fn the_outcome_decides_before_the_deadline() {
        assert_eq!(RadioStart::begin(0).poll(10, Some(true)), RadioStart::Up);
        assert_eq!(
            RadioStart::begin(0).poll(10, Some(false)),
            RadioStart::Refused
        );
        // A clock that goes backwards never ends the start-up early.
        assert!(RadioStart::begin(50).poll(10, None).starting());
    }
}
