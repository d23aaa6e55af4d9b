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
#[path = "../basic/board.rs"]
mod board;
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

use embedded_hal::digital::OutputPin;
use esp_hal::{clock::CpuClock, main};
use firmware_basic::teach::Teach;
use firmware_basic::{BasicConfig, Programmed};
use protocol_core::timing::{BUS_BAUD, HOST_BAUD};

use crate::{board_io::BoardIo, loop_time::LoopTime, screen_text::BoardStatus};
use board_support::{LoopWatchdog, board_log, now_us};

esp_bootloader_esp_idf::esp_app_desc!();

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

    let mut lcd_buffer = [0_u8; board::LCD_BUFFER_BYTES];
    let lcd = [pins.lcd_clk, pins.lcd_mosi, pins.lcd_cs, pins.lcd_dc];
    let mut screen = board::status_screen(
        p.SPI2,
        lcd,
        pins.lcd_reset,
        &mut pins.lcd_backlight,
        &mut lcd_buffer,
    );

    let mut host = board::uart_port(p.UART0, HOST_BAUD, pins.host_tx, pins.host_rx, "host");
    let mut bus = board::uart_port(p.UART1, BUS_BAUD, pins.bus_tx, pins.bus_rx, "bus");
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
