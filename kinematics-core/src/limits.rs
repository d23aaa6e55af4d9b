//! Joint limits as run-time data, and wrapping an angle by +-360 deg into them.

use crate::pose::JointAngles;

/// Centidegrees in a full turn.
const TURN_CENTIDEG: i32 = 36_000;

/// Per-joint limits in centidegrees (inclusive); `Default` = the factory range of
/// `docs/kinematics.md` (J1 +-168, J2 +-140, J3 +-150, J4 +-150, J5 -155..+160, J6 +-180 deg).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct JointLimits {
    /// Lowest allowed angle of each joint, centidegrees.
    pub min: [i32; 6],
    /// Highest allowed angle of each joint, centidegrees.
    pub max: [i32; 6],
}

impl Default for JointLimits {
    fn default() -> Self {
        Self {
            min: [-16_800, -14_000, -15_000, -15_000, -15_500, -18_000],
            max: [16_800, 14_000, 15_000, 15_000, 16_000, 18_000],
        }
    }
}

impl JointLimits {
    /// Whether every joint of `q` is within its limits.
    pub fn contains(&self, q: &JointAngles) -> bool {
        self.violated_joint(q).is_none()
    }

    /// The first joint (0-based) of `q` outside its limits, if any.
    pub fn violated_joint(&self, q: &JointAngles) -> Option<usize> {
        q.0.iter()
            .zip(self.min.iter().zip(self.max.iter()))
            .position(|(&v, (&lo, &hi))| v < lo || v > hi)
    }

    /// Joint `joint`'s angle `q_centideg` (in -180..=180 deg) moved by a multiple of 360 deg into
    /// the limits, choosing the value nearest `seed_centideg`; `None` if no multiple fits.
    pub fn wrap_into(&self, joint: usize, q_centideg: i32, seed_centideg: i32) -> Option<i32> {
        let (lo, hi) = (*self.min.get(joint)?, *self.max.get(joint)?);
        // The multiple of a turn that brings q nearest the seed, then the neighbours on either
        // side in case that one is outside the limits.
        // (A seed outside the limits counts as the nearest limit.)
        let (q, seed) = (
            i64::from(q_centideg),
            i64::from(seed_centideg.clamp(lo, hi.max(lo))),
        );
        let turn = i64::from(TURN_CENTIDEG);
        let nearest = q + (seed - q + turn / 2).div_euclid(turn) * turn;
        let fits = |v: i64| v >= i64::from(lo) && v <= i64::from(hi);
        let below = nearest - turn;
        let above = nearest + turn;
        let pick = if fits(nearest) {
            nearest
        } else if fits(below) && (!fits(above) || seed - below <= above - seed) {
            below
        } else if fits(above) {
            above
        } else {
            return None;
        };
        i32::try_from(pick).ok()
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn default_limits_match_current_firmware() {
        let l = JointLimits::default();
        assert!(l.contains(&JointAngles([
            16_800, -14_000, 15_000, -15_000, 16_000, -18_000
        ])));
        assert_eq!(
            l.violated_joint(&JointAngles([0, 0, 0, 0, -15_501, 0])),
            Some(4)
        );
        assert_eq!(
            l.violated_joint(&JointAngles([16_801, 0, 0, 0, 0, 0])),
            Some(0)
        );
    }

    #[test]
    fn wrapping_prefers_the_value_nearest_the_seed() {
        let l = JointLimits::default();
        // J6 +-180: -179 deg is also reachable as +181? No: 181 is outside, so -179 stays.
        assert_eq!(l.wrap_into(5, -17_900, 17_000), Some(-17_900));
        // J6 at exactly 180 may be written as -180 or +180: pick the side of the seed.
        assert_eq!(l.wrap_into(5, -18_000, 17_000), Some(18_000));
        assert_eq!(l.wrap_into(5, 18_000, -17_000), Some(-18_000));
        // A wide custom limit lets -170 deg become +190 deg when the seed is there.
        let wide = JointLimits {
            min: [-36_000; 6],
            max: [36_000; 6],
        };
        assert_eq!(wide.wrap_into(0, -17_000, 18_500), Some(19_000));
        // J1 +-168: 170 deg does not fit at any multiple of a turn.
        assert_eq!(l.wrap_into(0, 17_000, 0), None);
        // A seed far outside the limits still finds the in-limit value.
        assert_eq!(l.wrap_into(0, 10_000, i32::MAX), Some(10_000));
        assert_eq!(wide.wrap_into(0, 10_000, i32::MIN), Some(-26_000));
    }
}
