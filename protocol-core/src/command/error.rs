//! What can be wrong with a command, and the error codes the robot reports.
//!
//! * [`CommandError`]: a frame that arrived intact but is not a command we can execute.
//! * [`ErrorCode`]: the robot's error state, returned by get error information (0x07).
//! * [`ServoErrorCode`]: one servo's entry in read next error (0x15).

use super::types::JointId;

/// Why a well-formed frame is not a valid command. Each variant names the offending byte.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub enum CommandError {
    /// No command has this code.
    UnknownCommand {
        /// The CMD byte.
        cmd: u8,
    },
    /// The command exists but has no layout with this many data bytes.
    BadLength {
        /// The CMD byte.
        cmd: u8,
        /// Number of data bytes received (LEN - 2).
        data_len: u8,
    },
    /// A joint number outside 1..=6.
    BadJoint(u8),
    /// A servo id outside 1..=7 (or not the "all" value this command uses).
    BadServo(u8),
    /// A Cartesian axis outside 1..=6 (or an rpy axis outside 1..=3).
    BadAxis(u8),
    /// A jog direction other than 0/1.
    BadDirection(u8),
    /// A speed outside 1..=100 (0..=100 for the gripper).
    BadSpeed(u8),
    /// An on/off or mode byte outside its allowed values.
    BadFlag(u8),
    /// A GPIO number clients may not use for this command.
    BadPin(u8),
    /// An encoder value outside 0..=4096.
    BadEncoder(i16),
    /// A gripper opening outside 0..=100, state not 0/1/254, or type outside 1..=5.
    BadGripperValue(u8),
    /// A gripper torque (0x35) outside 150..=980 or protect current (0x39) outside 1..=500.
    BadGripperSetting(i16),
    /// A drag speed (0x3E) outside 0..=6000 steps/s.
    BadDragSpeed(i16),
    /// A write to a servo register below 5 (firmware version, model: read-only).
    BadAddress(u8),
    /// A collision threshold (0x75) outside 50..=250.
    BadThreshold(u8),
}

impl core::fmt::Display for CommandError {
    fn fmt(&self, f: &mut core::fmt::Formatter<'_>) -> core::fmt::Result {
        match *self {
            Self::UnknownCommand { cmd } => write!(f, "unknown command {cmd:#04x}"),
            Self::BadLength { cmd, data_len } => {
                write!(
                    f,
                    "command {cmd:#04x} has no layout with {data_len} data bytes"
                )
            }
            Self::BadJoint(v) => write!(f, "joint {v} is not 1..6"),
            Self::BadServo(v) => write!(f, "servo {v} is not 1..7"),
            Self::BadAxis(v) => write!(f, "axis {v} is out of range"),
            Self::BadDirection(v) => write!(f, "direction {v} is not 0/1"),
            Self::BadSpeed(v) => write!(f, "speed {v} is out of range"),
            Self::BadFlag(v) => write!(f, "flag/mode {v} is not allowed"),
            Self::BadPin(v) => write!(f, "pin {v} is not usable for this command"),
            Self::BadEncoder(v) => write!(f, "encoder {v} is not 0..4096"),
            Self::BadGripperValue(v) => write!(f, "gripper value {v} is out of range"),
            Self::BadGripperSetting(v) => write!(f, "gripper setting {v} is out of range"),
            Self::BadDragSpeed(v) => write!(f, "drag speed {v} is not 0..6000"),
            Self::BadAddress(v) => write!(f, "servo register {v} may not be accessed"),
            Self::BadThreshold(v) => write!(f, "collision threshold {v} is not 50..250"),
        }
    }
}

/// The robot's error state, the byte returned by get error information (0x07).
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Hash)]
pub enum ErrorCode {
    /// No error (0).
    #[default]
    None,
    /// A joint is at or beyond its limit (1..=6, the joint number).
    JointLimit(JointId),
    /// A collision was detected (16..=19; the value is 0..=3, code minus 16).
    Collision(u8),
    /// A joint's state readings stopped or jumped (its servo's replies late, lost or
    /// inconsistent), so the motion stopped: 21..=26, 20 + the joint number.
    StateLost(JointId),
    /// The pose has no inverse-kinematics solution (32).
    IkNoSolution,
    /// A linear move found no adjacent solution along the line (33 or 34; the value is 0 or
    /// 1, code minus 33).
    LinearNoAdjacentSolution(u8),
}

impl ErrorCode {
    /// The wire byte.
    pub const fn code(self) -> u8 {
        match self {
            Self::None => 0,
            Self::JointLimit(j) => j.get(),
            Self::Collision(n) => 16 + (n & 3),
            Self::StateLost(j) => 20 + j.get(),
            Self::IkNoSolution => 32,
            Self::LinearNoAdjacentSolution(n) => 33 + (n & 1),
        }
    }

    /// The error for a wire byte; `None` for a code this protocol does not define.
    pub const fn from_code(code: u8) -> Option<Self> {
        match code {
            0 => Some(Self::None),
            1..=6 => match JointId::new(code) {
                Some(j) => Some(Self::JointLimit(j)),
                None => None,
            },
            16..=19 => Some(Self::Collision(code - 16)),
            21..=26 => match JointId::new(code - 20) {
                Some(j) => Some(Self::StateLost(j)),
                None => None,
            },
            32 => Some(Self::IkNoSolution),
            33 | 34 => Some(Self::LinearNoAdjacentSolution(code - 33)),
            _ => None,
        }
    }
}

/// One servo's entry in the reply to read next error (0x15), seven bytes for servos 1..=7.
///
/// Our codes, chosen inside the ranges pymycobot 4.0.7 maps to its messages
/// (16..=22 "communication lost", 23..=28 "unstable", 32..=111 "servo fault"):
///
/// | code | meaning |
/// |---|---|
/// | 0 | no error |
/// | 16 | the servo did not answer (timeout) |
/// | 17 | the servo's answers are corrupt (bad checksum / wrong id / truncated) |
/// | 23 | the servo is not where it was sent (position error beyond tolerance) |
/// | 32 + bits | the servo reports a fault: bits = its status register (65) masked to its 6 fault bits (`servo::fault`: 1 voltage, 2 angle sensor, 4 overheat, 8 overcurrent, 32 overload), so 33..=95 |
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Hash)]
pub enum ServoErrorCode {
    /// No error (0).
    #[default]
    Ok,
    /// The servo did not answer (16).
    NoAnswer,
    /// The servo's answers are corrupt (17).
    BadAnswer,
    /// The servo is not where it was sent (23).
    PositionError,
    /// The servo's status register reports faults (32 + the fault bits, 0..=63).
    Fault(u8),
}

impl ServoErrorCode {
    /// Mask of the status-register bits carried in [`ServoErrorCode::Fault`].
    pub const FAULT_MASK: u8 = 0x3F;

    /// The wire byte.
    pub const fn code(self) -> u8 {
        match self {
            Self::Ok => 0,
            Self::NoAnswer => 16,
            Self::BadAnswer => 17,
            Self::PositionError => 23,
            Self::Fault(bits) => 32 + (bits & Self::FAULT_MASK),
        }
    }

    /// The entry for a wire byte; `None` for a code this scheme does not define.
    pub const fn from_code(code: u8) -> Option<Self> {
        match code {
            0 => Some(Self::Ok),
            16 => Some(Self::NoAnswer),
            17 => Some(Self::BadAnswer),
            23 => Some(Self::PositionError),
            32..=95 => Some(Self::Fault(code - 32)),
            _ => None,
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn error_codes_round_trip_and_match_protocol_md() {
        for code in 0..=255u8 {
            if let Some(e) = ErrorCode::from_code(code) {
                assert_eq!(e.code(), code);
            }
        }
        assert_eq!(ErrorCode::IkNoSolution.code(), 32);
        assert_eq!(ErrorCode::JointLimit(JointId::new(6).unwrap()).code(), 6);
        assert_eq!(ErrorCode::from_code(7), None);
        assert_eq!(ErrorCode::from_code(20), None);
        assert_eq!(ErrorCode::from_code(27), None);
        assert_eq!(
            ErrorCode::StateLost(JointId::new(3).unwrap()).code(),
            23,
            "joint 3's readings stopped"
        );
        assert_eq!(
            ErrorCode::from_code(34),
            Some(ErrorCode::LinearNoAdjacentSolution(1))
        );
    }

    #[test]
    fn servo_error_codes_land_in_pymycobot_ranges() {
        assert!((16..=22).contains(&ServoErrorCode::NoAnswer.code()));
        assert!((16..=22).contains(&ServoErrorCode::BadAnswer.code()));
        assert!((23..=28).contains(&ServoErrorCode::PositionError.code()));
        for bits in 0..=u8::MAX {
            let code = ServoErrorCode::Fault(bits).code();
            assert!((32..=111).contains(&code), "bits {bits} -> {code}");
            assert_eq!(
                ServoErrorCode::from_code(code),
                Some(ServoErrorCode::Fault(bits & ServoErrorCode::FAULT_MASK))
            );
        }
    }
}
