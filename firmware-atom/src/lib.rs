//! The myCobot 280 M5 Atom firmware as a hardware-free library.
//!
//! The Atom is the brain of the arm: it owns the shared 1 Mbaud bus, answers the host commands
//! of `protocol.md`, drives the six joint servos and the gripper (`servo-bus.md`), the LEDs and
//! the user pins, and runs the kinematics. Everything here is a state machine polled with the
//! time ([`Atom::poll`]); the board layer (`src/bin`) and the virtual robot bind the traits
//! ([`protocol_core::BytePort`], [`AtomIo`]) to hardware or to a simulation.
#![cfg_attr(not(test), no_std)]
#![forbid(unsafe_code)]

mod atom;
pub mod bus;
pub mod cartesian;
mod commands;
pub mod config;
pub mod driver;
pub mod health;
pub mod io;
pub mod motion;
pub mod safety;

pub use atom::Atom;
pub use config::{AtomConfig, ConfigError, JointLimit, JointSign, TimingBudget};
pub use health::ServoHealth;
pub use io::{AtomIo, PinMode, RecordingIo};
