//! The Basic running a program of its own: teach and play ([`firmware_basic::teach`]), the
//! worked example of "Write your own program" (docs/program.md). Button A records the arm moved
//! by hand, B plays it back, C stops; the LCD says what it does.
//!
//! The board is the shipped Basic's ([`firmware_basic::Basic`] on the same UARTs, pins, LCD
//! and watchdog, without Wi-Fi), with [`firmware_basic::Programmed`] in place of the
//! transponder alone: the program's calls reach the Atom through the transponder's router, so
//! they follow the bus's rules, and the USB link keeps answering a PC. To write another
//! program, copy this file, implement [`firmware_basic::Program`] and put yours in place of
//! `Teach`.
#![no_std]
#![no_main]
#![deny(unsafe_code)]

#[cfg(not(target_os = "none"))]
compile_error!(
    "the basic-teach board binary builds only for a chip: `cargo build-basic-teach-c3` or `cargo +esp build-basic-teach` (docs/boards.md)"
);

// The board layer is the Basic's; the teach image uses part of its screen text.
#[path = "../basic/board_io.rs"]
mod board_io;
#[path = "../basic/loop_time.rs"]
mod loop_time;
#[path = "../basic/pins.rs"]
mod pins;
#[allow(dead_code)]
#[path = "../basic/radio_start.rs"]
mod radio_start;
#[path = "../basic/screen.rs"]
mod screen;
#[allow(dead_code)]
#[path = "../basic/screen_text.rs"]
mod screen_text;
mod teach_text;

use embedded_graphics::{pixelcolor::Rgb565, prelude::*};
use embedded_hal::digital::OutputPin;
use embedded_hal_bus::spi::ExclusiveDevice;
use esp_hal::{
    clock::CpuClock,
    delay::Delay,
    gpio::{Level, Output, OutputConfig},
    main,
    spi::{
        Mode,
        master::{Config as SpiConfig, Spi},
    },
    time::Rate,
    uart::Uart,
};
use firmware_basic::teach::Teach;
use firmware_basic::{BasicConfig, Programmed};
use mipidsi::{
    Builder,
    interface::SpiInterface,
    models::ILI9342CRgb565,
    options::{ColorInversion, ColorOrder},
};
use protocol_core::timing::{BUS_BAUD, HOST_BAUD};

use crate::{
    board_io::BoardIo, loop_time::LoopTime, screen::StatusScreen, screen_text::BoardStatus,
};
use board_support::{LoopWatchdog, UartPort, board_log, now_us};

esp_bootloader_esp_idf::esp_app_desc!();

/// LCD SPI clock: the ILI9342C's write limit on the M5Stack Basic.
const LCD_SPI_MHZ: u32 = 40;
/// Bytes mipidsi batches per SPI write.
const LCD_BUFFER_BYTES: usize = 512;

#[main]
fn main() -> ! {
    // The C3: RAM the bootloader ran code from, written once (board_support::stack_paint).
    #[cfg(feature = "esp32c3")]
    board_support::stack_paint::paint_unused_ram();
    run()
}

/// Everything `main` does after the stack is painted, in frames of their own.
#[inline(never)]
fn run() -> ! {
    let p = esp_hal::init(esp_hal::Config::default().with_cpu_clock(CpuClock::max()));
    board_support::clock::start(&p);
    let mut watchdog = LoopWatchdog::start(p.RTC_TIMER, p.TIMG1, now_us());
    let mut pins = pins::chip::take_pins!(p);
    let Ok(()) = OutputPin::set_low(&mut pins.speaker);
    board_log!("open-mycobot basic-teach {}", env!("CARGO_PKG_VERSION"));

    let mut lcd_buffer = [0_u8; LCD_BUFFER_BYTES];
    let spi_config = SpiConfig::default()
        .with_frequency(Rate::from_mhz(LCD_SPI_MHZ))
        .with_mode(Mode::_0);
    let display = Spi::new(p.SPI2, spi_config).ok().and_then(|spi| {
        let spi = spi.with_sck(pins.lcd_clk).with_mosi(pins.lcd_mosi);
        let cs = Output::new(pins.lcd_cs, Level::High, OutputConfig::default());
        let dc = Output::new(pins.lcd_dc, Level::Low, OutputConfig::default());
        let device = ExclusiveDevice::new(spi, cs, Delay::new()).ok()?;
        Builder::new(
            ILI9342CRgb565,
            SpiInterface::new(device, dc, &mut lcd_buffer),
        )
        .reset_pin(pins.lcd_reset)
        .color_order(ColorOrder::Bgr)
        .invert_colors(ColorInversion::Inverted)
        .init(&mut Delay::new())
        .ok()
    });
    let mut screen = display.and_then(|mut display| {
        display.clear(Rgb565::BLACK).ok()?;
        let Ok(()) = OutputPin::set_high(&mut pins.lcd_backlight);
        Some(StatusScreen::new(display))
    });

    let host_uart = Uart::new(p.UART0, board_support::uart_port::config(HOST_BAUD))
        .unwrap_or_else(|_| panic!("host UART configuration refused"))
        .with_tx(pins.host_tx)
        .with_rx(pins.host_rx);
    let mut host = UartPort::new(host_uart, HOST_BAUD);
    let bus_uart = Uart::new(p.UART1, board_support::uart_port::config(BUS_BAUD))
        .unwrap_or_else(|_| panic!("bus UART configuration refused"))
        .with_tx(pins.bus_tx)
        .with_rx(pins.bus_rx);
    let mut bus = UartPort::new(bus_uart, BUS_BAUD);
    let mut io = BoardIo::new(pins.outputs, pins.inputs, pins.buttons);

    // The program: the Basic's transponder with teach and play beside it.
    let mut basic = Programmed::new(BasicConfig::default(), Teach::new());
    let mut loop_time = LoopTime::default();

    loop {
        let now = now_us();
        loop_time.pass(now);
        basic.poll(now, &mut host, &mut bus, &mut io);
        if let Some(screen) = &mut screen {
            screen.update(now, || {
                let board = BoardStatus {
                    loop_max_us: loop_time.max_us(),
                    wifi: None,
                    radio: None,
                };
                teach_text::render_teach(&basic.program().status(), &basic.basic().status(), &board)
            });
            screen.draw_next();
        }
        watchdog.pass(now);
    }
}
