//! Host tests of the Atom board binary's hardware-free parts; the binary itself builds only
//! for a chip (docs/boards.md).

#[path = "pwm.rs"]
mod pwm;
#[path = "ws2812.rs"]
mod ws2812;
