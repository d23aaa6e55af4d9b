//! Things the arm can run into: an obstacle is a rigid stop for one joint at an angle
//! ([`Obstacle`], `--obstacle J:DEG`), placed in that joint's simulated servo
//! ([`SimServo::add_obstacle`]). The firmware learns of it only through what the servo reports
//! on the bus (position, load, current, status), as on the real arm.

use std::fmt;
use std::str::FromStr;

use firmware_atom::{AtomConfig, JointSign};
use protocol_core::units::Centideg;

use sim_hw::{ServoChain, SimServo};

use super::arg_error::ArgError;

/// A rigid stop for joint `joint` (1..=6) at `angle`: the joint cannot move past it from the
/// side it is on when the stop is placed.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct Obstacle {
    /// The joint, 1..=6.
    pub joint: u8,
    /// Where the stop is, as the joint's angle.
    pub angle: Centideg,
}

impl Obstacle {
    /// Puts this stop into its joint's servo among `servos`, whose angles `config` maps onto
    /// encoder steps; `false` if there is no such servo.
    pub fn place(&self, servos: &mut ServoChain, config: &AtomConfig) -> bool {
        let Some(servo) = joint_servo(servos, config, self.joint) else {
            return false;
        };
        let index = usize::from(self.joint - 1);
        let steps = config.angle_to_steps(index, self.angle);
        servo.add_obstacle(steps.0.clamp(0, 4095) as u16);
        true
    }
}

/// Pushes joint `joint` (1..=6) with an external torque of `permille` thousandths of its
/// servo's maximum torque, towards higher angles for a positive value (0 lets go): someone
/// leaning on the arm ([`SimServo::push`]). `false` if there is no such joint.
pub fn push(servos: &mut ServoChain, config: &AtomConfig, joint: u8, permille: i16) -> bool {
    let Some(servo) = joint_servo(servos, config, joint) else {
        return false;
    };
    let towards_higher_steps = match config.joint_signs.get(usize::from(joint - 1)) {
        Some(JointSign::Negative) => permille.saturating_neg(),
        _ => permille,
    };
    servo.push(towards_higher_steps);
    true
}

/// The servo of joint `joint` (1..=6) among `servos`, as `config` maps joints onto bus ids.
fn joint_servo<'a>(
    servos: &'a mut ServoChain,
    config: &AtomConfig,
    joint: u8,
) -> Option<&'a mut SimServo> {
    if !(1..=6).contains(&joint) {
        return None;
    }
    let id = *config.servo_ids.get(usize::from(joint - 1))?;
    servos.get_mut(id)
}

impl FromStr for Obstacle {
    type Err = ArgError;

    /// `J:DEG`, e.g. `2:-30` or `1:45.5`: joint 1..=6, angle in degrees within -180..=180.
    fn from_str(text: &str) -> Result<Self, Self::Err> {
        let refuse = |why: &str| ArgError::new(text, why, "J:DEG");
        let (joint, degrees) = text.split_once(':').ok_or_else(|| refuse("no colon"))?;
        let joint: u8 = joint
            .trim()
            .parse()
            .ok()
            .filter(|j| (1..=6).contains(j))
            .ok_or_else(|| refuse("the joint is 1..6"))?;
        let degrees: f64 = degrees
            .trim()
            .parse()
            .ok()
            .filter(|d: &f64| d.is_finite() && d.abs() <= 180.0)
            .ok_or_else(|| refuse("the angle is -180..180 degrees"))?;
        Ok(Self {
            joint,
            angle: Centideg((degrees * 100.0).round() as i16),
        })
    }
}

impl fmt::Display for Obstacle {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        write!(
            f,
            "joint {} at {:.2} deg",
            self.joint,
            f64::from(self.angle.0) / 100.0
        )
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_joint_without_a_servo_gets_no_stop() {
        let mut servos = ServoChain::new();
        let obstacle = Obstacle {
            joint: 7,
            angle: Centideg(0),
        };
        assert!(!obstacle.place(&mut servos, &AtomConfig::default()));
    }

    #[test]
    fn parses_joint_and_degrees_and_refuses_the_rest() {
        assert_eq!(
            "2:-30".parse(),
            Ok(Obstacle {
                joint: 2,
                angle: Centideg(-3000)
            })
        );
        assert_eq!("6:45.25".parse::<Obstacle>().unwrap().angle, Centideg(4525));
        for bad in ["0:10", "7:10", "2", "2:181", "x:1", "1:nan", "1:"] {
            assert!(bad.parse::<Obstacle>().is_err(), "{bad}");
        }
    }

    #[test]
    fn the_stop_sits_at_the_joints_angle_whatever_its_sign() {
        let config = AtomConfig::default();
        for joint in 1..=6u8 {
            let obstacle = Obstacle {
                joint,
                angle: Centideg(2000),
            };
            let mut bus = sim_hw::Bus::mycobot(1);
            let mut servos = ServoChain::new();
            let id = config.servo_ids[usize::from(joint - 1)];
            servos.attach(&mut bus, sim_hw::SimServo::new(id, 2048));
            assert!(obstacle.place(&mut servos, &config));
            let beyond = config.angle_to_steps(usize::from(joint - 1), Centideg(4000));
            let servo = servos.get_mut(id).unwrap();
            servo.move_by_hand(beyond.0 as u16);
            let reached = config.steps_to_angle(
                usize::from(joint - 1),
                protocol_core::units::Steps(servo.present_position() as i16),
            );
            assert!((reached.0 - 2000).abs() <= 5, "joint {joint}: {reached:?}");
        }
    }
}
