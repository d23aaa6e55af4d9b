//! Which GPIO does what, per chip. The only chip-specific code of the board binary.
//!
//! Each chip module ([`chip`]) defines `take_pins!(peripherals)`, which moves the pins out of
//! esp-hal's `Peripherals` into a [`BasicPins`]; [`FixedOutput`] (per chip, here) is the type of
//! the outputs a board may have wired to a fixed level instead of a GPIO (LCD reset and
//! backlight, speaker).

use esp_hal::gpio::AnyPin;

/// An output on a GPIO.
#[cfg(feature = "esp32")]
pub type FixedOutput = esp_hal::gpio::Output<'static>;

/// On the C3 stand-in, an output wired to a fixed level: writes to it do nothing.
#[cfg(feature = "esp32c3")]
pub type FixedOutput = esp_hal::gpio::NoPin;

/// The Basic's pins by function.
pub struct BasicPins {
    /// Host link (USB serial), transmit (UART0).
    pub host_tx: AnyPin<'static>,
    /// Host link (USB serial), receive (UART0).
    pub host_rx: AnyPin<'static>,
    /// Shared servo bus, transmit (UART1).
    pub bus_tx: AnyPin<'static>,
    /// Shared servo bus, receive (UART1).
    pub bus_rx: AnyPin<'static>,
    /// User outputs in the order of `firmware_basic::io::OUTPUT_PINS` (protocol GPIO 2, 5).
    pub outputs: [AnyPin<'static>; 2],
    /// User inputs in the order of `firmware_basic::io::INPUT_PINS` (protocol GPIO 35, 36).
    pub inputs: [AnyPin<'static>; 2],
    /// Front buttons A, B, C: active low, external pull-ups.
    pub buttons: [AnyPin<'static>; 3],
    /// LCD SPI clock.
    pub lcd_clk: AnyPin<'static>,
    /// LCD SPI data out (the LCD is only written, so MISO is not used).
    pub lcd_mosi: AnyPin<'static>,
    /// LCD chip select.
    pub lcd_cs: AnyPin<'static>,
    /// LCD data/command select.
    pub lcd_dc: AnyPin<'static>,
    /// LCD reset, active low.
    pub lcd_reset: FixedOutput,
    /// LCD backlight, on when high.
    pub lcd_backlight: FixedOutput,
    /// Speaker (DAC pin), kept low so it stays silent.
    pub speaker: FixedOutput,
}

#[cfg(feature = "esp32")]
#[path = "pins_esp32.rs"]
pub(crate) mod chip;

#[cfg(feature = "esp32c3")]
#[path = "pins_esp32c3.rs"]
pub(crate) mod chip;
