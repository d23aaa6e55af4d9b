//! The two protocols that travel on a myCobot 280 M5's wires, typed and zero-allocation.
//!
//! * [`command`]: what each host frame means: typed requests and replies, error codes.
//! * [`dialect`]: the two ways clients speak the host protocol (pymycobot's and the vendor
//!   manual's), as translations into the one the rest of this crate implements.
//! * [`frame`]: host frames `FE FE LEN CMD DATA FA` and a streaming decoder that finds them in
//!   any byte stream (any chunking, garbage, servo packets on the same wire).
//! * [`servo`]: Feetech STS servo packets `FF FF ID LEN ...`, their checksum, register values
//!   and a streaming packet decoder.
//! * [`listener`]: one timed listener for every station: bytes and time in; host frames, servo
//!   packets, own echo and quiet-line handling out.
//! * [`units`]: the protocol's units as distinct types.
//! * [`port`]: the byte-link trait both firmwares and the virtual robot are written against.
//! * [`timing`]: baud rates and the bus-sharing rules every station follows.
//!
//! Nothing in this crate panics on any input.
#![cfg_attr(not(test), no_std)]
#![forbid(unsafe_code)]

pub mod command;
pub mod dialect;
pub mod frame;
pub mod listener;
pub mod port;
mod scanner;
pub mod servo;
pub mod timing;
pub mod units;

pub use frame::{Frame, FrameDecoder};
pub use listener::{Listener, ListenerConfig};
pub use port::{BytePort, NullPort};
