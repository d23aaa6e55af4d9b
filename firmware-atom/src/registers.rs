//! Host access to single servos: raw register reads and writes (0x52/0x53), calibration
//! (0x54, 0x68), joint brake (0x55) and drag goals (0x3E).
//!
//! A raw write may not bypass the firmware's bookkeeping: a write touching the goal position is
//! a motion and goes through the safety check; torque writes go through the torque bookkeeping
//! (torque 128 is the calibration); id and baud rate are refused (they would take the servo off
//! the arm's bus). EEPROM registers are unlocked and locked around the write.

use protocol_core::command::ServoValue;
use protocol_core::servo::{reg, sign_magnitude};
use protocol_core::units::Steps;

use crate::bank::{ServoBank, Then};
use crate::config::{GRIPPER, JOINTS, SERVOS};
use crate::driver::Op;
use crate::error::AtomError;
use crate::gripper::{self, Gripper};
use crate::link::Link;
use crate::motion::MotionController;
use crate::safety::{Goal, GoalSet};
use crate::settings::Settings;

/// Servo registers below this address are EEPROM: writes need the lock (55) opened first.
const FIRST_RAM_REGISTER: u8 = reg::TORQUE_ENABLE;

/// The parts a servo access may touch.
pub struct ServoAccess<'a> {
    /// The servos.
    pub bank: &'a mut ServoBank,
    /// Limits and configuration.
    pub settings: &'a Settings,
    /// The motion (halted before a calibration).
    pub motion: &'a mut MotionController,
    /// The gripper's range (follows its calibration).
    pub gripper: &'a mut Gripper,
}

impl ServoAccess<'_> {
    /// Writes a servo register for 0x52 (servo `index` 0..=6). See the [module doc](self).
    pub fn write(
        &mut self,
        now_us: u64,
        index: usize,
        addr: u8,
        value: ServoValue,
    ) -> Result<(), AtomError> {
        let id = self.id(index)?;
        let (data, len): ([u8; 2], u8) = match value {
            ServoValue::Byte(b) => ([b, 0], 1),
            ServoValue::Word(w) => (w.to_le_bytes(), 2),
        };
        let touches = |r: u8| addr <= r && r < addr.saturating_add(len);
        if touches(reg::ID) || touches(reg::BAUD_RATE) {
            return Err(AtomError::Invalid);
        }
        if addr == reg::TORQUE_ENABLE && value == ServoValue::Byte(128) {
            return self.calibrate(now_us, index);
        }
        if addr == reg::TORQUE_ENABLE
            && let ServoValue::Byte(b) = value
        {
            return if self.bank.set_torque(self.settings, index, b != 0) {
                Ok(())
            } else {
                Err(AtomError::Invalid)
            };
        }
        if touches(reg::GOAL_POSITION) || touches(reg::GOAL_POSITION + 1) {
            return match value {
                ServoValue::Word(w) if addr == reg::GOAL_POSITION => {
                    let steps = Steps(sign_magnitude(w, 15));
                    self.move_to_steps(index, steps)
                }
                _ => Err(AtomError::Invalid),
            };
        }
        let data = data.get(..usize::from(len)).ok_or(AtomError::Invalid)?;
        let eeprom = addr < FIRST_RAM_REGISTER;
        let needed = if eeprom { 3 } else { 1 };
        if self.bank.op_room() < needed {
            return Err(AtomError::Busy);
        }
        let write = Op::write(id, addr, data).ok_or(AtomError::Invalid)?;
        if eeprom && let Some(unlock) = Op::write(id, reg::EEPROM_LOCK, &[0]) {
            self.bank.queue_op(unlock, Then::Nothing);
        }
        self.bank.queue_op(write, Then::Nothing);
        if eeprom && let Some(lock) = Op::write(id, reg::EEPROM_LOCK, &[1]) {
            self.bank.queue_op(lock, Then::Nothing);
        }
        Ok(())
    }

    /// Queues a read of one or two bytes at `addr` of servo `index` (0x53); the reply goes to
    /// `link` when the read finishes.
    pub fn read(
        &mut self,
        index: usize,
        addr: u8,
        two_bytes: bool,
        link: Link,
    ) -> Result<(), AtomError> {
        let id = self.id(index)?;
        let op = Op::Read {
            id,
            addr,
            count: if two_bytes { 2 } else { 1 },
        };
        if self
            .bank
            .queue_op(op, Then::ReplyServoData { link, two_bytes })
        {
            Ok(())
        } else {
            Err(AtomError::Busy)
        }
    }

    /// Calibration (0x54, 0x68): the servo's present position becomes 2048. A joint's motion
    /// is halted first.
    pub fn calibrate(&mut self, now_us: u64, index: usize) -> Result<(), AtomError> {
        let id = self.id(index)?;
        if index < JOINTS {
            self.motion.halt(now_us, self.bank, self.settings);
        }
        let op = Op::write(id, reg::TORQUE_ENABLE, &[128]).ok_or(AtomError::Invalid)?;
        if !self.bank.queue_op(op, Then::Nothing) {
            return Err(AtomError::Busy);
        }
        self.bank.calibrated(index);
        if index == GRIPPER {
            self.gripper.calibrated();
        }
        Ok(())
    }

    /// Joint brake (0x55): the servo holds where it is.
    pub fn brake(&mut self, index: usize) -> Result<(), AtomError> {
        let steps = self
            .bank
            .health(index)
            .map(|h| h.position)
            .ok_or(AtomError::Invalid)?;
        self.move_to_steps(index, steps)
    }

    /// Moves servo `index` to an encoder position at the default speed.
    fn move_to_steps(&mut self, index: usize, steps: Steps) -> Result<(), AtomError> {
        let speed = self.settings.speed_percent();
        if index == GRIPPER {
            return gripper::move_steps(self.bank, self.settings, steps, speed);
        }
        let config = self.settings.config();
        let mut goals: GoalSet = [None; SERVOS];
        if let Some(slot) = goals.get_mut(index) {
            *slot = Some(Goal {
                position: steps,
                speed_steps_per_s: config.joint_speed_steps(speed) as u16,
                accel: config.joint_accel_register(),
            });
        }
        self.bank.send_goals(self.settings, goals)
    }

    fn id(&self, index: usize) -> Result<u8, AtomError> {
        self.settings
            .config()
            .servo_ids
            .get(index)
            .copied()
            .ok_or(AtomError::Invalid)
    }
}

/// Moves the joints to six encoder positions with their own speeds (0x3E set encoders drag).
pub fn drag_to(
    bank: &mut ServoBank,
    settings: &Settings,
    encoders: [Steps; JOINTS],
    speeds_steps_per_s: [i16; JOINTS],
) -> Result<(), AtomError> {
    let accel = settings.config().joint_accel_register();
    let mut goals: GoalSet = [None; SERVOS];
    for (slot, (e, s)) in goals
        .iter_mut()
        .zip(encoders.iter().zip(speeds_steps_per_s))
    {
        *slot = Some(Goal {
            position: *e,
            speed_steps_per_s: s.unsigned_abs().max(1),
            accel,
        });
    }
    bank.send_goals(settings, goals)
}
