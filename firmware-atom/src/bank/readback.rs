//! The state read of every servo, and the repair of writes lost on the shared wire.

use protocol_core::servo::{Packet, reg, sign_magnitude};
use protocol_core::units::Steps;

use super::ServoBank;
use crate::driver::Op;
use crate::health::ServoHealth;
use crate::safety::Goals;
use crate::settings::Settings;
use crate::tolerance;

/// First register of the state read: torque enable (40) through present current (69..70), so
/// one READ per servo confirms torque and goal as well as the present state. 31 bytes: a
/// transaction of about 0.5 ms, a full round of seven servos in about 4 ms (250 Hz).
pub(super) const STATE_READ_ADDR: u8 = reg::TORQUE_ENABLE;
/// Length of the state read (registers 40..=70).
pub(super) const STATE_READ_LEN: u8 = reg::PRESENT_CURRENT + 2 - reg::TORQUE_ENABLE;

/// Corrective writes per servo and command when the read-back disagrees (a lost write is
/// re-sent; a servo that keeps disagreeing, e.g. a goal clamped by its own position limits, is
/// left alone after this many).
pub(super) const MAX_REPAIRS: u8 = 3;

/// Applies a state read (registers 40..=70) to a servo's health.
pub(super) fn apply_state(h: &mut ServoHealth, p: &Packet) {
    let at = |addr: u8| usize::from(addr - STATE_READ_ADDR);
    let byte = |addr: u8| p.params().get(at(addr)).copied().unwrap_or(0);
    let word = |addr: u8| p.u16_at(at(addr)).unwrap_or(0);
    h.answering = true;
    h.ever_answered = true;
    h.misses = 0;
    h.corrupt_answers = false;
    h.position = Steps(sign_magnitude(word(reg::PRESENT_POSITION), 15));
    h.speed_steps_per_s = sign_magnitude(word(reg::PRESENT_SPEED), 15);
    h.load_permille = sign_magnitude(word(reg::PRESENT_LOAD), 10);
    h.voltage_decivolt = byte(reg::PRESENT_VOLTAGE);
    h.temperature_c = byte(reg::PRESENT_TEMPERATURE);
    h.fault_bits = p.code() | byte(reg::STATUS);
    h.moving = byte(reg::MOVING) != 0;
    h.current_raw = sign_magnitude(word(reg::PRESENT_CURRENT), 15);
    h.torque_reported = byte(reg::TORQUE_ENABLE) != 0;
    h.goal_reported = Steps(sign_magnitude(word(reg::GOAL_POSITION), 15));
}

impl ServoBank {
    /// Compares what servo `index` reports with what it was told (torque, goal) and re-sends
    /// what got lost: a SYNC WRITE has no answer, and a collision on the shared wire can
    /// swallow it or a torque write. At most [`MAX_REPAIRS`] corrections per command, and
    /// none while a command for that servo is still on its way.
    pub(super) fn verify(&mut self, settings: &Settings, index: usize) {
        let Some(&id) = settings.config().servo_ids.get(index) else {
            return;
        };
        let Some(s) = self.servos.get(index).copied() else {
            return;
        };
        let h = s.health;
        let pending_goal = self
            .pending
            .as_ref()
            .is_some_and(|p| p.goals().get(index).is_some());
        let pending_job = self.jobs.iter().any(|j| j.op.id() == id);
        if pending_goal || pending_job || s.repairs >= MAX_REPAIRS {
            return;
        }
        if h.torque_reported != h.torque_on {
            let op = if h.torque_on {
                self.torque_on_op(settings, index, id)
            } else {
                Op::write(id, reg::TORQUE_ENABLE, &[0])
            };
            if let Some(op) = op {
                self.queue_op(op);
            }
        } else if h.torque_on
            && let Some(goal) = s.last_goal
            && !tolerance::goal_confirmed(goal.position, h.goal_reported)
        {
            let waiting = self.pending.as_ref().map_or(Goals::NONE, |p| *p.goals());
            // Through the safety check again: the limits may have changed since.
            if self
                .hold_pending(settings, waiting.merge(&Goals::one(index, goal)))
                .is_err()
            {
                return;
            }
        } else {
            return;
        }
        if let Some(s) = self.servos.get_mut(index) {
            s.repairs += 1;
        }
    }
}
