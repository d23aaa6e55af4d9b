//! [`Error`]: what can go wrong with a call, with the robot's reason where it gave one.

use protocol_core::command::ErrorCode;

/// Why a call did not return its value. `cmd` is the request's command code
/// ([`Request::cmd`](protocol_core::command::Request::cmd), pymycobot's numbering).
///
/// `Display` writes one line a person can act on, the refusal's reason included:
///
/// ```
/// use mycobot_api::Error;
/// use protocol_core::command::{ErrorCode, JointId};
///
/// let refused = Error::Refused {
///     cmd: 0x21,
///     code: JointId::new(3).map(ErrorCode::JointLimit),
/// };
/// assert_eq!(
///     refused.to_string(),
///     "command 0x21 refused: joint 3 is at or beyond its limit"
/// );
/// ```
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
#[non_exhaustive]
pub enum Error {
    /// No reply with the request's CMD came before the deadline
    /// ([`MyCobot::set_reply_timeout_us`](crate::MyCobot::set_reply_timeout_us), 500 ms by
    /// default).
    Timeout {
        /// The request's command code.
        cmd: u8,
    },
    /// The robot answered `00`: the request was refused and nothing changed.
    Refused {
        /// The request's command code.
        cmd: u8,
        /// What get error information (0x07) said after the refusal; `None` if it said "no
        /// error" or could not be read. It is the last error the robot recorded: a refusal
        /// without a code of its own (powered off, busy) leaves an older one in place
        /// (`docs/protocol.md` section 7).
        code: Option<ErrorCode>,
    },
    /// A reply with the request's CMD came, but not in the shape the request expects (wrong
    /// length, impossible value).
    BadReply {
        /// The request's command code.
        cmd: u8,
    },
    /// The request has no frame in the dialect spoken: in the seed dialect, is paused,
    /// release servo and is in position with angles
    /// ([`Dialect::encode`](protocol_core::dialect::Dialect::encode)).
    NotInDialect {
        /// The request's command code.
        cmd: u8,
    },
}

impl Error {
    /// The command code of the request that failed.
    pub const fn cmd(&self) -> u8 {
        match *self {
            Self::Timeout { cmd }
            | Self::Refused { cmd, .. }
            | Self::BadReply { cmd }
            | Self::NotInDialect { cmd } => cmd,
        }
    }
}

impl core::fmt::Display for Error {
    fn fmt(&self, f: &mut core::fmt::Formatter<'_>) -> core::fmt::Result {
        match *self {
            Self::Timeout { cmd } => write!(f, "no reply to command {cmd:#04x} in time"),
            Self::Refused { cmd, code: None } => write!(f, "command {cmd:#04x} refused"),
            Self::Refused {
                cmd,
                code: Some(code),
            } => {
                write!(f, "command {cmd:#04x} refused: ")?;
                describe(code, f)
            }
            Self::BadReply { cmd } => write!(f, "the reply to command {cmd:#04x} is malformed"),
            Self::NotInDialect { cmd } => {
                write!(f, "command {cmd:#04x} has no frame in this dialect")
            }
        }
    }
}

impl core::error::Error for Error {}

/// What an error code means, in words (`docs/protocol.md` section 7), as a refusal's
/// `Display` gives it.
///
/// ```
/// use mycobot_api::Reason;
/// use protocol_core::command::ErrorCode;
///
/// assert_eq!(
///     Reason(ErrorCode::IkNoSolution).to_string(),
///     "no inverse-kinematics solution for the pose"
/// );
/// ```
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct Reason(pub ErrorCode);

impl core::fmt::Display for Reason {
    fn fmt(&self, f: &mut core::fmt::Formatter<'_>) -> core::fmt::Result {
        describe(self.0, f)
    }
}

/// The meaning of an error code (`docs/protocol.md` section 7).
fn describe(code: ErrorCode, f: &mut core::fmt::Formatter<'_>) -> core::fmt::Result {
    match code {
        ErrorCode::None => f.write_str("no error recorded"),
        ErrorCode::JointLimit(j) => write!(f, "joint {} is at or beyond its limit", j.get()),
        ErrorCode::Collision(0) => f.write_str("collision while moving the joints"),
        ErrorCode::Collision(1) => f.write_str("collision while moving in a line or arc"),
        ErrorCode::Collision(2) => f.write_str("collision while holding still"),
        ErrorCode::Collision(_) => f.write_str("collision"),
        ErrorCode::StateLost(j) => write!(
            f,
            "joint {} has no trustworthy reading (its servo's replies stopped or jumped)",
            j.get()
        ),
        ErrorCode::IkNoSolution => f.write_str("no inverse-kinematics solution for the pose"),
        ErrorCode::LinearNoAdjacentSolution(0) => {
            f.write_str("the path has no adjacent solution (or the arc no circle)")
        }
        ErrorCode::LinearNoAdjacentSolution(_) => {
            f.write_str("the path meets a point without a solution")
        }
    }
}
