//! The arm's link geometry (standard DH, `docs/kinematics.md`) and the forward chain of link
//! transforms. The parameters live here and only here, so a calibrated set can replace them.

use crate::fixed::{Angle, ONE};
use crate::pose::JointAngles;
use crate::transform::{LEN_PER_TENTH_MM, Len, Rotation, Transform};

/// Internal length units per micrometre.
const LEN_PER_UM: i64 = LEN_PER_TENTH_MM / 100;

/// Link lengths of a six-axis arm of the Universal-Robots type (joints 2, 3, 4 parallel, offset
/// wrist): DH alpha = (+90, 0, 0, +90, -90, 0) deg, and every d and a not named here is zero.
/// Lengths in micrometres (each within +-1 m), signs as in the DH table.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct ArmGeometry {
    /// d1: base to shoulder height, um.
    pub d1_um: i32,
    /// a2: upper arm length (negative in the vendor table), um.
    pub a2_um: i32,
    /// a3: forearm length (negative in the vendor table), um.
    pub a3_um: i32,
    /// d4: shoulder-to-wrist side offset, um.
    pub d4_um: i32,
    /// d5: wrist 1 to wrist 2 offset, um.
    pub d5_um: i32,
    /// d6: wrist 2 to flange, um.
    pub d6_um: i32,
    /// theta_i = q_i + offset_i: the DH angle at protocol angle zero, centidegrees.
    pub theta_offset_centideg: [i32; 6],
}

impl ArmGeometry {
    /// The vendor-published DH table of the myCobot 280 M5.
    pub const MYCOBOT_280: Self = Self {
        d1_um: 131_220,
        a2_um: -110_400,
        a3_um: -96_000,
        d4_um: 63_400,
        d5_um: 75_050,
        d6_um: 45_600,
        theta_offset_centideg: [0, -9000, 0, -9000, 9000, 0],
    };
}

impl Default for ArmGeometry {
    fn default() -> Self {
        Self::MYCOBOT_280
    }
}

/// DH alpha of each joint, centidegrees: the structure the closed-form IK relies on (the same
/// for every [`ArmGeometry`]). Published for models drawn outside this crate (the virtual
/// robot's 3D view); `ALPHA_SIN_COS` is the form the chain computes with.
pub const DH_ALPHA_CENTIDEG: [i32; 6] = [9000, 0, 0, 9000, -9000, 0];

/// [`DH_ALPHA_CENTIDEG`] as (sin, cos) in Q30.
const ALPHA_SIN_COS: [(i64, i64); 6] =
    [(ONE, 0), (0, ONE), (0, ONE), (ONE, 0), (-ONE, 0), (0, ONE)];

/// The geometry in internal length units, with the DH angle offsets as binary angles.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub(crate) struct Links {
    /// d of each joint.
    pub d: [Len; 6],
    /// a of each joint.
    pub a: [Len; 6],
    /// theta offset of each joint.
    pub offset: [Angle; 6],
}

impl Links {
    /// Internal form of `g`.
    pub fn new(g: &ArmGeometry) -> Self {
        let len = |um: i32| i64::from(um) * LEN_PER_UM;
        let [o1, o2, o3, o4, o5, o6] = g.theta_offset_centideg.map(Angle::from_centideg);
        Self {
            d: [len(g.d1_um), 0, 0, len(g.d4_um), len(g.d5_um), len(g.d6_um)],
            a: [0, len(g.a2_um), len(g.a3_um), 0, 0, 0],
            offset: [o1, o2, o3, o4, o5, o6],
        }
    }

    /// A_i = Rz(theta) * Tz(d_i) * Tx(a_i) * Rx(alpha_i) for joint `i` (0-based) at DH angle
    /// `theta`.
    pub fn link(&self, i: usize, theta: Angle) -> Transform {
        let (s, c) = theta.sin_cos();
        let (sa, ca) = ALPHA_SIN_COS.get(i).copied().unwrap_or((0, ONE));
        let d = self.d.get(i).copied().unwrap_or(0);
        let a = self.a.get(i).copied().unwrap_or(0);
        let m = crate::fixed::mul;
        Transform {
            rotation: Rotation([
                [c, -m(s, ca), m(s, sa)],
                [s, m(c, ca), -m(c, sa)],
                [0, sa, ca],
            ]),
            position: [m(a, c), m(a, s), d],
        }
    }

    /// DH angle of joint `i` (0-based) at protocol angle `q_centideg`.
    pub fn theta(&self, i: usize, q_centideg: i32) -> Angle {
        Angle::from_centideg(q_centideg).add(self.offset.get(i).copied().unwrap_or(Angle::ZERO))
    }

    /// The flange in the base frame at joint angles `q`: A_1 * ... * A_6.
    pub fn flange(&self, q: &JointAngles) -> Transform {
        let mut t = Transform::IDENTITY;
        for (i, &qi) in q.0.iter().enumerate() {
            t = t.then(&self.link(i, self.theta(i, qi)));
        }
        t
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_published_alphas_are_the_ones_the_chain_uses() {
        for (&centideg, &sin_cos) in DH_ALPHA_CENTIDEG.iter().zip(ALPHA_SIN_COS.iter()) {
            assert_eq!(
                Angle::from_centideg(centideg).sin_cos(),
                sin_cos,
                "{centideg}"
            );
        }
    }
}
