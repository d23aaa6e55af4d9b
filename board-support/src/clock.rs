//! The board's clock, microseconds since boot: esp-hal's `Instant`, which reads timer group
//! 0's LACT timer on the ESP32 and SYSTIMER unit 0 on the ESP32-C3. Every deadline of the board
//! layers ([`crate::deadline`]) and every timer of the libraries counts on it.

use esp_hal::{peripherals::Peripherals, time::Instant};

/// Microseconds since boot.
pub fn now_us() -> u64 {
    Instant::now().duration_since_epoch().as_micros()
}

/// Makes sure the clock counts; call it right after `esp_hal::init`, before the first
/// [`now_us`].
///
/// On the ESP32-C3 esp-hal reads SYSTIMER unit 0 but never starts it: it relies on the
/// silicon, whose `SYSTIMER_CONF` resets with `TIMER_UNIT0_WORK_EN` set. This sets that bit
/// (on a chip it is set already, so nothing changes). A machine that resets it clear, as the
/// C3 model of the QEMU fork docs/boards.md names does, would otherwise read 0 for ever: no
/// deadline would ever pass, and the first wait that needs one (a colour on an emulator
/// without an RMT) would hang the loop until the watchdog reset the chip (docs/boards.md,
/// "What the emulator cannot show").
pub fn start(peripherals: &Peripherals) {
    #[cfg(feature = "esp32c3")]
    peripherals
        .SYSTIMER
        .register_block()
        .conf()
        .modify(|_, w| w.timer_unit0_work_en().set_bit());
    // The ESP32's LACT timer is started by `esp_hal::init` itself.
    #[cfg(not(feature = "esp32c3"))]
    let _ = peripherals;
}
