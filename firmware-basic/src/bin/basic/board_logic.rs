//! Host tests of the Basic board binary's hardware-free parts; the binary itself builds only
//! for a chip (docs/boards.md).

#[path = "loop_time.rs"]
mod loop_time;
#[path = "radio_start.rs"]
mod radio_start;
#[path = "screen_text.rs"]
mod screen_text;
#[path = "../basic-teach/teach_text.rs"]
mod teach_text;
