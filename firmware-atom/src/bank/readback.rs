//! The state read of every servo, and the repair of writes lost on the shared wire.

use protocol_core::servo::{Packet, reg, sign_magnitude};
use protocol_core::units::Steps;

use crate::health::ServoHealth;
use crate::safety::Goal;
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

/// What a servo's read-back asks the bank to send again.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub(super) enum Repair {
    /// Its torque is not what it was told: write torque on (`true`) or off again.
    Torque(bool),
    /// It holds torque but not the goal it was last sent: send that goal again (through the
    /// safety check: the limits may have changed since).
    Goal(Goal),
}

/// Compares what a servo reports (`h`) with what it was told (torque, `last_goal`) and says
/// what got lost: a SYNC WRITE has no answer, and a collision on the shared wire can swallow
/// it or a torque write. Nothing after [`MAX_REPAIRS`] corrections (`repairs`) for the same
/// command, nor while a command for that servo is still on its way (`busy`).
pub(super) fn repair(
    h: &ServoHealth,
    last_goal: Option<Goal>,
    repairs: u8,
    busy: bool,
) -> Option<Repair> {
    if busy || repairs >= MAX_REPAIRS {
        return None;
    }
    if h.torque_reported != h.torque_on {
        return Some(Repair::Torque(h.torque_on));
    }
    match last_goal {
        Some(goal) if h.torque_on && !tolerance::goal_confirmed(goal.position, h.goal_reported) => {
            Some(Repair::Goal(goal))
        }
        _ => None,
    }
}
