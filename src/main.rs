//! `cargo run --release`: starts the virtual robot.
fn main() {}
