//! Rigid transforms in fixed point: rotation matrices in Q30, positions in [`Len`] units, and the
//! conversion to and from the wire's [`Pose`] (0.1 mm, 0.01 deg, R = Rz(rz) * Ry(ry) * Rx(rx)).

use crate::Pose;
use crate::fixed::{Angle, ONE, atan2, mul, sqrt};

/// Internal length unit: 1/16 micrometre, i.e. this many units per 0.1 mm. Fine enough that
/// rounding never shows at the wire's 0.1 mm; coarse enough that a Q30 rotation times a
/// position up to [`POSITION_LIMIT`] stays inside `i64`.
pub const LEN_PER_TENTH_MM: i64 = 1600;

/// Largest position coordinate accepted from a [`Pose`], in 0.1 mm (10 m, far beyond the wire's
/// i16 range); larger values saturate, which keeps every product inside `i64`.
pub const POSITION_LIMIT_TENTH_MM: i32 = 100_000;

/// Below this |cos(ry)| (Q30, about 1e-5) the RPY triple is at gimbal lock and rz is set to 0.
const GIMBAL_LOCK_COS: i64 = 1 << 13;

/// A length in internal units ([`LEN_PER_TENTH_MM`] per 0.1 mm).
pub type Len = i64;

/// A 3x3 rotation matrix, row-major, entries Q30.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct Rotation(pub [[i64; 3]; 3]);

impl Rotation {
    /// The identity rotation.
    pub const IDENTITY: Self = Self([[ONE, 0, 0], [0, ONE, 0], [0, 0, ONE]]);

    /// The entry at row `r`, column `c` (0 outside the matrix).
    #[inline]
    pub fn at(&self, r: usize, c: usize) -> i64 {
        self.0
            .get(r)
            .and_then(|row| row.get(c))
            .copied()
            .unwrap_or(0)
    }

    /// Column `c` as a vector.
    pub fn column(&self, c: usize) -> [i64; 3] {
        [self.at(0, c), self.at(1, c), self.at(2, c)]
    }

    /// R = Rz(rz) * Ry(ry) * Rx(rx).
    pub fn from_rpy(rx: Angle, ry: Angle, rz: Angle) -> Self {
        let (sa, ca) = rx.sin_cos();
        let (sb, cb) = ry.sin_cos();
        let (sc, cc) = rz.sin_cos();
        Self([
            [
                mul(cc, cb),
                mul(mul(cc, sb), sa) - mul(sc, ca),
                mul(mul(cc, sb), ca) + mul(sc, sa),
            ],
            [
                mul(sc, cb),
                mul(mul(sc, sb), sa) + mul(cc, ca),
                mul(mul(sc, sb), ca) - mul(cc, sa),
            ],
            [-sb, mul(cb, sa), mul(cb, ca)],
        ])
    }

    /// The (rx, ry, rz) with R = Rz(rz) * Ry(ry) * Rx(rx), ry in [-90, 90] deg; at gimbal lock
    /// (ry = +-90 deg) rz is 0 and rx carries the whole rotation about the vertical.
    pub fn to_rpy(&self) -> (Angle, Angle, Angle) {
        let cos_ry = sqrt(self.at(0, 0) * self.at(0, 0) + self.at(1, 0) * self.at(1, 0));
        let ry = atan2(-self.at(2, 0), cos_ry);
        if cos_ry < GIMBAL_LOCK_COS {
            // R = Ry(ry) * Rx(rx): r11 = cos rx, r12 = -sin rx.
            return (atan2(-self.at(1, 2), self.at(1, 1)), ry, Angle::ZERO);
        }
        let rz = atan2(self.at(1, 0), self.at(0, 0));
        let rx = atan2(self.at(2, 1), self.at(2, 2));
        (rx, ry, rz)
    }

    /// The product self * other.
    #[must_use]
    pub fn mul(&self, other: &Self) -> Self {
        let mut out = [[0i64; 3]; 3];
        for (r, row) in out.iter_mut().enumerate() {
            for (c, cell) in row.iter_mut().enumerate() {
                *cell = (self.at(r, 0) * other.at(0, c)
                    + self.at(r, 1) * other.at(1, c)
                    + self.at(r, 2) * other.at(2, c))
                    >> 30;
            }
        }
        Self(out)
    }

    /// The transpose (= inverse of a rotation).
    #[must_use]
    pub fn transpose(&self) -> Self {
        let mut out = [[0i64; 3]; 3];
        for (r, row) in out.iter_mut().enumerate() {
            for (c, cell) in row.iter_mut().enumerate() {
                *cell = self.at(c, r);
            }
        }
        Self(out)
    }

    /// The rotated vector self * v (v in any unit that keeps |v| * 2^30 * 3 inside i64).
    pub fn apply(&self, v: &[i64; 3]) -> [i64; 3] {
        let [x, y, z] = *v;
        let row = |r: usize| (self.at(r, 0) * x + self.at(r, 1) * y + self.at(r, 2) * z) >> 30;
        [row(0), row(1), row(2)]
    }
}

/// A rigid transform: rotate, then translate by `position` ([`Len`] units).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct Transform {
    /// Orientation of the moving frame in the fixed frame.
    pub rotation: Rotation,
    /// Origin of the moving frame in the fixed frame, [`Len`] units.
    pub position: [Len; 3],
}

impl Transform {
    /// The identity transform.
    pub const IDENTITY: Self = Self {
        rotation: Rotation::IDENTITY,
        position: [0; 3],
    };

    /// The transform a wire pose describes (positions saturated at [`POSITION_LIMIT_TENTH_MM`]).
    pub fn from_pose(pose: &Pose) -> Self {
        let len = |tenths: i32| {
            i64::from(tenths.clamp(-POSITION_LIMIT_TENTH_MM, POSITION_LIMIT_TENTH_MM))
                * LEN_PER_TENTH_MM
        };
        Self {
            rotation: Rotation::from_rpy(
                Angle::from_centideg(pose.rx),
                Angle::from_centideg(pose.ry),
                Angle::from_centideg(pose.rz),
            ),
            position: [len(pose.x), len(pose.y), len(pose.z)],
        }
    }

    /// The wire pose of this transform, each value rounded to the nearest unit.
    pub fn to_pose(&self) -> Pose {
        let tenths = |v: Len| {
            let half = LEN_PER_TENTH_MM / 2;
            let rounded = if v >= 0 {
                (v + half) / LEN_PER_TENTH_MM
            } else {
                (v - half) / LEN_PER_TENTH_MM
            };
            rounded.clamp(i64::from(i32::MIN), i64::from(i32::MAX)) as i32
        };
        let (rx, ry, rz) = self.rotation.to_rpy();
        let [x, y, z] = self.position;
        Pose {
            x: tenths(x),
            y: tenths(y),
            z: tenths(z),
            rx: rx.to_centideg(),
            ry: ry.to_centideg(),
            rz: rz.to_centideg(),
        }
    }

    /// The composition self * other (other expressed in self's moving frame).
    #[must_use]
    pub fn then(&self, other: &Self) -> Self {
        let moved = self.rotation.apply(&other.position);
        Self {
            rotation: self.rotation.mul(&other.rotation),
            position: [
                self.position[0] + moved[0],
                self.position[1] + moved[1],
                self.position[2] + moved[2],
            ],
        }
    }

    /// The inverse transform.
    #[must_use]
    pub fn inverse(&self) -> Self {
        let rotation = self.rotation.transpose();
        let back = rotation.apply(&self.position);
        Self {
            rotation,
            position: [-back[0], -back[1], -back[2]],
        }
    }
}
