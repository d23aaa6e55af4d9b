//! What the host has set: joint limits, fresh/free mode, the default speed, the coordinate
//! frames and collision protection. The fields are private and every setter keeps what depends on them in step: a new
//! limit is checked against the factory range and handed to the kinematics' branch selection,
//! a new frame is re-applied to the kinematics model. Values the protocol layer has already
//! range-checked (speed, modes) are taken as they come.

use protocol_core::command::{EndType, MoveMode, Pose, ReferenceFrame};
use protocol_core::units::{Centideg, Decideg, Steps};

use crate::cartesian::Cartesian;
use crate::collision::{CollisionSettings, DEFAULT_PROTECTION};
use crate::config::{AtomConfig, FACTORY_LIMITS, JOINTS, JointLimit};
use crate::error::AtomError;

/// The Atom's settings: its configuration and what the host changed at run time.
#[derive(Clone, Debug)]
pub struct Settings {
    config: AtomConfig,
    limits: [JointLimit; JOINTS],
    fresh_mode: bool,
    free_mode: bool,
    speed_percent: u8,
    cart: Cartesian,
    collision: CollisionSettings,
}

impl Settings {
    /// The settings at boot: the configured limits, fresh mode on (a new move replaces the
    /// current one), free mode off, speed 100 %, flange in the base frame, collision protection
    /// as [`DEFAULT_PROTECTION`] says with every threshold at its default (until the flash's
    /// settings are loaded).
    pub fn new(config: AtomConfig) -> Self {
        Self {
            limits: config.joint_limits,
            cart: Cartesian::new(&config.joint_limits),
            config,
            fresh_mode: true,
            free_mode: false,
            speed_percent: 100,
            collision: CollisionSettings::new(DEFAULT_PROTECTION),
        }
    }

    /// Collision protection: mode and thresholds (0x74..0x76, 0xFD).
    pub fn collision(&self) -> &CollisionSettings {
        &self.collision
    }

    /// Collision protection, to change (its setters keep its values in range).
    pub fn collision_mut(&mut self) -> &mut CollisionSettings {
        &mut self.collision
    }

    /// The configuration the Atom runs with.
    pub fn config(&self) -> &AtomConfig {
        &self.config
    }

    /// The joint limits in force.
    pub fn limits(&self) -> &[JointLimit; JOINTS] {
        &self.limits
    }

    /// The limit of joint `j` (0-based).
    pub fn limit(&self, j: usize) -> Option<JointLimit> {
        self.limits.get(j).copied()
    }

    /// Sets joint `j`'s lower and/or upper limit (0x4C/0x4D). Refused if min would exceed max
    /// ([`AtomError::Invalid`]) or a limit would leave the factory range
    /// ([`crate::config::FACTORY_LIMITS`]; [`AtomError::JointLimit`], so 0x07 reports the
    /// joint): a limit can be narrowed, never widened beyond what the arm can do.
    pub fn set_limit(
        &mut self,
        j: usize,
        min: Option<Decideg>,
        max: Option<Decideg>,
    ) -> Result<(), AtomError> {
        let limit = self.limit(j).ok_or(AtomError::Invalid)?;
        let to_cd = |d: Decideg| i32::from(d.0) * 10;
        let new_min = min.map_or(i32::from(limit.min.0), to_cd);
        let new_max = max.map_or(i32::from(limit.max.0), to_cd);
        let factory = FACTORY_LIMITS.get(j).ok_or(AtomError::Invalid)?;
        if new_min < i32::from(factory.min.0) || new_max > i32::from(factory.max.0) {
            return Err(AtomError::JointLimit(j));
        }
        if new_min > new_max {
            return Err(AtomError::Invalid);
        }
        if let Some(l) = self.limits.get_mut(j) {
            l.min = Centideg(new_min as i16);
            l.max = Centideg(new_max as i16);
        }
        self.cart.set_limits(&self.limits);
        Ok(())
    }

    /// Checks joint angles against the limits (`None` = that joint is not part of the goal).
    pub fn check_angles(&self, angles: &[Option<Centideg>; JOINTS]) -> Result<(), AtomError> {
        for (j, (a, l)) in angles.iter().zip(&self.limits).enumerate() {
            if let Some(a) = a
                && !l.contains(*a)
            {
                return Err(AtomError::JointLimit(j));
            }
        }
        Ok(())
    }

    /// The encoder goal for joint `j` at `angle`: the nearest step whose angle is still within
    /// the joint's limits (a limit rarely falls on a whole step: 140 deg is step 3641.2, and
    /// step 3641 reads 140.01 deg, which the safety check would refuse).
    pub fn goal_steps(&self, j: usize, angle: Centideg) -> Steps {
        let steps = self.config.angle_to_steps(j, angle);
        let Some(limit) = self.limit(j) else {
            return steps;
        };
        [steps.0, steps.0 - 1, steps.0 + 1]
            .into_iter()
            .map(Steps)
            .find(|&s| limit.contains(self.config.steps_to_angle(j, s)))
            .unwrap_or(steps)
    }

    /// Joint angle of encoder position `steps` of joint `j`.
    pub fn angle(&self, j: usize, steps: Steps) -> Centideg {
        self.config.steps_to_angle(j, steps)
    }

    /// True in fresh mode (0x16 1): a new move replaces the current one; false in queue mode.
    pub fn fresh_mode(&self) -> bool {
        self.fresh_mode
    }

    /// Sets fresh (true) or queue (false) mode.
    pub fn set_fresh_mode(&mut self, fresh: bool) {
        self.fresh_mode = fresh;
    }

    /// True in free mode (0x1A 1): the Atom's button releases the joints while held.
    pub fn free_mode(&self) -> bool {
        self.free_mode
    }

    /// Turns free mode on or off.
    pub fn set_free_mode(&mut self, on: bool) {
        self.free_mode = on;
    }

    /// The default speed (0x41), percent: used by commands that carry none.
    pub fn speed_percent(&self) -> u8 {
        self.speed_percent
    }

    /// Sets the default speed, percent (1..=100, checked by the protocol layer).
    pub fn set_speed_percent(&mut self, percent: u8) {
        self.speed_percent = percent;
    }

    /// The kinematics with the selected frames.
    pub fn cart(&self) -> &Cartesian {
        &self.cart
    }

    /// Sets the tool pose (0x81), re-applying the frames.
    pub fn set_tool(&mut self, pose: Pose) {
        self.cart.set_tool(pose);
    }

    /// Sets the base pose in the world frame (0x83), re-applying the frames.
    pub fn set_world(&mut self, pose: Pose) {
        self.cart.set_world(pose);
    }

    /// Sets the reference frame (0x85), re-applying the frames.
    pub fn set_reference(&mut self, frame: ReferenceFrame) {
        self.cart.set_reference(frame);
    }

    /// Sets the end type (0x89), re-applying the frames.
    pub fn set_end(&mut self, end: EndType) {
        self.cart.set_end(end);
    }

    /// Sets the default interpolation of send coords (0x87).
    pub fn set_movement(&mut self, mode: MoveMode) {
        self.cart.set_movement(mode);
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_limit_is_refused_when_inverted_or_beyond_the_factory_range() {
        let mut s = Settings::new(AtomConfig::default());
        assert_eq!(
            s.set_limit(0, Some(Decideg(100)), Some(Decideg(-100))),
            Err(AtomError::Invalid)
        );
        assert_eq!(
            s.set_limit(0, Some(Decideg(-1_690)), None),
            Err(AtomError::JointLimit(0)),
            "beyond the factory range"
        );
        assert_eq!(
            s.set_limit(1, Some(Decideg(-1_700)), None),
            Err(AtomError::JointLimit(1))
        );
        assert_eq!(s.set_limit(0, None, Some(Decideg(900))), Ok(()));
        assert_eq!(s.limit(0).map(|l| l.max), Some(Centideg(9_000)));
        assert_eq!(
            s.check_angles(&[Some(Centideg(9_001)), None, None, None, None, None]),
            Err(AtomError::JointLimit(0))
        );
    }

    #[test]
    fn a_goal_at_a_limit_rounds_to_a_step_inside_it() {
        let s = Settings::new(AtomConfig::default());
        let steps = s.goal_steps(1, Centideg(14_000));
        assert!(s.limit(1).is_some_and(|l| l.contains(s.angle(1, steps))));
    }
}
