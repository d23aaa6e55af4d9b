//! The Atom board binary: binds [`firmware_atom::Atom`] to the chip and polls it forever.
//!
//! * UART1 at 1 Mbaud: the shared bus (servos and the Basic).
//! * UART0 at 115200: the USB serial, a direct host link (or logs with `log-uart0`).
//! * RMT: the WS2812 LEDs. LEDC: PWM on the user pins. GPIO: user pins and the button.
//!
//! Pins per chip are in [`pins`]; docs/boards.md says how to build and flash.
#![no_std]
#![no_main]
#![deny(unsafe_code)]

#[cfg(not(target_os = "none"))]
compile_error!(
    "the atom board binary builds only for a chip: `cargo build-atom-c3` or `cargo +esp build-atom` (docs/boards.md)"
);

mod board_io;
mod leds;
mod pins;
mod pwm;
mod ws2812;

use esp_hal::{
    clock::CpuClock,
    gpio::{AnyPin, Flex, Input, InputConfig, OutputSignal, Pull},
    ledc::{LSGlobalClkSource, Ledc, LowSpeed, channel, timer},
    main,
    rmt::Rmt,
    time::Rate,
    uart::Uart,
};
use firmware_atom::{Atom, AtomConfig};
use protocol_core::timing::BUS_BAUD;

use crate::{
    board_io::{BoardIo, UserPin},
    leds::{Leds, RMT_TICK_MHZ},
};
use board_support::{LoopWatchdog, UartPort, board_log, now_us};

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
    // Armed before anything that could hang: from here on only the loop below feeds it.
    let mut watchdog = LoopWatchdog::start(p.RTC_TIMER, p.TIMG1, now_us());
    let pins = pins::chip::take_pins!(p);
    board_log!("open-mycobot atom {}", env!("CARGO_PKG_VERSION"));

    let bus_uart = Uart::new(p.UART1, board_support::uart_port::config(BUS_BAUD))
        .unwrap_or_else(|_| panic!("bus UART configuration refused"))
        .with_tx(pins.bus_tx)
        .with_rx(pins.bus_rx);
    let mut bus = UartPort::new(bus_uart, BUS_BAUD);

    #[cfg(not(feature = "log-uart0"))]
    let mut usb = {
        use protocol_core::timing::HOST_BAUD;
        let usb_uart = Uart::new(p.UART0, board_support::uart_port::config(HOST_BAUD))
            .unwrap_or_else(|_| panic!("USB UART configuration refused"))
            .with_tx(pins.usb_tx)
            .with_rx(pins.usb_rx);
        UartPort::new(usb_uart, HOST_BAUD)
    };
    // UART0 carries the log instead; its pins stay as esp-println left them.
    #[cfg(feature = "log-uart0")]
    let mut usb = {
        let _ = (p.UART0, pins.usb_tx, pins.usb_rx);
        protocol_core::NullPort
    };

    let mut ledc = Ledc::new(p.LEDC);
    ledc.set_global_slow_clock(LSGlobalClkSource::APBClk);
    let [pin0, pin1, pin2, pin3] = pins.user;
    let user = [
        user_pin(pin0, &ledc, 0),
        user_pin(pin1, &ledc, 1),
        user_pin(pin2, &ledc, 2),
        user_pin(pin3, &ledc, 3),
    ];

    let leds = Rmt::new(p.RMT, Rate::from_mhz(RMT_TICK_MHZ))
        .ok()
        .and_then(|rmt| Leds::new(rmt.channel0, pins.leds));
    if leds.is_none() {
        board_log!("RMT refused the LED channel; LEDs stay dark");
    }
    let button = Input::new(pins.button, InputConfig::default().with_pull(Pull::None));
    let flash = esp_storage::FlashStorage::new(p.FLASH);
    let io = BoardIo::new(user, leds, button, flash);
    #[cfg(feature = "esp32")]
    let io = io.with_accessory(board_io::AccessoryServo {
        gpio: Flex::new(pins.accessory),
        timer: ledc.timer::<esp_hal::ledc::HighSpeed>(timer::Number::Timer0),
    });
    let mut io = io;

    let mut atom = Atom::new(AtomConfig::default());
    if let Some(error) = atom.config_error() {
        board_log!("configuration refused, running defaults: {:?}", error);
    }

    loop {
        let now = now_us();
        atom.poll(now, &mut bus, &mut usb, &mut io);
        watchdog.pass(now);
    }
}

/// User pin `index` (0..4) of `firmware_atom::io::OUTPUT_PINS`, with LEDC timer and channel
/// `index` reserved for its PWM.
fn user_pin(pin: AnyPin<'static>, ledc: &Ledc<'static>, index: u8) -> UserPin<'static> {
    let (timer, channel, signal) = match index {
        0 => (
            timer::Number::Timer0,
            channel::Number::Channel0,
            OutputSignal::LEDC_LS_SIG0,
        ),
        1 => (
            timer::Number::Timer1,
            channel::Number::Channel1,
            OutputSignal::LEDC_LS_SIG1,
        ),
        2 => (
            timer::Number::Timer2,
            channel::Number::Channel2,
            OutputSignal::LEDC_LS_SIG2,
        ),
        _ => (
            timer::Number::Timer3,
            channel::Number::Channel3,
            OutputSignal::LEDC_LS_SIG3,
        ),
    };
    UserPin {
        gpio: Flex::new(pin),
        timer: ledc.timer::<LowSpeed>(timer),
        channel,
        signal,
    }
}
