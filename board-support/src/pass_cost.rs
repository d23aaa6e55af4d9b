//! What loop passes cost, for the pass-cost images (`atom-steps`, `basic-steps`: docs/boards.md,
//! "Loop passes on the chip"): the CPU's cycle counter, and a step's passes summed up.

/// The CPU's cycle counter (on the C3, which has none that is safe to read, microseconds at
/// its 160 MHz).
pub fn cycles() -> u32 {
    #[cfg(feature = "esp32")]
    {
        esp_hal::xtensa_lx::timer::get_cycle_count()
    }
    #[cfg(not(feature = "esp32"))]
    {
        (crate::now_us() as u32).wrapping_mul(160)
    }
}

/// A step's passes: the first (where a command is taken) and the longest of the others, where
/// that was, and the total, in cycles.
#[derive(Clone, Copy, Debug, Default)]
pub struct PassCost {
    /// Passes counted.
    pub passes: u32,
    /// The first pass's cycles.
    pub first: u32,
    /// The longest other pass's cycles...
    pub longest: u32,
    /// ...and which pass it was (1 is the first).
    pub longest_at: u32,
    /// All passes' cycles.
    pub total: u64,
}

impl PassCost {
    /// Counts a pass that took `spent` cycles.
    pub fn add(&mut self, spent: u32) {
        self.passes += 1;
        self.total += u64::from(spent);
        if self.passes == 1 {
            self.first = spent;
        } else if spent > self.longest {
            self.longest = spent;
            self.longest_at = self.passes;
        }
    }

    /// Adds `other`'s passes after these.
    pub fn extend(&mut self, other: &PassCost) {
        if self.passes == 0 {
            self.first = other.first;
        } else if other.first > self.longest {
            self.longest = other.first;
            self.longest_at = self.passes + 1;
        }
        if other.longest > self.longest {
            self.longest = other.longest;
            self.longest_at = self.passes + other.longest_at;
        }
        self.passes += other.passes;
        self.total += other.total;
    }

    /// The longest pass of all, first included: its cycles, and which pass it was.
    pub fn worst(&self) -> (u32, u32) {
        if self.first >= self.longest {
            (self.first, 1)
        } else {
            (self.longest, self.longest_at)
        }
    }

    /// The mean pass, cycles.
    pub fn mean(&self) -> u64 {
        self.total / u64::from(self.passes.max(1))
    }
}
