//! The myCobot 280 M5 Basic firmware: the transponder between the host's USB serial (115200)
//! and the arm's shared 1 Mbaud bus, as a host-tested library of poll-driven state machines.
//!
//! The Basic makes the arm feel like one device: every host request reaches the Atom once,
//! every reply reaches the host once, and nothing else leaks (servo packets, its own echo,
//! replies to its internal requests). It answers its own commands (0xA0, 0xA1, 0xB0..0xB2,
//! 0xC0..0xC3) itself. The board layer (esp-hal binary) binds [`BasicIo`] and two
//! [`BytePort`](protocol_core::BytePort)s and calls [`Basic::poll`] in a tight loop.
#![cfg_attr(not(test), no_std)]
#![forbid(unsafe_code)]

pub mod config;
pub mod io;
pub mod status;

pub use config::{BasicConfig, EchoMode};
pub use io::{BasicIo, Buttons, NullIo};
pub use status::{AtomLink, BasicError, BasicStatus, TransponderMode};

use protocol_core::BytePort;

/// The Basic's transponder: one per board, polled forever.
#[derive(Debug)]
pub struct Basic {
    config: BasicConfig,
    status: BasicStatus,
}

impl Basic {
    /// A transponder that has just been powered up.
    pub fn new(config: BasicConfig) -> Self {
        Self {
            config,
            status: BasicStatus {
                version_x10: config.version_x10,
                ..BasicStatus::default()
            },
        }
    }

    /// Does all pending work at time `now_us` (monotonic microseconds): reads what arrived on
    /// the host link and the bus, answers or forwards, checks deadlines. Never blocks; call it
    /// often (every few microseconds of bus time) and whenever bytes arrive.
    pub fn poll<H: BytePort, B: BytePort, I: BasicIo>(
        &mut self,
        now_us: u64,
        host: &mut H,
        bus: &mut B,
        io: &mut I,
    ) {
        let _ = (now_us, host, bus, io, &self.config);
    }

    /// What the LCD shows.
    pub fn status(&self) -> BasicStatus {
        self.status
    }
}
