//! The loop watchdog: the RTC watchdog resets the chip if the super-loop stalls.

use esp_hal::{
    peripherals::RTC_TIMER,
    rtc_cntl::{Rtc, RwdtStage},
    time::Duration,
};

/// The watchdog resets the chip if the loop stalls this long.
const TIMEOUT_MS: u64 = 1_000;
/// How often the loop feeds the watchdog (feeding is a slow RTC register write).
const FEED_INTERVAL_US: u64 = 100_000;

/// The RTC watchdog, armed for [`TIMEOUT_MS`] and fed from the loop.
pub struct LoopWatchdog<'d> {
    rtc: Rtc<'d>,
    fed_at_us: u64,
}

impl<'d> LoopWatchdog<'d> {
    /// Arms the watchdog; `now_us` is the current time.
    pub fn start(rtc_timer: RTC_TIMER<'d>, now_us: u64) -> Self {
        let mut rtc = Rtc::new(rtc_timer);
        rtc.rwdt
            .set_timeout(RwdtStage::Stage0, Duration::from_millis(TIMEOUT_MS));
        rtc.rwdt.enable();
        Self {
            rtc,
            fed_at_us: now_us,
        }
    }

    /// Call on every loop pass: feeds the watchdog every [`FEED_INTERVAL_US`].
    pub fn pass(&mut self, now_us: u64) {
        if now_us.wrapping_sub(self.fed_at_us) >= FEED_INTERVAL_US {
            self.rtc.rwdt.feed();
            self.fed_at_us = now_us;
        }
    }
}
