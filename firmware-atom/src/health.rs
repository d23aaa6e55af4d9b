//! What the Atom knows about each servo, refreshed from the bus.

use protocol_core::command::ServoErrorCode;
use protocol_core::units::Steps;

/// The latest state read from one servo (registers 40..=70: torque, goal, present state;
/// `docs/servo-bus.md`).
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct ServoHealth {
    /// True while the servo answers; false after
    /// [`TimingBudget::misses_before_lost`](crate::TimingBudget) consecutive missed reads.
    pub answering: bool,
    /// True once at least one state read succeeded since boot.
    pub ever_answered: bool,
    /// Fault bits of the last status packet and register 65 (`protocol_core::servo::fault`).
    pub fault_bits: u8,
    /// Present position.
    pub position: Steps,
    /// Present speed, steps per second (signed).
    pub speed_steps_per_s: i16,
    /// Present load, signed, 0.1 % of the maximum torque.
    pub load_permille: i16,
    /// Present current, signed, in the servo's 6.5 mA units.
    pub current_raw: i16,
    /// Supply voltage, tenths of a volt.
    pub voltage_decivolt: u8,
    /// Temperature, degrees Celsius.
    pub temperature_c: u8,
    /// The servo's moving flag.
    pub moving: bool,
    /// Whether the Atom last switched this servo's torque on (what 0x50 reports).
    pub torque_on: bool,
    /// The servo's own torque-enable register, as last read.
    pub torque_reported: bool,
    /// The servo's own goal-position register, as last read.
    pub goal_reported: Steps,
    /// Failed transactions (timeouts and bad checksums) since boot. Wraps.
    pub comm_errors: u32,
    /// True if the last failed read got a corrupt answer (bad checksum) rather than none.
    pub corrupt_answers: bool,
    /// Consecutive missed state reads.
    pub(crate) misses: u8,
}

/// What get servo status (0xE4) reports for a servo that does not answer: every bit set, a
/// value no answering servo reports (its status register has six fault bits).
pub const NO_ANSWER_STATUS: u8 = 0xFF;

impl ServoHealth {
    /// Present current in milliamps (the STS current register counts 6.5 mA units),
    /// saturated to int16.
    pub fn current_milliamps(&self) -> i16 {
        (i32::from(self.current_raw) * 65 / 10).clamp(-32_768, 32_767) as i16
    }

    /// What get servo status (0xE4) reports: the fault bits, or [`NO_ANSWER_STATUS`] while
    /// the servo does not answer.
    pub fn status_byte(&self) -> u8 {
        if self.answering {
            self.fault_bits
        } else {
            NO_ANSWER_STATUS
        }
    }

    /// This servo's entry of read next error (0x15): corrupt answers, no answer, a fault, or
    /// none.
    pub fn error_code(&self) -> ServoErrorCode {
        if !self.answering && self.corrupt_answers {
            ServoErrorCode::BadAnswer
        } else if !self.answering {
            ServoErrorCode::NoAnswer
        } else if self.fault_bits & ServoErrorCode::FAULT_MASK != 0 {
            ServoErrorCode::Fault(self.fault_bits)
        } else {
            ServoErrorCode::Ok
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_silent_servo_reports_no_answer_and_every_status_bit() {
        let answering = ServoHealth {
            answering: true,
            fault_bits: 0x20,
            current_raw: -200,
            ..ServoHealth::default()
        };
        assert_eq!(answering.status_byte(), 0x20);
        assert_eq!(answering.error_code(), ServoErrorCode::Fault(0x20));
        assert_eq!(answering.current_milliamps(), -1_300);
        let silent = ServoHealth::default();
        assert_eq!(silent.status_byte(), NO_ANSWER_STATUS);
        assert_eq!(silent.error_code(), ServoErrorCode::NoAnswer);
        let garbled = ServoHealth {
            corrupt_answers: true,
            ..silent
        };
        assert_eq!(garbled.error_code(), ServoErrorCode::BadAnswer);
    }
}
