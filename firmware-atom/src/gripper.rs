//! The gripper (servo 7): its opening 0 (closed) ..= 100 (open) mapped linearly onto an encoder
//! range, and the settings the gripper commands read back.
//!
//! Speed 0 means stop (pymycobot's `gripper_stop` sends set gripper value 0 at speed 0): the
//! gripper holds where it is, whatever the value. After a release (state 254) the next command
//! switches the servo on before its goal is written, so that command moves it.

use protocol_core::command::GripperState;
use protocol_core::units::Steps;

use crate::bank::ServoBank;
use crate::config::{GRIPPER, GripperRange, STEPS_ZERO};
use crate::context::Context;
use crate::error::AtomError;
use crate::safety::{Goal, Goals};
use crate::settings::Settings;

/// The gripper's range and settings.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct Gripper {
    range: GripperRange,
    torque: i16,
    protect_current: i16,
}

impl Gripper {
    /// The gripper of `settings`' configuration; torque and protection current 300 (the
    /// vendor's defaults).
    pub fn new(settings: &Settings) -> Self {
        Self {
            range: settings.config().gripper,
            torque: 300,
            protect_current: 300,
        }
    }

    /// Opening 0 (closed) ..= 100 (open) from the servo's present position.
    pub fn value(&self, bank: &ServoBank) -> u8 {
        let pos = i32::from(bank.gripper_position().0);
        let closed = i32::from(self.range.closed.0);
        let span = i32::from(self.range.open.0) - closed;
        if span == 0 {
            return 0;
        }
        ((pos - closed) * 100 / span).clamp(0, 100) as u8
    }

    /// Opens (100), closes (0) or releases the gripper (0x66); speed 0 stops it where it is.
    pub fn set_state(
        &self,
        cx: &mut Context<'_>,
        state: GripperState,
        speed_percent: u8,
    ) -> Result<(), AtomError> {
        match state {
            GripperState::Open => self.move_to(cx, 100, speed_percent),
            GripperState::Close => self.move_to(cx, 0, speed_percent),
            GripperState::Release => {
                if cx.bank.set_torque(cx.settings, GRIPPER, false) {
                    Ok(())
                } else {
                    Err(AtomError::Busy)
                }
            }
        }
    }

    /// Moves the gripper to opening `value` 0..=100 (0x67); speed 0 stops it where it is.
    pub fn move_to(
        &self,
        cx: &mut Context<'_>,
        value: u8,
        speed_percent: u8,
    ) -> Result<(), AtomError> {
        if speed_percent == 0 {
            return stop(cx);
        }
        let closed = i32::from(self.range.closed.0);
        let open = i32::from(self.range.open.0);
        let steps = closed + (open - closed) * i32::from(value.min(100)) / 100;
        move_steps(cx, Steps(steps as i16), speed_percent)
    }

    /// Follows a calibration of the gripper servo (its present position became 2048): that
    /// is the new closed end, the span is kept.
    pub fn calibrated(&mut self) {
        let span = self.range.open.0 - self.range.closed.0;
        self.range.closed = Steps(STEPS_ZERO as i16);
        self.range.open = Steps(STEPS_ZERO as i16 + span);
    }

    /// The torque setting of the HTS gripper (0x35/0x36).
    pub fn torque(&self) -> i16 {
        self.torque
    }

    /// Sets the torque setting (150..=980, checked by the protocol layer).
    pub fn set_torque(&mut self, torque: i16) {
        self.torque = torque;
    }

    /// The protection current (0x39/0x3A).
    pub fn protect_current(&self) -> i16 {
        self.protect_current
    }

    /// Sets the protection current (1..=500, checked by the protocol layer).
    pub fn set_protect_current(&mut self, current: i16) {
        self.protect_current = current;
    }
}

/// Stops the gripper where it is: braking at the servo's full deceleration, the goal where it
/// comes to rest. A released gripper stays released.
fn stop(cx: &mut Context<'_>) -> Result<(), AtomError> {
    match crate::motion::stop_one(cx, GRIPPER) {
        Some(goal) => cx.send_goals(Goals::one(GRIPPER, goal)),
        None => Ok(()),
    }
}

/// Moves the gripper servo to an encoder position at `speed_percent` of the joint speed (a
/// released gripper is switched on by the bank before its goal is written).
pub fn move_steps(cx: &mut Context<'_>, steps: Steps, speed_percent: u8) -> Result<(), AtomError> {
    let config = cx.settings.config();
    let goal = Goal {
        position: steps,
        speed_steps_per_s: config.joint_speed_steps(speed_percent.max(1)) as u16,
        accel: config.joint_accel_register(),
    };
    cx.send_goals(Goals::one(GRIPPER, goal))
}
