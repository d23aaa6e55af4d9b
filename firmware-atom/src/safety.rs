//! The one choke point every servo goal passes: joint limits, gripper encoder range and power
//! state.
//!
//! [`SafeGoals`] can only be made by [`check`], and the Atom sends position goals to servos
//! only from a `SafeGoals` (the servo bank's `send_goals`, its only maker of goals): no command
//! path (move, jog, stream, path, braking, encoder write, raw servo data write) can put an
//! unchecked goal on the bus.

use protocol_core::servo::{SyncWriteBuilder, reg, to_sign_magnitude};
use protocol_core::units::{Centideg, Steps};

use crate::config::{AtomConfig, GRIPPER, JOINTS, JointLimit, SERVOS, STEPS_PER_TURN};
use crate::error::AtomError;

/// A goal for one servo: where to go and how (the STS move block).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct Goal {
    /// Goal position.
    pub position: Steps,
    /// Goal speed, steps per second (at least 1: 0 means "as fast as possible" to the servo).
    pub speed_steps_per_s: u16,
    /// Acceleration register, 100 steps/s^2 units (at least 1: 0 means "no ramp").
    pub accel: u8,
}

impl Goal {
    /// The 7-byte move block at [`reg::MOVE_BLOCK`]: acceleration, goal position, goal time 0,
    /// goal speed (little-endian sign-magnitude).
    pub fn move_block(&self) -> [u8; reg::MOVE_BLOCK_LEN as usize] {
        let [p0, p1] = to_sign_magnitude(self.position.0, 15).to_le_bytes();
        let speed = self.speed_steps_per_s.clamp(1, i16::MAX as u16) as i16;
        let [s0, s1] = to_sign_magnitude(speed, 15).to_le_bytes();
        [self.accel.max(1), p0, p1, 0, 0, s0, s1]
    }
}

/// Goals per servo (index 0..5 joints, 6 gripper); a servo without one is left alone.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct Goals([Option<Goal>; SERVOS]);

impl Goals {
    /// No goal for any servo.
    pub const NONE: Self = Self([None; SERVOS]);

    /// Only servo `index`'s goal (none at all for an index beyond the servos).
    pub fn one(index: usize, goal: Goal) -> Self {
        let mut goals = Self::NONE;
        goals.set(index, Some(goal));
        goals
    }

    /// Servo `index`'s goal, if it has one.
    pub fn get(&self, index: usize) -> Option<Goal> {
        self.0.get(index).copied().flatten()
    }

    /// Gives servo `index` `goal` (`None`: leave it alone); an index beyond the servos is
    /// ignored.
    pub fn set(&mut self, index: usize, goal: Option<Goal>) {
        if let Some(slot) = self.0.get_mut(index) {
            *slot = goal;
        }
    }

    /// These goals with `newer`'s on top: a servo keeps its goal unless `newer` has one.
    #[must_use]
    pub fn merge(mut self, newer: &Self) -> Self {
        for (slot, new) in self.0.iter_mut().zip(&newer.0) {
            if new.is_some() {
                *slot = *new;
            }
        }
        self
    }

    /// The servos with a goal, and their goals, by index.
    pub fn iter(&self) -> impl Iterator<Item = (usize, Goal)> + '_ {
        self.0
            .iter()
            .enumerate()
            .filter_map(|(i, g)| g.map(|g| (i, g)))
    }

    /// True if no servo has a goal.
    pub fn is_empty(&self) -> bool {
        self.0.iter().all(Option::is_none)
    }
}

/// Goals that passed [`check`]. The only input of the goal-sending path.
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct SafeGoals(Goals);

impl SafeGoals {
    /// The checked goals.
    pub fn goals(&self) -> &Goals {
        &self.0
    }

    /// The same goals without servo `index`'s (still checked: a goal less is never unsafe).
    #[must_use]
    pub fn without(mut self, index: usize) -> Self {
        self.0.set(index, None);
        self
    }

    /// One WRITE at the torque-enable register (40) switching servo `index` (bus id `id`) on
    /// together with its move block (41..47): the servo holds the checked goal from the moment
    /// its torque is on, whatever stale goal its register held.
    pub fn torque_on_write(&self, index: usize, id: u8) -> Option<crate::driver::Op> {
        let goal = self.0.get(index)?;
        let mut data = [1u8; 1 + reg::MOVE_BLOCK_LEN as usize];
        if let Some(block) = data.get_mut(1..) {
            block.copy_from_slice(&goal.move_block());
        }
        crate::driver::Op::write(id, reg::TORQUE_ENABLE, &data)
    }

    /// The SYNC WRITE of the move blocks to the servos with a goal (`ids` per index).
    pub fn sync_write(&self, ids: &[u8; SERVOS]) -> Option<protocol_core::servo::Packet> {
        let mut b = SyncWriteBuilder::new(reg::MOVE_BLOCK, reg::MOVE_BLOCK_LEN);
        for (index, goal) in self.0.iter() {
            b.push(*ids.get(index)?, &goal.move_block())?;
        }
        b.to_packet()
    }
}

/// Checks `goals` against the power state, `limits` and the gripper range of `config`.
/// All or nothing: one bad goal refuses the whole set.
pub fn check(
    config: &AtomConfig,
    limits: &[JointLimit; JOINTS],
    powered: bool,
    goals: Goals,
) -> Result<SafeGoals, AtomError> {
    if !powered {
        return Err(AtomError::PoweredOff);
    }
    for (j, limit) in limits.iter().enumerate() {
        if let Some(g) = goals.get(j)
            && !goal_within(config, j, g.position, limit)
        {
            return Err(AtomError::JointLimit(j));
        }
    }
    // The gripper has no angle limits: its goals only have to be encoder positions (clients
    // set it by raw encoder, e.g. 0x3A servo 7, beyond the 0..100 value range).
    if let Some(g) = goals.get(GRIPPER)
        && !(0..STEPS_PER_TURN as i16).contains(&g.position.0)
    {
        return Err(AtomError::GripperRange);
    }
    Ok(SafeGoals(goals))
}

/// True if encoder goal `position` of joint `joint` lies within `limit`. Compared in steps
/// with the limit rounded inwards, so a goal that rounds to an angle just outside is refused.
fn goal_within(config: &AtomConfig, joint: usize, position: Steps, limit: &JointLimit) -> bool {
    let angle = config.steps_to_angle(joint, position);
    let back = config.angle_to_steps(joint, angle);
    back == position && limit.contains(angle) && in_turn(angle)
}

fn in_turn(angle: Centideg) -> bool {
    (-18_000..=18_000).contains(&angle.0)
}

#[cfg(test)]
mod tests {
    use super::*;

    fn goal_at(cfg: &AtomConfig, joint: usize, centideg: i16) -> Goal {
        Goal {
            position: cfg.angle_to_steps(joint, Centideg(centideg)),
            speed_steps_per_s: 100,
            accel: 10,
        }
    }

    #[test]
    fn refuses_out_of_limit_and_powered_off() {
        let cfg = AtomConfig::default();
        let limits = cfg.joint_limits;
        let mut goals = Goals::NONE;
        goals.set(1, Some(goal_at(&cfg, 1, 14_500))); // J2 limit is 140 deg
        assert_eq!(
            check(&cfg, &limits, true, goals),
            Err(AtomError::JointLimit(1))
        );
        goals.set(1, Some(goal_at(&cfg, 1, 13_900)));
        assert!(check(&cfg, &limits, true, goals).is_ok());
        assert_eq!(
            check(&cfg, &limits, false, goals),
            Err(AtomError::PoweredOff)
        );
    }

    #[test]
    fn gripper_goal_must_stay_in_range() {
        let cfg = AtomConfig::default();
        let goals = Goals::one(
            GRIPPER,
            Goal {
                position: Steps(4096),
                speed_steps_per_s: 100,
                accel: 10,
            },
        );
        assert_eq!(
            check(&cfg, &cfg.joint_limits, true, goals),
            Err(AtomError::GripperRange)
        );
    }

    #[test]
    fn newer_goals_merge_on_top_and_one_gives_a_single_servo_a_goal() {
        let g = |position| Goal {
            position: Steps(position),
            speed_steps_per_s: 1,
            accel: 1,
        };
        let older = Goals::one(0, g(1)).merge(&Goals::one(1, g(2)));
        let merged = older.merge(&Goals::one(1, g(3)));
        assert_eq!(merged.iter().collect::<Vec<_>>(), [(0, g(1)), (1, g(3))]);
        assert_eq!(merged.get(2), None);
        assert!(Goals::one(SERVOS, g(1)).is_empty(), "no such servo");
        assert!(Goals::NONE.is_empty());
    }

    #[test]
    fn move_block_layout() {
        let g = Goal {
            position: Steps(3000),
            speed_steps_per_s: 500,
            accel: 0,
        };
        assert_eq!(g.move_block(), [1, 0xB8, 0x0B, 0, 0, 0xF4, 0x01]);
    }
}
