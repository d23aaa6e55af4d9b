//! The real Atom (ESP32-PICO-D4), as in `docs/boards.md`. GPIO 6..11, 16 and 17 belong to the
//! embedded flash and are never taken.

/// Moves the Atom's pins out of `$p` (esp-hal `Peripherals`).
macro_rules! take_pins {
    ($p:ident) => {
        $crate::pins::AtomPins {
            bus_tx: $p.GPIO21.into(),
            bus_rx: $p.GPIO25.into(),
            usb_tx: $p.GPIO1.into(),
            usb_rx: $p.GPIO3.into(),
            leds: $p.GPIO27.into(),
            button: $p.GPIO39.into(),
            user: [
                $p.GPIO19.into(),
                $p.GPIO22.into(),
                $p.GPIO23.into(),
                $p.GPIO33.into(),
            ],
            accessory: $p.GPIO26.into(),
        }
    };
}
pub(crate) use take_pins;
