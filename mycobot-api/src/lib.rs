//! The myCobot 280's Arduino API in Rust: the vendor manual's section 2 (the functions of its
//! library MyCobotBasic: `powerOn`, `getAngles`, `writeAngles`, `jogAngle`, `setGripper`, ...)
//! as the methods of [`MyCobot`], each documented with the manual's name.
//!
//! `no_std` and allocation-free: it speaks through a [`BytePort`](protocol_core::BytePort)
//! (a UART on a board, a serial port or TCP socket on a PC) and a [`Clock`] the caller gives.
//! Every call is blocking with a deadline (500 ms unless set otherwise): it writes one request,
//! waits for the reply by polling the port and the clock, and returns the value typed in the
//! protocol's units ([`protocol_core::units`], [`protocol_core::command`]; [`convert`] turns
//! degrees and millimetres into them) or one [`Error`]: no reply in time, refused (with the
//! reason the robot gives), a malformed reply. Nothing panics on any reply.
//!
//! Both dialects of the host protocol are spoken (`docs/protocol.md` section 21): pymycobot's,
//! where every command is answered, and the manual's ("seed"), where a command without a
//! value is not answered and joints, servos and axes are numbered from 0 on the wire. The
//! calls take the same arguments in both; the frames differ.
//!
//! ```
//! use mycobot_api::convert::{angles, to_deg};
//! use mycobot_api::MyCobot;
//! use protocol_core::dialect::Dialect;
//! use protocol_core::units::SpeedPercent;
//! # use protocol_core::BytePort;
//! # use std::collections::VecDeque;
//! # /// An arm that answers get angles with (10, 20, -30, 15, -25, 40) deg, the rest `01`.
//! # #[derive(Default)]
//! # struct Arm { rx: VecDeque<u8> }
//! # impl BytePort for Arm {
//! #     fn read_byte(&mut self) -> Option<u8> { self.rx.pop_front() }
//! #     fn write(&mut self, b: &[u8]) {
//! #         let data: &[u8] = match b.get(3) {
//! #             Some(0x20) => &[3, 232, 7, 208, 244, 72, 5, 220, 246, 60, 15, 160],
//! #             _ => &[1],
//! #         };
//! #         let len = data.len() as u8 + 2;
//! #         self.rx.extend([0xFE, 0xFE, len, b[3]].iter().chain(data).chain(&[0xFA]));
//! #     }
//! #     fn tx_idle(&self) -> bool { true }
//! # }
//! # let port = Arm::default();
//! let start = std::time::Instant::now();
//! let clock = move || start.elapsed().as_micros() as u64;
//! let mut arm = MyCobot::new(port, clock, Dialect::Pymycobot);
//!
//! arm.power_on()?;
//! arm.write_angles(angles([10.0, 20.0, -30.0, 15.0, -25.0, 40.0]), SpeedPercent::MAX)?;
//! let now = arm.get_angles()?.map(to_deg);
//! assert_eq!(now, [10.0, 20.0, -30.0, 15.0, -25.0, 40.0]);
//! # Ok::<(), mycobot_api::Error>(())
//! ```
//!
//! Which calls exist, and what each sends: the [`MyCobot`] methods; [`MyCobot::request`]
//! sends any other command of [`protocol_core::command::Request`].
#![cfg_attr(not(any(test, feature = "std")), no_std)]
#![forbid(unsafe_code)]

mod calls;
pub mod convert;
mod error;
mod robot;
#[cfg(feature = "std")]
pub mod transport;

pub use calls::Angles;
pub use error::{Error, Reason};
pub use robot::{
    Call, Clock, DEFAULT_REPLY_TIMEOUT_US, MyCobot, POLL_READ_BUDGET, REPLY_FRAME_GAP_US,
};

#[cfg(test)]
mod tests;
