//! The simulation core of the virtual robot: wires with byte timing, Feetech STS servos, and
//! the whole arm under virtual time.
//!
//! * [`wire`]: the shared 1 Mbaud half-duplex bus (every station hears every byte, overlapping
//!   transmissions garble each other, echo per station) and 115200 serial lines.
//! * [`servo`]: a simulated STS servo: control table, instructions, trapezoidal motion, faults,
//!   contact (obstacles, pushes, the load they cause).
//! * [`contact`]: obstacles in a joint's way (`--obstacle J:DEG`).
//! * [`reply_faults`]: a servo's answers late or lost (`--late-replies ID:US`,
//!   `--lost-replies ID:PER_MILLE`).
//! * [`busy_client`]: a client that sends request after request and counts late and lost
//!   answers.
//! * [`hops`]: where the time of a host round trip through the Basic goes, hop by hop.
//! * [`external`]: the same bus and servos serving boards that run elsewhere (the real images on
//!   an emulated chip), whole frames in and the bus's bytes, echo included, out.
//! * [`VirtualRobot`]: the real `firmware_basic::Basic` and `firmware_atom::Atom` wired to seven
//!   servos; time advances only in [`VirtualRobot::run_until`], as fast as the host can.
//!
//! What a test or a tool can do with it:
//!
//! * talk like a host: [`VirtualRobot::host_write`] / [`VirtualRobot::host_read`] (the Basic's
//!   USB), [`VirtualRobot::link_write`] / [`VirtualRobot::link_read`] (either board's USB, or
//!   a network client of the Basic from [`VirtualRobot::connect`]: several at once, each with
//!   its own answers), or one request at a time with [`VirtualRobot::ask`],
//!   [`VirtualRobot::transact`] and [`VirtualRobot::await_frame`];
//! * drive it in real time: call [`VirtualRobot::run_until`] with the wall clock;
//! * break things: [`SimServo::set_faults`] (no answer, bad checksum, stall, overheat,
//!   answers late or lost: [`Faults::reply_delay_us`], [`Faults::dropped_per_mille`]),
//!   [`SimServo::drop_next_answers`], [`SimServo::power_cycle`], [`SimServo::move_by_hand`], [`VirtualRobot::inject_bus_noise`],
//!   [`VirtualRobot::reset_atom`], [`VirtualRobot::reset_basic`], [`VirtualRobot::add_obstacle`]
//!   and [`VirtualRobot::push_joint`] (contact, felt by the Atom's collision protection,
//!   [`VirtualRobot::collisions`]), and [`RobotConfig`] for echo
//!   wiring, a robot without a Basic, a slow Atom ([`RobotConfig::atom_loop_us`]), and the
//!   firmware configurations;
//! * look: [`VirtualRobot::measured_angles`] (where the shafts really are),
//!   [`VirtualRobot::shaft_angles_deg`] and [`measure`] (the flange's true pose), the servos' tables
//!   and [`ServoStats`], and every byte on the bus with its sender and times
//!   ([`Bus::set_tracing`], [`Bus::take_trace`]).
//!
//! ```
//! use open_mycobot::sim::{RobotConfig, VirtualRobot};
//!
//! let mut robot = VirtualRobot::new(RobotConfig::default());
//! robot.run_for(1_000);
//! assert_eq!(robot.now_us(), 1_000);
//! assert_eq!(robot.servo(1).map(|s| s.present_position()), Some(2048));
//! ```

pub mod arg_error;
mod basic_flash;
pub mod busy_client;
pub mod contact;
pub mod external;
pub mod flash_timing;
pub mod hops;
pub mod measure;
pub mod reply_faults;
mod robot;

pub use sim_hw::{servo, wire};

pub use basic_flash::{BASIC_FLASH_BYTES, BasicFlash, BasicFlashStore};
pub use busy_client::BusyClient;
pub use flash_timing::FlashTiming;
pub use robot::{
    AskError, BasicProgram, HostLink, NET_BUFFER_BYTES, NetClient, POLL_PERIOD_NS, RobotConfig,
    SERVO_IDS, SimBasicIo, VirtualRobot,
};
pub use servo::{Faults, PacketListener, ServoStats, SimServo};
pub use wire::{Bus, BusByte, HeardByte, LineByte, SerialLine, StationId};
