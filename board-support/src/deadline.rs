//! Waits with a deadline: every wait of the board layers on a peripheral ends when the
//! peripheral is done or when the board's clock passes a deadline, whichever comes first, so a
//! stuck peripheral costs one operation, never the loop. Pure logic, no esp-hal: built and
//! tested on the host too (`cargo test -p board-support`).

/// A moment of the board's clock (microseconds since boot) after which a wait gives up.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct Deadline {
    at_us: u64,
}

/// A wait reached its [`Deadline`] before the peripheral was done.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct TimedOut;

impl Deadline {
    /// `budget_us` microseconds after `now_us`.
    pub const fn after(now_us: u64, budget_us: u64) -> Self {
        Self {
            at_us: now_us.saturating_add(budget_us),
        }
    }

    /// True once the clock reads `now_us` at or past the deadline.
    pub const fn passed(self, now_us: u64) -> bool {
        now_us >= self.at_us
    }
}

/// Calls `step` until it reports done (`true`) or `clock` passes `deadline`. `step` is called
/// at least once, and again after the deadline has not yet passed, so a peripheral that finishes
/// just in time still counts as done.
pub fn wait_until(
    mut clock: impl FnMut() -> u64,
    deadline: Deadline,
    mut step: impl FnMut() -> bool,
) -> Result<(), TimedOut> {
    loop {
        if step() {
            return Ok(());
        }
        if deadline.passed(clock()) {
            return Err(TimedOut);
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use core::cell::Cell;

    #[test]
    fn a_peripheral_that_never_finishes_costs_the_budget_and_no_more() {
        let now = Cell::new(1_000_u64);
        let clock = || {
            now.set(now.get() + 7);
            now.get()
        };
        let mut steps = 0;
        let result = wait_until(clock, Deadline::after(1_000, 100), || {
            steps += 1;
            false
        });
        assert_eq!(result, Err(TimedOut));
        assert!(
            now.get() >= 1_100 && now.get() < 1_107,
            "gave up at {}",
            now.get()
        );
        assert_eq!(steps, 15);
    }

    #[test]
    fn a_peripheral_that_finishes_is_done_at_once() {
        let mut steps = 0;
        let result = wait_until(
            || 0,
            Deadline::after(0, 100),
            || {
                steps += 1;
                steps == 3
            },
        );
        assert_eq!(result, Ok(()));
        assert_eq!(steps, 3);
    }

    #[test]
    fn a_step_is_tried_even_when_the_deadline_has_passed() {
        // A pass that was late to start (a long flash erase before it) still gives the
        // peripheral one look.
        assert_eq!(wait_until(|| 500, Deadline::after(0, 100), || true), Ok(()));
    }

    #[test]
    fn a_deadline_near_the_end_of_time_does_not_wrap() {
        let deadline = Deadline::after(u64::MAX - 5, 100);
        assert!(!deadline.passed(u64::MAX - 1));
        assert!(deadline.passed(u64::MAX));
    }
}
