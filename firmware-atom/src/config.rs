//! Everything about the arm the Atom must know, with the real arm's values as the default and
//! one validation point ([`AtomConfig::validate`]).

use protocol_core::units::{Centideg, Steps};

/// Number of arm joints (servos 1..6).
pub const JOINTS: usize = 6;
/// Number of servos on the bus: the six joints and the gripper.
pub const SERVOS: usize = 7;
/// Index of the gripper in per-servo arrays (servo id 7 on the real arm).
pub const GRIPPER: usize = 6;

/// Encoder steps per full turn (`docs/servo-bus.md`).
pub const STEPS_PER_TURN: i32 = 4096;
/// Encoder reading at 0 degrees.
pub const STEPS_ZERO: i32 = 2048;

/// True if `steps` is an encoder position, 0..=4095 (a value from the wire may be 4096).
pub fn in_encoder_range(steps: Steps) -> bool {
    (0..STEPS_PER_TURN).contains(&i32::from(steps.0))
}

/// Direction of a joint: whether more encoder steps mean more degrees.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum JointSign {
    /// +steps = +degrees.
    Positive,
    /// +steps = -degrees.
    Negative,
}

/// Lower and upper limit of one joint.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct JointLimit {
    /// Smallest angle a goal may have.
    pub min: Centideg,
    /// Largest angle a goal may have.
    pub max: Centideg,
}

impl JointLimit {
    /// A limit from degrees.
    pub const fn degrees(min: i16, max: i16) -> Self {
        Self {
            min: Centideg(min * 100),
            max: Centideg(max * 100),
        }
    }

    /// True if `angle` lies within the limit (ends included).
    pub fn contains(&self, angle: Centideg) -> bool {
        self.min <= angle && angle <= self.max
    }
}

/// The factory joint range of the myCobot 280 M5, degrees: J1 +-168, J2 +-140, J3 +-150,
/// J4 +-150, J5 -155..+160, J6 +-180. Source: pymycobot 4.0.7's own table for `MyCobot280`
/// (`robot_info.py`, `angles_min` / `angles_max`), the range the vendor's client enforces
/// (`docs/kinematics.md`). A hard outer bound: the limits may be narrowed at run time
/// (0x4C/0x4D), never widened beyond it.
pub const FACTORY_LIMITS: [JointLimit; JOINTS] = [
    JointLimit::degrees(-168, 168),
    JointLimit::degrees(-140, 140),
    JointLimit::degrees(-150, 150),
    JointLimit::degrees(-150, 150),
    JointLimit::degrees(-155, 160),
    JointLimit::degrees(-180, 180),
];

/// The joint limits at boot: the factory range.
pub const DEFAULT_LIMITS: [JointLimit; JOINTS] = FACTORY_LIMITS;

/// Speeds and accelerations at 100 % (`docs/kinematics.md`: joints up to 150 deg/s and 200 deg/s^2,
/// Cartesian up to 100 mm/s), and what the servos can do.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct MotionLimits {
    /// Fastest joint speed, centidegrees per second.
    pub joint_speed_centideg_per_s: u32,
    /// Fastest joint acceleration, centidegrees per second squared.
    pub joint_accel_centideg_per_s2: u32,
    /// Fastest Cartesian speed, tenth-millimetres per second.
    pub linear_speed_decimm_per_s: u32,
    /// Fastest rotation speed of jog rpy and linear moves, centidegrees per second.
    pub rotation_speed_centideg_per_s: u32,
    /// Acceleration of the end along a Cartesian path (lines, Cartesian jogs), tenth-millimetres
    /// per second squared: how fast a path speeds up and slows down at its ends.
    pub linear_accel_decimm_per_s2: u32,
    /// The fastest a joint servo can speed up or brake, steps per second squared: what stopping
    /// and following a stream assume. 11 400 (1 000 deg/s^2, acceleration register 114): below
    /// what measured STS3215 models reach with the myCobot's position gains (`docs/motion.md`),
    /// so a braking joint never overshoots the point it is told to stop at.
    pub servo_accel_steps_per_s2: u32,
    /// The fastest a joint servo's shaft can turn, steps per second: 3 400 (about 300 deg/s,
    /// above the STS3215's 270 deg/s at 12 V). What a goal speed of 0 means, and how far a
    /// joint can have turned between two state reads: a reading further from the last one is
    /// not believed (`bank::readback`).
    pub servo_speed_max_steps_per_s: u32,
}

impl Default for MotionLimits {
    fn default() -> Self {
        Self {
            joint_speed_centideg_per_s: 15_000,
            joint_accel_centideg_per_s2: 20_000,
            linear_speed_decimm_per_s: 1_000,
            rotation_speed_centideg_per_s: 9_000,
            linear_accel_decimm_per_s2: 5_000,
            servo_accel_steps_per_s2: 11_400,
            servo_speed_max_steps_per_s: 3_400,
        }
    }
}

/// The gripper servo's encoder range: value 0 (closed) .. 100 (open) maps linearly onto
/// `closed ..= open`. Calibration (0x68) makes the present position the new `closed` (the servo
/// is told "current position = 2048") and keeps the span.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct GripperRange {
    /// Encoder position of gripper value 0 (closed).
    pub closed: Steps,
    /// Encoder position of gripper value 100 (open).
    pub open: Steps,
}

impl Default for GripperRange {
    /// Closed at the calibrated zero 2048, open a quarter turn (1024 steps, 90 deg) away: the
    /// travel of the myCobot parallel gripper's crank.
    fn default() -> Self {
        Self {
            closed: Steps(2048),
            open: Steps(2048 + 1024),
        }
    }
}

/// Time budgets of the servo bus and the host link, in microseconds.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct TimingBudget {
    /// Extra time allowed for a servo reply beyond instruction wire time + the worst
    /// turnaround + reply wire time. 150 us covers the servo's return delay register (default
    /// 0 on the arm) plus scheduling jitter of the board loop.
    pub reply_margin_us: u64,
    /// How often a servo transaction that expects a reply is retried after a timeout or a bad
    /// checksum before the command fails (`docs/servo-bus.md`: corrupted replies are retried).
    pub retries: u8,
    /// Consecutive missed state reads after which a servo is reported as not answering. Three
    /// misses = three refresh rounds, about 12 ms: one collision never marks a servo dead.
    pub misses_before_lost: u8,
    /// Period of the straight-line and jog interpolators: a new set of goals every 20 ms, short
    /// enough that the servos' own ramp keeps the path within a fraction of a millimetre.
    pub interpolation_period_us: u64,
    /// A continuous jog (0x30..0x32) stops if no host command (other than the Basic's probe,
    /// 0x12) arrives for this long. 2 s: long
    /// enough for a script that jogs, sleeps a second and stops (pymycobot has no keep-alive),
    /// short enough that a lost link cannot drive a joint far (at most 2 s of motion).
    pub jog_watchdog_us: u64,
}

impl Default for TimingBudget {
    fn default() -> Self {
        Self {
            reply_margin_us: 150,
            retries: 2,
            misses_before_lost: 3,
            interpolation_period_us: 20_000,
            jog_watchdog_us: 2_000_000,
        }
    }
}

/// Why an [`AtomConfig`] cannot be used.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum ConfigError {
    /// A servo id is outside 0..=0xFC or used twice.
    BadServoId,
    /// A joint limit has min > max or lies outside the factory range ([`FACTORY_LIMITS`]).
    BadJointLimit,
    /// The gripper range is empty or outside 0..4095.
    BadGripperRange,
    /// A speed, acceleration or period is zero, or the servo acceleration is outside what the
    /// acceleration register can express (100..=25 400 steps/s^2).
    BadTiming,
}

/// The Atom's configuration. `Default` is the real arm.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct AtomConfig {
    /// Bus ids of joints 1..6 and the gripper (real arm: 1..=7).
    pub servo_ids: [u8; SERVOS],
    /// Direction of each joint: the one place that says whether +steps is +degrees.
    pub joint_signs: [JointSign; JOINTS],
    /// Joint limits at boot (narrowed at run time with 0x4C/0x4D), within [`FACTORY_LIMITS`].
    pub joint_limits: [JointLimit; JOINTS],
    /// Speeds at 100 %.
    pub motion: MotionLimits,
    /// Gripper encoder range.
    pub gripper: GripperRange,
    /// Bus and host-link time budgets.
    pub timing: TimingBudget,
    /// Whether the Atom starts with torque on (the virtual robot); on the real arm the Basic
    /// sends power on (0x10) at boot.
    pub powered_at_boot: bool,
}

impl Default for AtomConfig {
    fn default() -> Self {
        Self {
            servo_ids: [1, 2, 3, 4, 5, 6, 7],
            joint_signs: [JointSign::Positive; JOINTS],
            joint_limits: DEFAULT_LIMITS,
            motion: MotionLimits::default(),
            gripper: GripperRange::default(),
            timing: TimingBudget::default(),
            powered_at_boot: false,
        }
    }
}

impl AtomConfig {
    /// Checks every field; the one place a bad configuration is caught.
    pub fn validate(&self) -> Result<(), ConfigError> {
        for (i, &id) in self.servo_ids.iter().enumerate() {
            let dup = self.servo_ids.iter().skip(i + 1).any(|&other| other == id);
            if id > protocol_core::servo::MAX_ID || dup {
                return Err(ConfigError::BadServoId);
            }
        }
        if self
            .joint_limits
            .iter()
            .zip(&FACTORY_LIMITS)
            .any(|(l, f)| l.min > l.max || l.min < f.min || l.max > f.max)
        {
            return Err(ConfigError::BadJointLimit);
        }
        let (closed, open) = (self.gripper.closed.0, self.gripper.open.0);
        if closed == open || !(0..4096).contains(&closed) || !(0..4096).contains(&open) {
            return Err(ConfigError::BadGripperRange);
        }
        let m = &self.motion;
        let t = &self.timing;
        if m.joint_speed_centideg_per_s == 0
            || m.joint_accel_centideg_per_s2 == 0
            || m.linear_speed_decimm_per_s == 0
            || m.rotation_speed_centideg_per_s == 0
            || m.linear_accel_decimm_per_s2 == 0
            || !(100..=25_400).contains(&m.servo_accel_steps_per_s2)
            || t.interpolation_period_us == 0
            || t.misses_before_lost == 0
        {
            return Err(ConfigError::BadTiming);
        }
        Ok(())
    }

    /// The fastest joint speed at `speed_percent`, steps per second (at least 1).
    pub fn joint_speed_steps(&self, speed_percent: u8) -> u32 {
        let pct = u32::from(speed_percent.clamp(1, 100));
        (centideg_to_steps(self.motion.joint_speed_centideg_per_s) * pct / 100).max(1)
    }

    /// The acceleration register value of the fastest joint in a planned joint move (100
    /// steps/s^2 units, 1..=254).
    pub fn joint_accel_register(&self) -> u8 {
        (centideg_to_steps(self.motion.joint_accel_centideg_per_s2) / 100).clamp(1, 254) as u8
    }

    /// The acceleration register (100 steps/s^2 units) of the servos' full acceleration
    /// ([`MotionLimits::servo_accel_steps_per_s2`]).
    pub fn servo_accel_register(&self) -> u8 {
        self.motion
            .servo_accel_steps_per_s2
            .div_ceil(100)
            .clamp(1, 254) as u8
    }

    /// Joint angle of encoder position `millisteps` (thousandths of a step) of joint `joint`,
    /// rounded to the nearest centidegree within +-180 degrees.
    pub fn millisteps_to_angle(&self, joint: usize, millisteps: i64) -> Centideg {
        let delta = millisteps - i64::from(STEPS_ZERO) * 1000;
        let scale = i64::from(STEPS_PER_TURN) * 1000;
        let centideg = (delta * 36_000 + delta.signum() * scale / 2) / scale;
        let signed = match self.joint_signs.get(joint) {
            Some(JointSign::Negative) => -centideg,
            _ => centideg,
        };
        Centideg(signed.clamp(-18_000, 18_000) as i16)
    }

    /// Encoder position of joint `joint` at `centideg`, in thousandths of a step (unrounded,
    /// not limited to one turn).
    pub fn angle_to_millisteps(&self, joint: usize, centideg: i32) -> i64 {
        let a = match self.joint_signs.get(joint) {
            Some(JointSign::Negative) => -i64::from(centideg),
            _ => i64::from(centideg),
        };
        i64::from(STEPS_ZERO) * 1000 + a * i64::from(STEPS_PER_TURN) * 1000 / 36_000
    }

    /// Joint angle of encoder position `steps` of joint `joint` (0-based).
    pub fn steps_to_angle(&self, joint: usize, steps: Steps) -> Centideg {
        let delta = i32::from(steps.0) - STEPS_ZERO;
        let centideg = (delta * 36_000 + delta.signum() * STEPS_PER_TURN / 2) / STEPS_PER_TURN;
        let signed = match self.joint_signs.get(joint) {
            Some(JointSign::Negative) => -centideg,
            _ => centideg,
        };
        Centideg(signed.clamp(-18_000, 18_000) as i16)
    }

    /// Encoder position of joint `joint` (0-based) at `angle`.
    pub fn angle_to_steps(&self, joint: usize, angle: Centideg) -> Steps {
        let a = i32::from(angle.0);
        let a = match self.joint_signs.get(joint) {
            Some(JointSign::Negative) => -a,
            _ => a,
        };
        let delta = (a * STEPS_PER_TURN + a.signum() * 18_000) / 36_000;
        Steps((STEPS_ZERO + delta).clamp(0, STEPS_PER_TURN - 1) as i16)
    }
}

/// Steps (per second, per second squared) of an angle (speed, acceleration) in centidegrees.
pub fn centideg_to_steps(centideg: u32) -> u32 {
    (u64::from(centideg) * STEPS_PER_TURN as u64 / 36_000) as u32
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn default_is_valid() {
        assert_eq!(AtomConfig::default().validate(), Ok(()));
    }

    #[test]
    fn validation_catches_each_mistake() {
        let mut c = AtomConfig::default();
        c.servo_ids[3] = 2;
        assert_eq!(c.validate(), Err(ConfigError::BadServoId));
        let mut c = AtomConfig::default();
        c.joint_limits[0] = JointLimit::degrees(10, -10);
        assert_eq!(c.validate(), Err(ConfigError::BadJointLimit));
        let mut c = AtomConfig::default();
        c.gripper.open = c.gripper.closed;
        assert_eq!(c.validate(), Err(ConfigError::BadGripperRange));
        let mut c = AtomConfig::default();
        c.timing.interpolation_period_us = 0;
        assert_eq!(c.validate(), Err(ConfigError::BadTiming));
    }

    #[test]
    fn angle_and_steps_round_trip_within_one_step() {
        let mut c = AtomConfig::default();
        c.joint_signs[1] = JointSign::Negative;
        assert_eq!(c.angle_to_steps(0, Centideg(0)), Steps(2048));
        assert_eq!(c.angle_to_steps(0, Centideg(9000)), Steps(3072));
        assert_eq!(c.angle_to_steps(1, Centideg(9000)), Steps(1024));
        for a in (-18_000i16..=18_000).step_by(7) {
            for j in 0..2 {
                let back = c.steps_to_angle(j, c.angle_to_steps(j, Centideg(a)));
                // One step is 8.8 centidegrees; +180 deg clamps to step 4095.
                assert!(
                    (i32::from(back.0) - i32::from(a)).abs() <= 9,
                    "{a} -> {back:?}"
                );
            }
        }
    }
}
