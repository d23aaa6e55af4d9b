//! Which GPIO does what, per chip. The only chip-specific code of the board binary.
//!
//! Each chip module ([`chip`]) defines `take_pins!(peripherals)`, which moves the pins out of
//! esp-hal's `Peripherals` into an [`AtomPins`].

use esp_hal::gpio::AnyPin;

/// The Atom's pins by function.
pub struct AtomPins {
    /// Shared servo bus, transmit (UART1).
    pub bus_tx: AnyPin<'static>,
    /// Shared servo bus, receive (UART1).
    pub bus_rx: AnyPin<'static>,
    /// USB serial, transmit (UART0): direct host link, or logs with `log-uart0`.
    pub usb_tx: AnyPin<'static>,
    /// USB serial, receive (UART0).
    pub usb_rx: AnyPin<'static>,
    /// WS2812 LED chain data line (RMT).
    pub leds: AnyPin<'static>,
    /// The button, active low, no internal pull.
    pub button: AnyPin<'static>,
    /// The user pins in the order of `firmware_atom::io::OUTPUT_PINS` (protocol GPIO 19, 22,
    /// 23, 33).
    pub user: [AnyPin<'static>; 4],
    /// The Grove port's signal pin, for an accessory hobby servo (`firmware_atom::dispenser`).
    #[cfg(feature = "esp32")]
    pub accessory: AnyPin<'static>,
}

#[cfg(feature = "esp32")]
#[path = "pins_esp32.rs"]
pub(crate) mod chip;

#[cfg(feature = "esp32c3")]
#[path = "pins_esp32c3.rs"]
pub(crate) mod chip;
