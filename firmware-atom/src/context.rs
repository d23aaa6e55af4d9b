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
use crate::safety::Goals;
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

    /// Makes joint `index`'s servo let go of what it presses on and hold where its shaft
    /// stands: its torque is switched off and on again, which restarts its position loop at
    /// the shaft (a new goal alone would let the servo's profile run on into the obstacle
    /// while it slows down) and drops a goal not yet written. Nothing happens to a joint that
    /// has not been read (it cannot be switched on holding a known place).
    pub fn let_go_and_hold(&mut self, index: usize) {
        if self.bank.health(index).is_some_and(|h| h.answering) {
            self.bank.set_torque(self.settings, index, false);
            self.bank.set_torque(self.settings, index, true);
        }
    }

    /// Checks `goals` and makes them the next goals written ([`ServoBank::send_goals`]).
    pub fn send_goals(&mut self, goals: Goals) -> Result<(), AtomError> {
        self.bank.send_goals(self.now_us, self.settings, goals)
    }
}
