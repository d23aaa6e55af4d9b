//! Why the Atom did not do what it was asked: the one error type of the application, mapped
//! once onto the error codes get error information (0x07) reports ([`AtomError::error_code`]).

use kinematics_core::{IkError, PathError};
use protocol_core::command::{ErrorCode, JointId};

use crate::collision::Kind;

/// Why a command or a motion was not carried out. A refused command answers `00` and changes
/// nothing; a motion that fails on the way stops the arm. Either way the error is recorded for
/// 0x07 where the protocol has a code for it.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum AtomError {
    /// The arm is powered off (0x11): no goal may be sent.
    PoweredOff,
    /// Joint `index` (0-based) would leave its limits.
    JointLimit(usize),
    /// A gripper goal is not an encoder position (0..4095).
    GripperRange,
    /// The pose has no inverse-kinematics solution.
    Unreachable,
    /// A Cartesian path cannot go on: no adjacent solution (a branch jump) or an unreachable
    /// point on the way.
    Path(PathError),
    /// A queue is full; the host may retry.
    Busy,
    /// The command cannot be carried out for another reason (bad register, missing servo).
    Invalid,
    /// A collision stopped the arm ([`crate::collision`]); motion is refused until cleared.
    Collision(Kind),
    /// Joint `index` (0-based) has no trustworthy state reading: its servo's replies stopped
    /// coming for longer than [`crate::bank::FRESH_STATE_US`], or its last reading jumped
    /// further than the servo can turn in the time since the one before. The motion stopped
    /// (or did not start) rather than guess where the joint is.
    StateLost(usize),
}

impl AtomError {
    /// The error code 0x07 reports for this failure (`docs/protocol.md` section 7), if it has one:
    /// 1..=6 joint limit, 16..=18 a collision ([`Kind::code`]), 21..=26 a joint's state
    /// readings stopped or jumped (20 + the joint number), 32 unreachable pose, 33 / 34 no
    /// continuous path (or an arc without a circle, 33).
    pub fn error_code(self) -> Option<ErrorCode> {
        match self {
            Self::JointLimit(j) => u8::try_from(j + 1)
                .ok()
                .and_then(JointId::new)
                .map(ErrorCode::JointLimit),
            Self::Unreachable => Some(ErrorCode::IkNoSolution),
            Self::Path(e) => ErrorCode::from_code(e.protocol_code()),
            Self::Collision(kind) => ErrorCode::from_code(kind.code()),
            Self::StateLost(j) => u8::try_from(j + 1)
                .ok()
                .and_then(JointId::new)
                .map(ErrorCode::StateLost),
            Self::PoweredOff | Self::GripperRange | Self::Busy | Self::Invalid => None,
        }
    }
}

impl From<IkError> for AtomError {
    fn from(_: IkError) -> Self {
        Self::Unreachable
    }
}

impl From<PathError> for AtomError {
    fn from(e: PathError) -> Self {
        Self::Path(e)
    }
}

/// The error state 0x07 reports: the last recorded error until cleared (0x08).
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct ErrorLog {
    last: ErrorCode,
}

impl ErrorLog {
    /// Records `e` if it has a code; errors without one leave the state as it was.
    pub fn record(&mut self, e: AtomError) {
        if let Some(code) = e.error_code() {
            self.last = code;
        }
    }

    /// Records the outcome of an action if it failed; gives the outcome back.
    pub fn note<T>(&mut self, outcome: Result<T, AtomError>) -> Result<T, AtomError> {
        if let Err(e) = &outcome {
            self.record(*e);
        }
        outcome
    }

    /// The wire byte of 0x07 (0 = no error).
    pub fn code(&self) -> u8 {
        self.last.code()
    }

    /// Forgets the error (0x08).
    pub fn clear(&mut self) {
        self.last = ErrorCode::None;
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn each_error_maps_to_its_protocol_code_in_one_place() {
        assert_eq!(
            AtomError::JointLimit(0).error_code().map(ErrorCode::code),
            Some(1)
        );
        assert_eq!(
            AtomError::JointLimit(5).error_code().map(ErrorCode::code),
            Some(6)
        );
        assert_eq!(AtomError::JointLimit(6).error_code(), None);
        assert_eq!(
            AtomError::StateLost(1).error_code().map(ErrorCode::code),
            Some(22)
        );
        assert_eq!(AtomError::StateLost(6).error_code(), None);
        assert_eq!(
            AtomError::Unreachable.error_code().map(ErrorCode::code),
            Some(32)
        );
        let jump = AtomError::Path(PathError::BranchJump { joint: 2 });
        assert_eq!(jump.error_code().map(ErrorCode::code), Some(33));
        let step = AtomError::Path(PathError::StepUnreachable(IkError::Unreachable));
        assert_eq!(step.error_code().map(ErrorCode::code), Some(34));
        for e in [AtomError::PoweredOff, AtomError::Busy, AtomError::Invalid] {
            assert_eq!(e.error_code(), None);
        }
    }

    #[test]
    fn the_log_keeps_the_last_coded_error_until_cleared() {
        let mut log = ErrorLog::default();
        log.record(AtomError::Unreachable);
        log.record(AtomError::Busy);
        assert_eq!(log.code(), 32);
        log.clear();
        assert_eq!(log.code(), 0);
    }
}
