//! The step context: what the Atom lends each part for one step (one poll, one command), like
//! smoltcp's `Context`: the time of the step, the servo bank and the settings.
//!
//! A part that acts on the servos (motion, gripper, register access, backups) takes
//! `cx: &mut Context` instead of a tail of `(now_us, bank, settings)` arguments, and its
//! queries of the servos' state go through the context, at the step's time.

use protocol_core::units::Centideg;

use crate::bank::ServoBank;
use crate::config::JOINTS;
use crate::error::AtomError;
use crate::safety::{Goal, Goals};
use crate::settings::Settings;

/// The parts lent to one step. See the [module doc](self).
#[derive(Debug)]
pub struct Context<'a> {
    /// The time of the step, monotonic microseconds.
    pub now_us: u64,
    /// The servos.
    pub bank: &'a mut ServoBank,
    /// What the host set.
    pub settings: &'a Settings,
}

impl<'a> Context<'a> {
    /// The context of a step at `now_us`.
    pub fn new(now_us: u64, bank: &'a mut ServoBank, settings: &'a Settings) -> Self {
        Self {
            now_us,
            bank,
            settings,
        }
    }

    /// Present joint angles now ([`ServoBank::present_angles`]).
    pub fn present_angles(&self) -> [Centideg; JOINTS] {
        self.bank.present_angles(self.now_us, self.settings)
    }

    /// True while a joint reports moving ([`ServoBank::joints_moving`]).
    pub fn joints_moving(&self) -> bool {
        self.bank.joints_moving(self.now_us)
    }

    /// Sets joint `index`'s goal where its shaft stands now (its last read position), at the
    /// servos' full acceleration: a servo held back by something stops pressing on it. Nothing
    /// is sent for a joint that has not been read.
    pub fn hold_where_it_stands(&mut self, index: usize) {
        let Some(position) = self.bank.health(index).map(|h| h.position) else {
            return;
        };
        let config = self.settings.config();
        let goal = Goal {
            position,
            speed_steps_per_s: config.joint_speed_steps(100) as u16,
            accel: config.servo_accel_register(),
        };
        // A refusal (powered off, outside the limits) leaves the goal the stop sent.
        self.send_goals(Goals::one(index, goal)).ok();
    }

    /// Checks `goals` and makes them the next goals written ([`ServoBank::send_goals`]).
    pub fn send_goals(&mut self, goals: Goals) -> Result<(), AtomError> {
        self.bank.send_goals(self.now_us, self.settings, goals)
    }
}
