//! The loop watchdog: the chip resets if a pass of the super-loop does not end in time.
//!
//! Every wait inside a pass has a deadline of its own ([`crate::deadline`]); what has none (a
//! flash erase inside the ROM, a register handshake inside esp-hal, a task that preempts the
//! loop) is bounded by this watchdog. Two of the chip's watchdogs, both armed here and fed at
//! one place, [`LoopWatchdog::pass`], once per loop pass:
//!
//! * the main watchdog of timer group 1 (MWDT1, clocked from the APB clock), fed on every pass,
//!   resets the chip when a pass takes [`TIMEOUT_MS`];
//! * the RTC watchdog (RWDT, clocked from the RTC slow clock, so it runs whatever the main
//!   clocks do), fed at most every [`RTC_FEED_INTERVAL_US`] (for a timeout of seconds, feeding
//!   it on every pass would gain nothing), is the second line: it resets the chip after
//!   [`RTC_TIMEOUT_MS`].
//!
//! Why [`TIMEOUT_MS`]: the longest legitimate pass is one that writes flash (docs/boards.md,
//! "The loop watchdog"). A store that moves a full page (one write in a few hundred) reads the
//! flash up to about 135,000 times, some 0.5 to 1.1 s of ROM reads, and erases a 4 KiB sector:
//! about 45 ms, up to 400 ms by the flash datasheets. That is at most about 1.5 s; three seconds
//! leave a margin of two, and a hung arm is back in three seconds.

use esp_hal::{
    peripherals::{RTC_TIMER, TIMG1},
    rtc_cntl::{Rtc, RwdtStage},
    time::Duration,
    timer::timg::{MwdtStage, TimerGroup, Wdt},
};

/// The chip resets if a loop pass takes this long (the main watchdog's timeout).
pub const TIMEOUT_MS: u64 = 3_000;
/// The RTC watchdog's timeout: twice [`TIMEOUT_MS`], so it acts only if the main watchdog
/// could not.
pub const RTC_TIMEOUT_MS: u64 = 2 * TIMEOUT_MS;
/// How often the loop feeds the RTC watchdog, at most.
const RTC_FEED_INTERVAL_US: u64 = 100_000;

/// The loop's two watchdogs, armed by [`LoopWatchdog::start`] and fed by
/// [`LoopWatchdog::pass`].
pub struct LoopWatchdog<'d> {
    main: Wdt<TIMG1<'d>>,
    rtc: Rtc<'d>,
    rtc_fed_at_us: u64,
}

impl<'d> LoopWatchdog<'d> {
    /// Arms both watchdogs (timer group 1 is theirs from now on); `now_us` is the current
    /// time. Call it first thing after `esp_hal::init`, which leaves every watchdog off: the
    /// board's set-up must then end, and the loop start, within [`TIMEOUT_MS`]. Logs why the
    /// chip last reset (`log-uart0`): a reset by this watchdog reads as MWDT1 or RTC WDT.
    pub fn start(rtc_timer: RTC_TIMER<'d>, timg1: TIMG1<'d>, now_us: u64) -> Self {
        crate::board_log!("reset reason: {:?}", esp_hal::system::reset_reason());
        // Stage 0 resets the system, the other stages are off (esp-hal's `enable`).
        let mut main = TimerGroup::new(timg1).wdt;
        // First a timeout long enough to need a clock prescaler of 2, then the real one (1):
        // the prescaler changes twice, which silicon does not care about, but the ESP32-C3
        // model of the QEMU fork docs/boards.md names computes the watchdog's clock only when
        // the prescaler changes, and divides by zero (SIGFPE, the emulator dies) at `enable`
        // after a first timeout with the reset value 1.
        main.set_timeout(MwdtStage::Stage0, Duration::from_secs(120));
        main.set_timeout(MwdtStage::Stage0, Duration::from_millis(TIMEOUT_MS));
        main.enable();
        let mut rtc = Rtc::new(rtc_timer);
        rtc.rwdt
            .set_timeout(RwdtStage::Stage0, Duration::from_millis(RTC_TIMEOUT_MS));
        rtc.rwdt.enable();
        Self {
            main,
            rtc,
            rtc_fed_at_us: now_us,
        }
    }

    /// Call once per loop pass, at one place: feeds the main watchdog, and the RTC watchdog
    /// every [`RTC_FEED_INTERVAL_US`].
    pub fn pass(&mut self, now_us: u64) {
        self.main.feed();
        if now_us.wrapping_sub(self.rtc_fed_at_us) >= RTC_FEED_INTERVAL_US {
            self.rtc.rwdt.feed();
            self.rtc_fed_at_us = now_us;
        }
    }
}
