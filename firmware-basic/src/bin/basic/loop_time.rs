//! The longest gap between two passes of the super-loop, measured on the board: what the
//! UARTs' receive FIFOs must cover (128 bytes: 1.28 ms of a full 1 Mbaud bus). It includes
//! everything that held the loop up: the Basic's own poll, the LCD, Wi-Fi and TCP, a flash
//! write, and (with Wi-Fi) the radio's tasks preempting the loop. Pure logic, tested on the
//! host (`cargo test -p firmware-basic --test board_logic`).

/// Length of one measuring window, in microseconds: the maximum shown covers the last one to
/// two windows, so a past stall is forgotten after 20 s.
pub const WINDOW_US: u64 = 10_000_000;

/// The loop's longest pass gap over the last 10 to 20 seconds.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct LoopTime {
    last_pass_us: Option<u64>,
    window_start_us: u64,
    /// Longest gap in the current window, microseconds.
    current_max_us: u32,
    /// Longest gap in the window before, microseconds.
    previous_max_us: u32,
}

impl LoopTime {
    /// Notes a pass of the loop starting at `now_us`.
    pub fn pass(&mut self, now_us: u64) {
        if let Some(last) = self.last_pass_us {
            let gap = u32::try_from(now_us.saturating_sub(last)).unwrap_or(u32::MAX);
            self.current_max_us = self.current_max_us.max(gap);
        } else {
            self.window_start_us = now_us;
        }
        self.last_pass_us = Some(now_us);
        if now_us.saturating_sub(self.window_start_us) >= WINDOW_US {
            self.previous_max_us = self.current_max_us;
            self.current_max_us = 0;
            self.window_start_us = now_us;
        }
    }

    /// The longest gap between two passes in the last one to two windows, microseconds.
    pub fn max_us(&self) -> u32 {
        self.current_max_us.max(self.previous_max_us)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_longest_gap_is_kept_for_one_to_two_windows() {
        let mut time = LoopTime::default();
        assert_eq!(time.max_us(), 0);
        time.pass(1_000);
        time.pass(1_050);
        time.pass(1_400);
        time.pass(1_420);
        assert_eq!(time.max_us(), 350);
        // Still shown through the next window...
        let mut now = 1_420;
        while now < 1_000 + WINDOW_US + 5_000 {
            now += 100;
            time.pass(now);
        }
        assert_eq!(time.max_us(), 350);
        // ... and forgotten after it.
        while now < 1_000 + 2 * WINDOW_US + 5_000 {
            now += 100;
            time.pass(now);
        }
        assert_eq!(time.max_us(), 100);
    }

    #[test]
    fn a_huge_gap_saturates() {
        let mut time = LoopTime::default();
        time.pass(0);
        time.pass(u64::MAX);
        assert_eq!(time.max_us(), u32::MAX);
    }
}
