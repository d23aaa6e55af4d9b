//! The Basic board binary: binds [`firmware_basic::Basic`] to the chip and polls it forever.
//!
//! * UART0 at 115200: the host link (USB serial).
//! * UART1 at 1 Mbaud: the shared bus (servos and the Atom).
//! * GPIO: user outputs and inputs, front buttons; the speaker is held silent.
//! * SPI: the ILI9342C LCD, showing the transponder's status one character per loop pass.
//! * With the `wifi` feature: the Wi-Fi station and TCP server ([`network`]), under the esp-rtos
//!   scheduler that esp-radio needs (the loop below is its main task, preempted by the radio's
//!   tasks), with a heap of [`RECLAIMED_HEAP_BYTES`] + [`HEAP_BYTES`]; the settings' flash is
//!   lent to the Basic through [`board_io::BoardIo`], and TCP clients reach its router through
//!   the library's [`firmware_basic::NetworkClients`], like the USB serial. The radio starts on
//!   a thread of its own while the loop already serves USB, with a deadline
//!   ([`radio_start`]); the loop watchdog is armed before it.
//!
//! Pins per chip are in [`pins`]; docs/boards.md says how to build and flash.
#![no_std]
#![no_main]
#![deny(unsafe_code)]

#[cfg(not(target_os = "none"))]
compile_error!(
    "the basic board binary builds only for a chip: `cargo build-basic-c3` or `cargo +esp build-basic` (docs/boards.md)"
);

#[cfg(feature = "wifi")]
extern crate alloc;

mod board;
mod board_io;
mod loop_time;
#[cfg(feature = "wifi")]
mod network;
mod pins;
#[cfg_attr(not(feature = "wifi"), allow(dead_code))]
mod radio_start;
mod screen;
mod screen_text;

use embedded_hal::digital::OutputPin;
use esp_hal::{clock::CpuClock, main};
use firmware_basic::{Basic, BasicConfig};
use protocol_core::timing::{BUS_BAUD, HOST_BAUD};

use crate::{board_io::BoardIo, loop_time::LoopTime, screen_text::BoardStatus};
use board_support::{LoopWatchdog, board_log, now_us};

esp_bootloader_esp_idf::esp_app_desc!();

/// Heap for esp-radio (driver buffers, its tasks' stacks and event channels) and the TCP/IP
/// stack's buffers (about 9 KiB), 100 KiB as in esp-hal's Wi-Fi examples: this part in the RAM
/// the ESP-IDF bootloader used (free once the application runs, outside `.bss`)...
#[cfg(feature = "wifi")]
const RECLAIMED_HEAP_BYTES: usize = 64 * 1024;
/// ... and this part in `.bss`.
#[cfg(feature = "wifi")]
const HEAP_BYTES: usize = 36 * 1024;

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
    // Armed before anything that could hang (the LCD's set-up, the Wi-Fi scheduler and radio):
    // from here on only the loop below feeds it.
    let mut watchdog = LoopWatchdog::start(p.RTC_TIMER, p.TIMG1, now_us());
    let mut pins = pins::chip::take_pins!(p);
    // Through the embedded-hal trait, so this line means the same on every chip: a fixed output
    // is an `Output` on the ESP32 and a `NoPin` on the C3 stand-in, both infallible.
    let Ok(()) = OutputPin::set_low(&mut pins.speaker);
    board_log!("open-mycobot basic {}", env!("CARGO_PKG_VERSION"));

    // The LCD is a nicety: without it (driver refused, panel absent) the transponder runs on.
    // It is set up first: its ~0.2 s of init delays would overflow the UARTs' receive FIFOs.
    let mut lcd_buffer = [0_u8; board::LCD_BUFFER_BYTES];
    let lcd = [pins.lcd_clk, pins.lcd_mosi, pins.lcd_cs, pins.lcd_dc];
    let mut screen = board::status_screen(
        p.SPI2,
        lcd,
        pins.lcd_reset,
        &mut pins.lcd_backlight,
        &mut lcd_buffer,
    );
    if screen.is_none() {
        board_log!("LCD did not initialise; running without a status screen");
    }

    let mut host = board::uart_port(p.UART0, HOST_BAUD, pins.host_tx, pins.host_rx, "host");
    let mut bus = board::uart_port(p.UART1, BUS_BAUD, pins.bus_tx, pins.bus_rx, "bus");
    let io = BoardIo::new(pins.outputs, pins.inputs, pins.buttons);
    // The Wi-Fi settings: answered over 0xB0..0xB2 on every link, even if the radio fails.
    #[cfg(feature = "wifi")]
    let io = io.with_wifi_flash(
        esp_storage::FlashStorage::new(p.FLASH),
        network::SETTINGS_FLASH,
    );
    let mut io = io;

    let mut basic = Basic::new(BasicConfig::default());

    // Wi-Fi needs the scheduler running before the radio starts. The radio starts on a thread
    // of its own, so the loop serves USB from its first pass whatever the radio does; one that
    // is not up by its deadline (or fails) leaves the transponder without Wi-Fi, and the LCD
    // says so (docs/boards.md, "Wi-Fi").
    #[cfg(feature = "wifi")]
    let (mut wifi, mut clients) = {
        esp_alloc::heap_allocator!(#[esp_hal::ram(reclaimed)] size: RECLAIMED_HEAP_BYTES);
        esp_alloc::heap_allocator!(size: HEAP_BYTES);
        let timg0 = esp_hal::timer::timg::TimerGroup::new(p.TIMG0);
        esp_rtos::start(timg0.timer0, p.FROM_CPU_INTR0);
        let rng = esp_hal::rng::Rng::new();
        let seed = (u64::from(rng.random()) << 32) | u64::from(rng.random());
        (
            network::BoardWifi::begin(now_us(), p.WIFI, seed),
            firmware_basic::NetworkClients::new(),
        )
    };

    let mut loop_time = LoopTime::default();

    loop {
        let now = now_us();
        loop_time.pass(now);
        #[cfg(not(feature = "wifi"))]
        basic.poll(now, &mut host, &mut bus, &mut io);
        #[cfg(feature = "wifi")]
        {
            clients.poll_basic(&mut basic, now, &mut host, &mut bus, &mut io);
            wifi.poll(now, &mut basic, &mut clients);
        }
        if let Some(screen) = &mut screen {
            screen.update(now, || {
                let board = BoardStatus {
                    loop_max_us: loop_time.max_us(),
                    #[cfg(feature = "wifi")]
                    wifi: basic.wifi_status(clients.count()),
                    #[cfg(feature = "wifi")]
                    radio: Some(wifi.radio()),
                    #[cfg(not(feature = "wifi"))]
                    wifi: None,
                    #[cfg(not(feature = "wifi"))]
                    radio: None,
                };
                screen_text::render(&basic.status(), &board)
            });
            screen.draw_next();
        }
        watchdog.pass(now);
    }
}
