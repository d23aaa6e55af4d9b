//! Host access to single servos: raw register reads and writes (0x52/0x53), calibration
//! (0x54, 0x68), joint brake (0x55) and drag goals (0x3E).
//!
//! # Register policy of raw writes (0x52)
//!
//! A raw write may neither bypass the firmware's bookkeeping nor change what a position means
//! or switch a protection off ([`access`]):
//!
//! | registers | write |
//! |---|---|
//! | 21..=23 PID, 24..=25 minimum start-up force, 26..=27 dead zones, 37 / 39 speed loop gains | tuning: written, EEPROM unlocked and locked around it |
//! | 41 acceleration, 44..=45 goal time, 46..=47 goal speed, 48..=49 torque limit | written |
//! | 40 torque enable | through the torque bookkeeping (128 is the calibration, as 0x54) |
//! | 42..=43 goal position (a two-byte write at 42) | a motion: through the safety check |
//! | 5 id, 6 baud rate | refused: the servo would leave the arm's bus |
//! | 7 return delay, 8 status return level | refused: the bus schedule relies on both |
//! | 9..=12 angle limits, 30 angle resolution, 31..=32 homing offset, 33 operating mode | refused: they change what a position means (the joint's zero moves only by calibration) |
//! | 13..=20 temperature, voltage, torque limits, unloading and alarm conditions, 28..=29, 34..=36, 38 protection settings | refused: protections stay on |
//! | 55 EEPROM lock | refused: the firmware opens and closes it |
//! | 0..=4 and 56.. (read-only), anything else | refused |
//!
//! A write that touches a refused register (a two-byte write starting one below it) is refused
//! as a whole, answered `00`, and changes nothing.

use protocol_core::command::ServoValue;
use protocol_core::servo::{reg, sign_magnitude};
use protocol_core::units::Steps;

use crate::config::{GRIPPER, JOINTS};
use crate::context::Context;
use crate::driver::Op;
use crate::error::AtomError;
use crate::gripper::{self, Gripper};
use crate::motion::{self, MotionController};
use crate::safety::{Goal, Goals};
use crate::settings::Settings;

/// Servo registers below this address are EEPROM: writes need the lock (55) opened first.
const FIRST_RAM_REGISTER: u8 = reg::TORQUE_ENABLE;

/// What a raw write (0x52) may do to one servo register (the [module doc](self)'s table).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Access {
    /// Tuning or RAM settings: written as asked.
    Write,
    /// Torque enable: through the torque bookkeeping.
    Torque,
    /// Goal position: a motion, through the safety check.
    Goal,
    /// Refused.
    Refused,
}

/// The policy for raw writes to register `addr`.
pub fn access(addr: u8) -> Access {
    match addr {
        21..=27 | 37 | 39 | 41 | 44..=49 => Access::Write,
        reg::TORQUE_ENABLE => Access::Torque,
        42 | 43 => Access::Goal,
        _ => Access::Refused,
    }
}

/// Writes a servo register for 0x52 (servo `index` 0..=6). See the [module doc](self). A
/// torque write of 128 is a calibration ([`calibrate`]).
pub fn write(
    cx: &mut Context<'_>,
    motion: &mut MotionController,
    gripper: &mut Gripper,
    index: usize,
    addr: u8,
    value: ServoValue,
) -> Result<(), AtomError> {
    let id = id(cx.settings, index)?;
    let (data, len): ([u8; 2], u8) = match value {
        ServoValue::Byte(b) => ([b, 0], 1),
        ServoValue::Word(w) => (w.to_le_bytes(), 2),
    };
    let last = addr.checked_add(len - 1).ok_or(AtomError::Invalid)?;
    let kinds = (access(addr), access(last));
    match (kinds, value) {
        ((Access::Torque, Access::Torque), ServoValue::Byte(128)) => {
            return calibrate(cx, motion, gripper, index);
        }
        ((Access::Torque, Access::Torque), ServoValue::Byte(b)) => {
            return if cx.bank.set_torque(cx.settings, index, b != 0) {
                Ok(())
            } else {
                Err(AtomError::Invalid)
            };
        }
        ((Access::Goal, Access::Goal), ServoValue::Word(w)) if addr == reg::GOAL_POSITION => {
            if index < JOINTS {
                motion.may_move(cx)?;
            }
            return move_to_steps(cx, index, Steps(sign_magnitude(w, 15)));
        }
        ((Access::Write, Access::Write), _) => {}
        _ => return Err(AtomError::Invalid),
    }
    let data = data.get(..usize::from(len)).ok_or(AtomError::Invalid)?;
    let eeprom = addr < FIRST_RAM_REGISTER;
    let needed = if eeprom { 3 } else { 1 };
    if cx.bank.op_room() < needed {
        return Err(AtomError::Busy);
    }
    let write = Op::write(id, addr, data).ok_or(AtomError::Invalid)?;
    if eeprom && let Some(unlock) = Op::write(id, reg::EEPROM_LOCK, &[0]) {
        cx.bank.queue_op(unlock);
    }
    cx.bank.queue_op(write);
    if eeprom && let Some(lock) = Op::write(id, reg::EEPROM_LOCK, &[1]) {
        cx.bank.queue_op(lock);
    }
    Ok(())
}

/// The read of one or two bytes at `addr` of servo `index` (0x53).
pub fn read(settings: &Settings, index: usize, addr: u8, two_bytes: bool) -> Result<Op, AtomError> {
    Ok(Op::Read {
        id: id(settings, index)?,
        addr,
        count: if two_bytes { 2 } else { 1 },
    })
}

/// Calibration (0x54, 0x68): the servo's present position becomes 2048. A joint's motion is
/// halted first; the gripper's range follows its calibration.
pub fn calibrate(
    cx: &mut Context<'_>,
    motion: &mut MotionController,
    gripper: &mut Gripper,
    index: usize,
) -> Result<(), AtomError> {
    let id = id(cx.settings, index)?;
    if index < JOINTS {
        motion.halt(cx);
    }
    let op = Op::write(id, reg::TORQUE_ENABLE, &[128]).ok_or(AtomError::Invalid)?;
    if !cx.bank.queue_op(op) {
        return Err(AtomError::Busy);
    }
    cx.bank.calibrated(index);
    if index == GRIPPER {
        gripper.calibrated();
    }
    Ok(())
}

/// Joint brake (0x55): the servo stops where it comes to rest braking at full deceleration
/// ([`motion::stop_one`]: from what it was told, never from an old reading, which would turn a
/// moving joint back); a released servo stays released.
pub fn brake(cx: &mut Context<'_>, index: usize) -> Result<(), AtomError> {
    if cx.settings.config().servo_ids.get(index).is_none() {
        return Err(AtomError::Invalid);
    }
    match motion::stop_one(cx, index) {
        Some(goal) => cx.send_goals(Goals::one(index, goal)),
        None => Ok(()),
    }
}

/// Moves servo `index` to an encoder position at the default speed.
fn move_to_steps(cx: &mut Context<'_>, index: usize, steps: Steps) -> Result<(), AtomError> {
    let speed = cx.settings.speed_percent();
    if index == GRIPPER {
        return gripper::move_steps(cx, steps, speed);
    }
    let config = cx.settings.config();
    let goal = Goal {
        position: steps,
        speed_steps_per_s: config.joint_speed_steps(speed) as u16,
        accel: config.joint_accel_register(),
    };
    cx.send_goals(Goals::one(index, goal))
}

/// The bus id of servo `index`.
fn id(settings: &Settings, index: usize) -> Result<u8, AtomError> {
    settings
        .config()
        .servo_ids
        .get(index)
        .copied()
        .ok_or(AtomError::Invalid)
}

/// Fastest goal speed a drag (0x3E) may ask for, steps per second: the STS3215's top speed.
pub const MAX_DRAG_SPEED_STEPS_PER_S: i16 = 3_400;

/// Moves the joints to six encoder positions with their own speeds (0x3E set encoders drag), if
/// a motion may start ([`MotionController::may_move`]).
/// A speed of 0 (the servo would read it as "as fast as you can"), a negative one or one above
/// [`MAX_DRAG_SPEED_STEPS_PER_S`] is refused: nothing creeps and nothing races.
pub fn drag_to(
    cx: &mut Context<'_>,
    motion: &MotionController,
    encoders: [Steps; JOINTS],
    speeds_steps_per_s: [i16; JOINTS],
) -> Result<(), AtomError> {
    motion.may_move(cx)?;
    if speeds_steps_per_s
        .iter()
        .any(|s| !(1..=MAX_DRAG_SPEED_STEPS_PER_S).contains(s))
    {
        return Err(AtomError::Invalid);
    }
    let accel = cx.settings.config().joint_accel_register();
    let mut goals = Goals::NONE;
    for (j, (e, s)) in encoders.iter().zip(speeds_steps_per_s).enumerate() {
        let goal = Goal {
            position: *e,
            speed_steps_per_s: s.unsigned_abs(),
            accel,
        };
        goals.set(j, Some(goal));
    }
    cx.send_goals(goals)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn only_tuning_and_motion_registers_are_writable() {
        for addr in [
            5, 6, 7, 8, 9, 11, 13, 16, 19, 20, 28, 30, 31, 32, 33, 36, 55, 56, 70,
        ] {
            assert_eq!(access(addr), Access::Refused, "register {addr}");
        }
        for addr in [21, 22, 23, 24, 26, 27, 41, 44, 46, 48] {
            assert_eq!(access(addr), Access::Write, "register {addr}");
        }
        assert_eq!(access(40), Access::Torque);
        assert_eq!(access(42), Access::Goal);
    }
}
