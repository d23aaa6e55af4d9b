//! The command line: global options and one subcommand.

use std::str::FromStr;

use clap::{Parser, Subcommand, ValueEnum};
use protocol_core::command::{Axis, Direction, JointId, ServoId, ServoSelect};
use protocol_core::dialect::Dialect;

/// Drives a myCobot 280 (M5) from a shell: over its USB serial (`--port`), its Wi-Fi server or
/// the virtual robot's TCP port (`--tcp`). Angles are in degrees, x y z in millimetres.
/// Values may be negative: `mycobot --port /dev/ttyUSB0 move-angles 10 20 -30 15 -25 40`.
#[derive(Debug, Parser)]
#[command(name = "mycobot", version, about)]
pub struct Cli {
    /// The robot's serial port, or --tcp: one is needed (the Basic's USB serial, e.g. /dev/ttyUSB0, or the virtual
    /// robot's pseudo-terminal or its --pty-link, e.g. /tmp/mycobot), opened at 115200 8N1.
    #[arg(long, value_name = "PATH", global = true)]
    pub port: Option<String>,

    /// The robot's TCP server: the Basic's Wi-Fi server or the virtual robot's --tcp, e.g.
    /// 127.0.0.1:9000.
    #[arg(long, value_name = "HOST:PORT", global = true)]
    pub tcp: Option<String>,

    /// The protocol dialect the robot's Basic speaks: pymycobot's, or the vendor manual's.
    #[arg(long, value_enum, default_value_t = DialectArg::Pymycobot, global = true)]
    pub dialect: DialectArg,

    /// How long to wait for each reply, in milliseconds.
    #[arg(long, value_name = "MS", default_value_t = 500, global = true)]
    pub timeout_ms: u64,

    /// What to do.
    #[command(subcommand)]
    pub command: Command,
}

impl Cli {
    /// What is wrong with the link options, if anything: one of `--port` and `--tcp` is
    /// needed. (Checked here: clap checks a group of global options only where they were
    /// given, before or after the subcommand.)
    pub fn link_problem(&self) -> Option<&'static str> {
        match (&self.port, &self.tcp) {
            (None, None) => Some("give the robot's --port PATH or --tcp HOST:PORT"),
            (Some(_), Some(_)) => Some("give --port PATH or --tcp HOST:PORT, not both"),
            _ => None,
        }
    }
}

/// A protocol dialect, as the command line names it.
#[derive(Debug, Clone, Copy, PartialEq, Eq, ValueEnum)]
pub enum DialectArg {
    /// pymycobot's protocol (every command answered).
    Pymycobot,
    /// The vendor manual's protocol ("seed": set commands unanswered).
    Seed,
}

impl From<DialectArg> for Dialect {
    fn from(arg: DialectArg) -> Self {
        match arg {
            DialectArg::Pymycobot => Self::Pymycobot,
            DialectArg::Seed => Self::Seed,
        }
    }
}

/// The subcommands.
#[derive(Debug, Subcommand)]
pub enum Command {
    /// Powered on?, firmware versions, angles, coordinates, the last error, moving?
    Status,
    /// The six joint angles in degrees, on one line.
    Angles,
    /// The end's pose on one line: x y z in mm, rx ry rz in degrees.
    Coords,
    /// Moves the six joints to angles A1..A6 (degrees), and waits until the arm is there.
    #[command(allow_negative_numbers = true)]
    MoveAngles {
        /// The six angles, joints 1..6, in degrees.
        #[arg(num_args = 6, value_names = ["A1", "A2", "A3", "A4", "A5", "A6"], required = true)]
        angles: Vec<f32>,
        /// The move's options.
        #[command(flatten)]
        motion: MotionArgs,
    },
    /// Moves the end to a pose (x y z in mm, rx ry rz in degrees), and waits until it is there.
    #[command(allow_negative_numbers = true)]
    MoveCoords {
        /// The pose: X Y Z RX RY RZ.
        #[arg(num_args = 6, value_names = ["X", "Y", "Z", "RX", "RY", "RZ"], required = true)]
        pose: Vec<f32>,
        /// In a straight line (otherwise joint-interpolated).
        #[arg(long)]
        linear: bool,
        /// The move's options.
        #[command(flatten)]
        motion: MotionArgs,
    },
    /// Turns one joint, or moves the end along or about one axis: for `--for SECONDS`, then
    /// stops. Without `--for` it returns at once, and the arm goes on until `mycobot stop`, a
    /// limit, or the firmware's jog watchdog (2 s after the last command it received).
    Jog {
        /// A joint (1..6, or j1..j6) or an axis (x, y, z, rx, ry, rz).
        target: JogTarget,
        /// Which way: + (or pos) for increasing, - (or neg) for decreasing.
        #[arg(allow_hyphen_values = true)]
        direction: DirectionArg,
        /// Speed in percent, 1..100.
        #[arg(long, default_value_t = 50, value_parser = clap::value_parser!(u8).range(1..=100))]
        speed: u8,
        /// Jog for SECONDS (asking the arm where it is now and then, which keeps the jog
        /// going), then stop.
        #[arg(long = "for", value_name = "SECONDS")]
        duration: Option<f32>,
    },
    /// Stops every motion (brakes; queued and paused motions are forgotten).
    Stop,
    /// Opens or closes the gripper, or sets its opening 0 (closed)..100 (open).
    Gripper {
        /// open, close, release (torque off) or a value 0..100.
        action: GripperArg,
        /// Gripper speed in percent, 1..100.
        #[arg(long, default_value_t = 50, value_parser = clap::value_parser!(u8).range(1..=100))]
        speed: u8,
    },
    /// Sets the Atom's LED colour.
    Led {
        /// Red, 0..255.
        r: u8,
        /// Green, 0..255.
        g: u8,
        /// Blue, 0..255.
        b: u8,
    },
    /// Backs up the servo parameters (in the Atom's flash) of one servo or all.
    Backup {
        /// A servo, 1..7 (7: the gripper), or all.
        #[arg(default_value = "all")]
        servo: ServoArg,
    },
    /// Restores the servo parameters backed up, of one servo or all.
    Restore {
        /// A servo, 1..7 (7: the gripper), or all.
        #[arg(default_value = "all")]
        servo: ServoArg,
    },
    /// A live table of the angles, coordinates and errors, until Ctrl-C.
    Watch {
        /// Milliseconds between rows.
        #[arg(long, value_name = "MS", default_value_t = 200)]
        interval_ms: u64,
        /// Stop after N rows.
        #[arg(long, value_name = "N")]
        count: Option<u64>,
    },
}

/// The options of a move.
#[derive(Debug, clap::Args)]
pub struct MotionArgs {
    /// Speed in percent, 1..100.
    #[arg(long, default_value_t = 50, value_parser = clap::value_parser!(u8).range(1..=100))]
    pub speed: u8,
    /// Return once the command is sent, without waiting for the arm to arrive.
    #[arg(long)]
    pub no_wait: bool,
    /// Give up waiting after SECONDS (the arm is still moving, or cannot get there).
    #[arg(long, value_name = "SECONDS", default_value_t = 60.0)]
    pub wait_timeout: f32,
}

/// What `jog` moves.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum JogTarget {
    /// A joint.
    Joint(JointId),
    /// A base axis.
    Axis(Axis),
}

impl FromStr for JogTarget {
    type Err = String;

    fn from_str(s: &str) -> Result<Self, String> {
        let lower = s.to_ascii_lowercase();
        let axis = match lower.as_str() {
            "x" => Some(Axis::X),
            "y" => Some(Axis::Y),
            "z" => Some(Axis::Z),
            "rx" => Some(Axis::Rx),
            "ry" => Some(Axis::Ry),
            "rz" => Some(Axis::Rz),
            _ => None,
        };
        if let Some(axis) = axis {
            return Ok(Self::Axis(axis));
        }
        lower
            .strip_prefix('j')
            .unwrap_or(&lower)
            .parse::<u8>()
            .ok()
            .and_then(JointId::new)
            .map(Self::Joint)
            .ok_or_else(|| format!("{s}: not a joint (1..6) nor an axis (x, y, z, rx, ry, rz)"))
    }
}

/// A jog direction.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct DirectionArg(pub Direction);

impl FromStr for DirectionArg {
    type Err = String;

    fn from_str(s: &str) -> Result<Self, String> {
        match s.to_ascii_lowercase().as_str() {
            "+" | "pos" | "positive" | "up" => Ok(Self(Direction::Positive)),
            "-" | "neg" | "negative" | "down" => Ok(Self(Direction::Negative)),
            _ => Err(format!("{s}: the direction is + (pos) or - (neg)")),
        }
    }
}

/// What `gripper` does.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum GripperArg {
    /// Open fully.
    Open,
    /// Close fully.
    Close,
    /// Torque off.
    Release,
    /// To an opening in percent.
    Value(u8),
}

impl FromStr for GripperArg {
    type Err = String;

    fn from_str(s: &str) -> Result<Self, String> {
        match s.to_ascii_lowercase().as_str() {
            "open" => Ok(Self::Open),
            "close" => Ok(Self::Close),
            "release" => Ok(Self::Release),
            v => v
                .parse::<u8>()
                .ok()
                .filter(|v| *v <= 100)
                .map(Self::Value)
                .ok_or_else(|| format!("{s}: open, close, release or a value 0..100")),
        }
    }
}

/// A servo or all of them.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct ServoArg(pub ServoSelect);

impl FromStr for ServoArg {
    type Err = String;

    fn from_str(s: &str) -> Result<Self, String> {
        if s.eq_ignore_ascii_case("all") {
            return Ok(Self(ServoSelect::All));
        }
        s.parse::<u8>()
            .ok()
            .and_then(ServoId::new)
            .map(|id| Self(ServoSelect::One(id)))
            .ok_or_else(|| format!("{s}: a servo is 1..7 or all"))
    }
}

#[cfg(test)]
mod tests {
    #![allow(clippy::unwrap_used, clippy::expect_used, clippy::indexing_slicing)] // tests: a panic is a failed check

    use clap::CommandFactory;

    use super::*;

    #[test]
    fn the_command_line_is_consistent() {
        Cli::command().debug_assert();
    }

    #[test]
    fn negative_values_are_values() {
        let cli = Cli::try_parse_from([
            "mycobot",
            "--port",
            "/tmp/x",
            "move-angles",
            "10",
            "20",
            "-30",
            "15",
            "-25",
            "40",
        ])
        .unwrap();
        let Command::MoveAngles { angles, motion } = cli.command else {
            panic!("{:?}", cli.command)
        };
        assert_eq!(angles, [10.0, 20.0, -30.0, 15.0, -25.0, 40.0]);
        assert_eq!(motion.speed, 50);
        let cli =
            Cli::try_parse_from(["mycobot", "--tcp", "h:1", "jog", "j2", "-", "--for", "0.5"])
                .unwrap();
        let Command::Jog {
            target, direction, ..
        } = cli.command
        else {
            panic!("{:?}", cli.command)
        };
        assert_eq!(target, JogTarget::Joint(JointId::new(2).unwrap()));
        assert_eq!(direction, DirectionArg(Direction::Negative));
    }

    #[test]
    fn a_port_or_an_address_is_required_and_not_both() {
        let problem = |args: &[&str]| Cli::try_parse_from(args).unwrap().link_problem();
        assert!(problem(&["mycobot", "angles"]).is_some());
        assert!(problem(&["mycobot", "--port", "a", "--tcp", "b:1", "angles"]).is_some());
        assert!(problem(&["mycobot", "--port", "a", "angles", "--tcp", "b:1"]).is_some());
        assert!(problem(&["mycobot", "angles", "--tcp", "b:1"]).is_none());
        assert!(Cli::try_parse_from(["mycobot", "angles", "--port", "a"]).is_ok());
    }
}
