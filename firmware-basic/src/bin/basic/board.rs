//! The board set-up every image of the Basic shares (the transponder, `basic/main.rs`, and
//! teach and play, `basic-teach/main.rs`): the status screen on the LCD and the UART ports.

use embedded_graphics::{pixelcolor::Rgb565, prelude::*};
use embedded_hal::digital::OutputPin;
use embedded_hal_bus::spi::ExclusiveDevice;
use esp_hal::{
    delay::Delay,
    gpio::{AnyPin, Level, Output, OutputConfig},
    peripherals::SPI2,
    spi::{
        Mode,
        master::{Config as SpiConfig, Spi},
    },
    time::Rate,
    uart::{Instance, Uart},
};
use mipidsi::{
    Builder,
    interface::SpiInterface,
    models::ILI9342CRgb565,
    options::{ColorInversion, ColorOrder},
};

use crate::{pins::FixedOutput, screen::StatusScreen};
use board_support::UartPort;

/// LCD SPI clock: the ILI9342C's write limit on the M5Stack Basic.
const LCD_SPI_MHZ: u32 = 40;
/// Bytes mipidsi batches per SPI write: the size of the buffer [`status_screen`] borrows.
pub const LCD_BUFFER_BYTES: usize = 512;

/// The LCD (SPI clock, data, chip select and data/command pins; its reset) as the status
/// screen, cleared, with its backlight switched on; `None` when the SPI, the driver or the panel
/// refuses: the Basic runs on without a screen. Its set-up waits about 0.2 s, long enough to
/// overflow a UART's receive FIFO: set it up before the UARTs.
pub fn status_screen<'a>(
    spi: SPI2<'static>,
    [clk, mosi, cs, dc]: [AnyPin<'static>; 4],
    reset: FixedOutput,
    backlight: &mut FixedOutput,
    buffer: &'a mut [u8; LCD_BUFFER_BYTES],
) -> Option<StatusScreen<impl DrawTarget<Color = Rgb565> + 'a>> {
    let config = SpiConfig::default()
        .with_frequency(Rate::from_mhz(LCD_SPI_MHZ))
        .with_mode(Mode::_0);
    let spi = Spi::new(spi, config).ok()?.with_sck(clk).with_mosi(mosi);
    let cs = Output::new(cs, Level::High, OutputConfig::default());
    let dc = Output::new(dc, Level::Low, OutputConfig::default());
    let device = ExclusiveDevice::new(spi, cs, Delay::new()).ok()?;
    let mut display = Builder::new(ILI9342CRgb565, SpiInterface::new(device, dc, buffer))
        .reset_pin(reset)
        .color_order(ColorOrder::Bgr)
        .invert_colors(ColorInversion::Inverted)
        .init(&mut Delay::new())
        .ok()?;
    display.clear(Rgb565::BLACK).ok()?;
    // Through the embedded-hal trait: an `Output` on the ESP32, a `NoPin` on the C3 stand-in,
    // both infallible.
    let Ok(()) = OutputPin::set_high(backlight);
    Some(StatusScreen::new(display))
}

/// `uart` at `baud` (8N1) on pins `tx` and `rx` as a byte port. A configuration the UART
/// refuses is a firmware bug (the settings are constants): it panics, naming `what`, and the
/// panic restarts the board.
pub fn uart_port(
    uart: impl Instance + 'static,
    baud: u32,
    tx: AnyPin<'static>,
    rx: AnyPin<'static>,
    what: &str,
) -> UartPort<'static> {
    let uart = Uart::new(uart, board_support::uart_port::config(baud))
        .unwrap_or_else(|_| panic!("{what} UART configuration refused"))
        .with_tx(tx)
        .with_rx(rx);
    UartPort::new(uart, baud)
}
