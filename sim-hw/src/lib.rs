//! Simulated hardware of the myCobot 280 bus: the shared wire with byte timing and collisions,
//! serial lines, Feetech STS servos. Used by the virtual robot and by the firmware crates'
//! tests.
//!
//! * [`wire`]: the shared 1 Mbaud half-duplex bus (every station hears every byte, overlapping
//!   transmissions garble each other, echo per station) and 115200 serial lines.
//! * [`servo`]: a simulated STS servo: control table, instructions, trapezoidal motion, faults,
//!   and contact: obstacles and pushes, the load they cause, the overload protection.
//! * [`chain`]: servos daisy-chained on one bus, hearing it through one decoder.
//!
//! Time is always passed in (nanoseconds); nothing here reads a clock.

#![forbid(unsafe_code)]

pub mod chain;
pub mod servo;
pub mod wire;

pub use chain::ServoChain;
pub use servo::{Faults, PacketListener, ServoStats, SimServo};
pub use wire::{Bus, BusByte, HeardByte, LineByte, SerialLine, StationId};
