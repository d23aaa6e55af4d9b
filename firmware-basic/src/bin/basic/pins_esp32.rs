//! The real M5Stack Basic (ESP32), as in `docs/boards.md`.

/// Moves the Basic's pins out of `$p` (esp-hal `Peripherals`).
macro_rules! take_pins {
    ($p:ident) => {{
        use esp_hal::gpio::{Level, Output, OutputConfig};
        $crate::pins::BasicPins {
            host_tx: $p.GPIO1.into(),
            host_rx: $p.GPIO3.into(),
            bus_tx: $p.GPIO17.into(),
            bus_rx: $p.GPIO16.into(),
            outputs: [$p.GPIO2.into(), $p.GPIO5.into()],
            inputs: [$p.GPIO35.into(), $p.GPIO36.into()],
            buttons: [$p.GPIO39.into(), $p.GPIO38.into(), $p.GPIO37.into()],
            lcd_clk: $p.GPIO18.into(),
            lcd_mosi: $p.GPIO23.into(),
            lcd_cs: $p.GPIO14.into(),
            lcd_dc: $p.GPIO27.into(),
            lcd_reset: Output::new($p.GPIO33, Level::High, OutputConfig::default()),
            lcd_backlight: Output::new($p.GPIO32, Level::Low, OutputConfig::default()),
            speaker: Output::new($p.GPIO25, Level::Low, OutputConfig::default()),
        }
    }};
}
pub(crate) use take_pins;
