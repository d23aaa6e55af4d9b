//! ESP32-C3 stand-in for the compile-and-link check. The C3 has GPIO 0..21 only and the flash
//! takes 12..17, which leaves 15 pins for the Basic's 18 functions: this stand-in board has
//! UART0 on the C3's default GPIO21/20, the buttons on GPIO9 (BOOT), 3 and 10, the LCD's reset
//! tied to the chip's reset, its backlight always on, and no speaker.

/// Moves the stand-in pins out of `$p` (esp-hal `Peripherals`).
macro_rules! take_pins {
    ($p:ident) => {
        $crate::pins::BasicPins {
            host_tx: $p.GPIO21.into(),
            host_rx: $p.GPIO20.into(),
            bus_tx: $p.GPIO4.into(),
            bus_rx: $p.GPIO5.into(),
            outputs: [$p.GPIO6.into(), $p.GPIO7.into()],
            inputs: [$p.GPIO0.into(), $p.GPIO1.into()],
            buttons: [$p.GPIO9.into(), $p.GPIO3.into(), $p.GPIO10.into()],
            lcd_clk: $p.GPIO19.into(),
            lcd_mosi: $p.GPIO18.into(),
            lcd_cs: $p.GPIO2.into(),
            lcd_dc: $p.GPIO8.into(),
            lcd_reset: esp_hal::gpio::NoPin,
            lcd_backlight: esp_hal::gpio::NoPin,
            speaker: esp_hal::gpio::NoPin,
        }
    };
}
pub(crate) use take_pins;
