//! How long the boards' flash keeps them standing still. On the ESP32 (and the C3) a flash
//! erase or write runs from ROM with the cache off and interrupts masked: the main loop stops,
//! and a UART only takes what its 128-byte receive FIFO holds (1.3 ms of the 1 Mbaud bus).
//! The virtual robot stops a board for as long as its flash work takes, by the datasheet of
//! the NOR flash these boards carry (Winbond W25Q32JV class: a 4 KiB sector erase takes 45 ms
//! typically and 400 ms at worst, a page program 0.4 ms typically and 3 ms at worst).

use clap::ValueEnum;
use flash_store::MemFlash;

/// Which of the datasheet's times the simulated flash takes.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, ValueEnum)]
pub enum FlashTiming {
    /// Typical times: a sector erase 45 ms, a page program 0.4 ms.
    #[default]
    Typical,
    /// Worst-case times: a sector erase 400 ms, a page program 3 ms.
    Worst,
    /// No time at all: a board never stands still for its flash (an idealised chip).
    Instant,
}

impl FlashTiming {
    /// Microseconds one 4 KiB sector erase takes.
    pub const fn sector_erase_us(self) -> u64 {
        match self {
            Self::Typical => 45_000,
            Self::Worst => 400_000,
            Self::Instant => 0,
        }
    }

    /// Microseconds one page program (up to 256 bytes) takes.
    pub const fn page_program_us(self) -> u64 {
        match self {
            Self::Typical => 400,
            Self::Worst => 3_000,
            Self::Instant => 0,
        }
    }
}

/// What a board's flash has done so far, to tell how long its last loop pass stood still.
#[derive(Clone, Copy, Debug, Default)]
pub(crate) struct FlashWork {
    erases: u64,
    programs: u32,
}

impl FlashWork {
    /// The work `flash` has done so far.
    pub(crate) fn of<const SIZE: usize>(flash: &MemFlash<SIZE>) -> Self {
        Self {
            erases: flash.erase_counts().iter().map(|&n| u64::from(n)).sum(),
            programs: flash.program_count(),
        }
    }

    /// Microseconds the work done since `before` took at `timing`.
    pub(crate) fn busy_us_since(self, before: Self, timing: FlashTiming) -> u64 {
        let erases = self.erases.saturating_sub(before.erases);
        let programs = u64::from(self.programs.wrapping_sub(before.programs));
        erases * timing.sector_erase_us() + programs * timing.page_program_us()
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use embedded_storage::nor_flash::NorFlash;

    #[test]
    fn an_erase_and_a_write_across_two_pages_cost_their_datasheet_times() {
        let mut flash = MemFlash::<8192>::new();
        let before = FlashWork::of(&flash);
        flash.erase(0, 4096).unwrap();
        flash.write(252, &[0; 8]).unwrap();
        let after = FlashWork::of(&flash);
        assert_eq!(
            after.busy_us_since(before, FlashTiming::Typical),
            45_000 + 2 * 400
        );
        assert_eq!(
            after.busy_us_since(before, FlashTiming::Worst),
            400_000 + 2 * 3_000
        );
        assert_eq!(after.busy_us_since(before, FlashTiming::Instant), 0);
        assert_eq!(after.busy_us_since(after, FlashTiming::Worst), 0);
    }
}
