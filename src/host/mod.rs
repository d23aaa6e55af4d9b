//! The front end of the virtual robot: what `cargo run --release` puts in front of the
//! simulated arm so that unmodified clients can drive it.
//!
//! * [`pty`]: a raw pseudo-terminal standing in for the Basic's USB serial port;
//! * [`pty_link`]: a stable symlink to it (`--pty-link`), held by one robot at a time;
//! * [`tcp`]: the host protocol over TCP, like the Basic's Wi-Fi server (`--tcp`);
//! * [`pacer`]: client input paced to the serial line's speed, as a real port does;
//! * [`realtime`]: the loop that runs the robot at wall-clock speed and moves the bytes;
//! * [`emulated`]: the bus and servos serving the real images on emulated chips (QEMU), through
//!   their UART sockets;
//! * [`buttons`]: the Basic's front buttons pressed from the keyboard and the 3D view;
//! * [`cli`]: the command line.

pub mod buttons;
pub mod cli;
pub mod emulated;
pub mod pacer;
pub mod pty;
pub mod pty_link;
pub mod realtime;
pub mod tcp;
