//! Servo replies that come late or not at all, from the command line: `--late-replies ID:US`
//! (every answer of servo ID starts US microseconds late, past the Atom's deadline from about
//! 200 us on, and still takes the wire when it comes) and `--lost-replies ID:PER_MILLE` (that
//! many of every thousand answers never come), put into the simulated servo's
//! [`Faults`](sim_hw::Faults) ([`ReplyFault::apply`]).

use std::fmt;

use sim_hw::ServoChain;

use super::arg_error::ArgError;

/// Longest `--late-replies` delay, microseconds: 100 ms, far past any deadline.
pub const MAX_REPLY_DELAY_US: u32 = 100_000;

/// What happens to a servo's replies.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum ReplyTrouble {
    /// Each answer this many microseconds late.
    Late(u32),
    /// This many of every thousand answers lost.
    Lost(u16),
}

/// Servo `servo`'s replies made late or lost.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct ReplyFault {
    /// The servo's bus id, 1..=7 (7: the gripper).
    pub servo: u8,
    /// What happens to its replies.
    pub trouble: ReplyTrouble,
}

impl ReplyFault {
    /// `ID:US` (`--late-replies`): servo 1..=7, a delay of 0..=[`MAX_REPLY_DELAY_US`].
    pub fn late(text: &str) -> Result<Self, ArgError> {
        let (servo, value) = split(text, "ID:US")?;
        let delay = u32::try_from(value)
            .ok()
            .filter(|&us| us <= MAX_REPLY_DELAY_US)
            .ok_or_else(|| ArgError::new(text, "the delay is 0..100000 us", "ID:US"))?;
        Ok(Self {
            servo,
            trouble: ReplyTrouble::Late(delay),
        })
    }

    /// `ID:PER_MILLE` (`--lost-replies`): servo 1..=7, 0..=1000 of every thousand answers.
    pub fn lost(text: &str) -> Result<Self, ArgError> {
        let (servo, value) = split(text, "ID:PER_MILLE")?;
        let per_mille = u16::try_from(value)
            .ok()
            .filter(|&p| p <= 1000)
            .ok_or_else(|| ArgError::new(text, "0..1000 of every thousand", "ID:PER_MILLE"))?;
        Ok(Self {
            servo,
            trouble: ReplyTrouble::Lost(per_mille),
        })
    }

    /// Puts this fault into its servo among `servos`, keeping its other faults; `false` if
    /// there is no such servo.
    pub fn apply(&self, servos: &mut ServoChain) -> bool {
        let Some(servo) = servos.get_mut(self.servo) else {
            return false;
        };
        let mut faults = servo.faults();
        match self.trouble {
            ReplyTrouble::Late(us) => faults.reply_delay_us = us,
            ReplyTrouble::Lost(per_mille) => faults.dropped_per_mille = per_mille,
        }
        servo.set_faults(faults);
        true
    }
}

impl fmt::Display for ReplyFault {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self.trouble {
            ReplyTrouble::Late(us) => write!(f, "servo {} answers {us} us late", self.servo),
            ReplyTrouble::Lost(per_mille) => write!(
                f,
                "servo {} loses {per_mille} of every 1000 answers",
                self.servo
            ),
        }
    }
}

/// The servo id (1..=7) and the number of `text`, `ID:N`.
fn split(text: &str, form: &str) -> Result<(u8, u64), ArgError> {
    let (servo, value) = text
        .split_once(':')
        .ok_or_else(|| ArgError::new(text, "no colon", form))?;
    let servo: u8 = servo
        .trim()
        .parse()
        .ok()
        .filter(|id| (1..=7).contains(id))
        .ok_or_else(|| ArgError::new(text, "the servo is 1..7", form))?;
    let value: u64 = value
        .trim()
        .parse()
        .map_err(|_| ArgError::new(text, "not a whole number", form))?;
    Ok((servo, value))
}

#[cfg(test)]
mod tests {
    use super::*;
    use sim_hw::{Bus, Faults, SimServo};

    #[test]
    fn parses_servo_and_value_and_refuses_the_rest() {
        assert_eq!(
            ReplyFault::late("3:300"),
            Ok(ReplyFault {
                servo: 3,
                trouble: ReplyTrouble::Late(300)
            })
        );
        assert_eq!(
            ReplyFault::lost("7:1000").map(|f| f.trouble),
            Ok(ReplyTrouble::Lost(1000))
        );
        for bad in ["0:10", "8:10", "3", "3:-1", "3:x", "3:100001"] {
            assert!(ReplyFault::late(bad).is_err(), "{bad}");
        }
        assert!(ReplyFault::lost("1:1001").is_err());
    }

    #[test]
    fn both_go_into_the_servos_faults_beside_the_others() {
        let mut bus = Bus::mycobot(1);
        let mut servos = ServoChain::new();
        servos.attach(&mut bus, SimServo::new(2, 2048));
        servos.get_mut(2).unwrap().set_faults(Faults::OVERHEAT);
        assert!(ReplyFault::late("2:250").unwrap().apply(&mut servos));
        assert!(ReplyFault::lost("2:100").unwrap().apply(&mut servos));
        assert!(!ReplyFault::lost("5:100").unwrap().apply(&mut servos));
        let faults = servos.get(2).unwrap().faults();
        assert_eq!(
            (
                faults.overheat,
                faults.reply_delay_us,
                faults.dropped_per_mille
            ),
            (true, 250, 100)
        );
    }
}
