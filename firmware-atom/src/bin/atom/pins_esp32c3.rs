//! ESP32-C3 stand-in for the compile-and-link check. The C3 has GPIO 0..21 only, so each
//! function gets a free C3 pin, chosen as on an ESP32-C3-DevKitM-1: UART0 on its default
//! GPIO21/20, the RGB LED on GPIO8, the BOOT button on GPIO9. Flash (GPIO12..17) and USB
//! (GPIO18/19) pins are left alone.

/// Moves the stand-in pins out of `$p` (esp-hal `Peripherals`).
macro_rules! take_pins {
    ($p:ident) => {
        $crate::pins::AtomPins {
            bus_tx: $p.GPIO4.into(),
            bus_rx: $p.GPIO5.into(),
            usb_tx: $p.GPIO21.into(),
            usb_rx: $p.GPIO20.into(),
            leds: $p.GPIO8.into(),
            button: $p.GPIO9.into(),
            user: [
                $p.GPIO0.into(),
                $p.GPIO1.into(),
                $p.GPIO3.into(),
                $p.GPIO10.into(),
            ],
        }
    };
}
pub(crate) use take_pins;
