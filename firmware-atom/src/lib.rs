//! The myCobot 280 M5 Atom firmware as a hardware-free library.
//!
//! The Atom is the brain of the arm: it owns the shared 1 Mbaud bus, answers the host commands
//! of `docs/protocol.md`, drives the six joint servos and the gripper (`docs/servo-bus.md`), the
//! LEDs and the user pins, and runs the kinematics. Everything here is a state machine polled
//! with the time ([`Atom::poll`]); the board layer (`src/bin`) and the virtual robot bind the traits
//! ([`protocol_core::BytePort`], [`AtomIo`]) to hardware or to a simulation.
//!
//! # Behaviour a client sees
//! * **Replies.** Every request gets exactly one reply with its CMD byte, sent as soon as the
//!   request's last byte is in (from cached state); only get servo data (0x53), get PID (0x2D)
//!   and backup / restore (0xEA / 0xEB) wait for servo reads (bounded by the retries below).
//!   Set commands answer `01` when accepted and `00` when refused; a refusal changes nothing
//!   and, where `protocol.md` has a code, records it for 0x07 (1..6 joint limit, 32 unreachable
//!   pose, 33/34 a line, jog or arc). Invalid frames (unknown code, wrong length, value out of
//!   range) answer `00`.
//! * **State** (angles, coords, encoders, speeds, voltages, temperatures, faults) comes from
//!   the servos: registers 40..=70 of every servo are read in turn (one READ each), about 225
//!   rounds per second (bench `latency`). Coordinates are the forward kinematics of the present
//!   angles; a value that rounding alone put 0.1 mm past pymycobot's bounds (the zero pose's
//!   z = 412.67 mm) is reported at the bound, so a pose read back can always be sent again
//!   ([`cartesian::for_client`]). The same read gives back each servo's torque and goal registers: a goal or torque
//!   write lost on the shared wire (a SYNC WRITE has no answer) is re-sent, at most 3 times per
//!   command.
//! * **Shared wire.** Host replies go out in the gap between servo transactions; a reply whose
//!   echo comes back garbled (collision) is sent again once the wire is quiet, up to twice, so
//!   the host never has to resend (and never repeats an incremental jog).
//! * **Safety.** Every position goal passes one check ([`safety::check`]): power on, joint
//!   limits (settable with 0x4C/0x4D), encoder range. No path bypasses it.
//! * **Motion.** Joint moves scale each joint's speed and ramp by its share of the longest
//!   travel, so all joints arrive together. Coordinate moves are joint-interpolated (mode 0) or
//!   stepped along a straight line every 20 ms (mode 1). Fresh mode (default 1) lets a new move
//!   replace the current one; mode 0 queues up to 16 moves.
//! * **Jog watchdog.** A continuous jog (0x30..0x32) stops when no host command has arrived
//!   for 2 s ([`TimingBudget::jog_watchdog_us`]): pymycobot has no keep-alive, so a script
//!   that jogs, sleeps a second and stops still works, while a lost link moves a joint for at
//!   most 2 s. Any command counts as a sign of life except is powered on (0x12), which the
//!   Basic sends by itself as its liveness probe. Jog stop (0x34 LEN 2), stop (0x29) or any
//!   new motion end it earlier.
//! * **Gripper** (servo 7): value 0 (closed) ..= 100 (open) maps linearly onto the encoder
//!   range [`config::GripperRange`] (default 2048 ..= 3072); calibration (0x68) makes the
//!   present position the new closed end (the servo's present position becomes 2048).
//! * **Servo health.** A servo that misses 3 state reads in a row is reported not answering
//!   (0x50, 0x51, 0xE4 reads 0xFF, 0x15 code 16, or 17 when its answers are corrupt) and then
//!   probed only every 8th round, so it costs the others almost nothing; fault bits show in
//!   0xE4 and 0x15 (32 + bits). Raw register writes (0x52) may not change a servo's id or baud
//!   rate; EEPROM registers are unlocked and locked around the write.
//! * **Free mode** (0x1A 1): holding the Atom's button releases the joints so the arm can be
//!   moved by hand; letting go holds it where it is.
//! * **Drag teaching** (0xF1..0xF5): every joint's encoder and speed recorded 20 times a second
//!   into 1 000 points, read back one point per request ([`drag`]).
//! * **Move round** (0xD4) turns the accessory hobby servo (the Connect-4 kit's dispenser, on
//!   the Grove port) one revolution; set four pieces zero (0xD7) stops it ([`dispenser`]).
//! * **Circular arcs** (0x8B, 0x8C): along the circle through three poses, walked whole with
//!   the inverse kinematics before the arm moves ([`motion`]).
//! * **MyCobotBasic's layouts**: send coord's axis byte 0 is x (the seed manual's numbering; 1..6
//!   stay pymycobot's x..rz); set / get PID (0x2C / 0x2D) write and read the joint servos' P, I,
//!   D registers, six bytes for joints 1..3 and 4..6.
#![cfg_attr(not(test), no_std)]
#![forbid(unsafe_code)]

mod atom;
pub mod backup;
mod bank;
pub mod cartesian;
pub mod collision;
mod commands;
pub mod config;
pub mod context;
pub mod dispenser;
pub mod drag;
pub mod driver;
pub mod error;
pub mod flash_writes;
mod gains;
mod gripper;
pub mod health;
pub mod io;
mod link;
pub mod motion;
mod parts;
mod registers;
pub mod safety;
mod schedule;
mod settings;
pub mod store;
pub mod tolerance;
mod waiting;

pub use atom::Atom;
pub use config::{AtomConfig, ConfigError, JointLimit, JointSign, TimingBudget};
pub use error::AtomError;
pub use health::ServoHealth;
pub use io::{AtomIo, PinMode, RecordingIo, Wiring};
