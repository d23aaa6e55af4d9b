//! What the Atom and the Basic board binaries share on the chip: the UART as a
//! `protocol_core::BytePort`, the clock, waits with a deadline, the loop watchdog, logging on
//! UART0 (off unless the `log-uart0` feature is on, because UART0 is a host link) and the panic
//! policy (restart).
//!
//! Everything that touches esp-hal is built only for a chip (`target_os = "none"`), so
//! workspace builds and tests never see esp-hal; on the host the crate is [`deadline`] alone,
//! the pure logic of the waits, with its tests.
#![cfg_attr(not(test), no_std)]
#![deny(unsafe_code)]

#[cfg(target_os = "none")]
pub mod clock;
pub mod deadline;
#[cfg(target_os = "none")]
pub mod pass_cost;
// Raw writes to the unused stack (the module says why).
#[cfg(all(target_os = "none", target_arch = "riscv32"))]
#[allow(unsafe_code)]
pub mod stack_paint;
#[cfg(target_os = "none")]
pub mod uart_port;
#[cfg(target_os = "none")]
pub mod watchdog;

#[cfg(target_os = "none")]
pub use clock::now_us;
pub use deadline::{Deadline, TimedOut, wait_until};
#[cfg(target_os = "none")]
pub use uart_port::UartPort;
#[cfg(target_os = "none")]
pub use watchdog::LoopWatchdog;

#[cfg(all(target_os = "none", feature = "log-uart0"))]
#[doc(hidden)]
pub use esp_println;

/// Prints a line on UART0 when the `log-uart0` feature is on; otherwise only type-checks its
/// arguments, so the default build never writes to a host link.
#[cfg(feature = "log-uart0")]
#[macro_export]
macro_rules! board_log {
    ($($arg:tt)*) => { $crate::esp_println::println!($($arg)*) };
}

/// Prints a line on UART0 when the `log-uart0` feature is on; otherwise only type-checks its
/// arguments, so the default build never writes to a host link.
#[cfg(not(feature = "log-uart0"))]
#[macro_export]
macro_rules! board_log {
    ($($arg:tt)*) => {{ let _ = format_args!($($arg)*); }};
}

/// Nothing reachable from received bytes panics (the libraries are tested for it); a panic is
/// a firmware bug, and a restart is the quickest way back to a working arm.
#[cfg(target_os = "none")]
#[panic_handler]
fn panic(info: &core::panic::PanicInfo) -> ! {
    board_log!("panic: {}", info);
    esp_hal::system::software_reset()
}
