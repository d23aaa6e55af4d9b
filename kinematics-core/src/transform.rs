//! Rigid transforms in fixed point: rotation matrices in Q30, positions in [`Len`] units, and the
//! conversion to and from the wire's [`Pose`] (0.1 mm, 0.01 deg, R = Rz(rz) * Ry(ry) * Rx(rx)).

use crate::fixed::{Angle, ONE, atan2, mul, ratio, sqrt};
use crate::pose::Pose;

/// Internal length unit: 1/16 micrometre, i.e. this many units per 0.1 mm. Fine enough that
/// rounding never shows at the wire's 0.1 mm; coarse enough that a Q30 rotation times a
/// position up to [`POSITION_LIMIT_TENTH_MM`] stays inside `i64`.
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

    /// The rotation by `angle` about the unit axis `axis` (Q30), by Rodrigues' formula.
    pub fn about_axis(axis: &[i64; 3], angle: Angle) -> Self {
        let (s, c) = angle.sin_cos();
        let v = ONE - c;
        let [x, y, z] = *axis;
        let (xs, ys, zs) = (mul(x, s), mul(y, s), mul(z, s));
        let (xv, yv) = (mul(x, v), mul(y, v));
        Self([
            [c + mul(xv, x), mul(xv, y) - zs, mul(xv, z) + ys],
            [mul(xv, y) + zs, c + mul(yv, y), mul(yv, z) - xs],
            [mul(xv, z) - ys, mul(yv, z) + xs, c + mul(mul(z, v), z)],
        ])
    }

    /// The shortest rotation that equals this one, as (unit axis Q30, angle in 0..=180 deg);
    /// the axis is x for the identity.
    pub fn to_axis_angle(&self) -> ([i64; 3], Angle) {
        let m = |r, c| self.at(r, c);
        let trace = m(0, 0) + m(1, 1) + m(2, 2);
        // Shepperd: the quaternion (w, x, y, z) scaled by 4 times its largest component, taken
        // from whichever of 1 + trace, 1 + 2 r_ii - trace is largest (the well-conditioned one).
        let diagonal = [
            ONE + trace,
            ONE + 2 * m(0, 0) - trace,
            ONE + 2 * m(1, 1) - trace,
            ONE + 2 * m(2, 2) - trace,
        ];
        // 4wx, 4wy, 4wz.
        let (wx, wy, wz) = (m(2, 1) - m(1, 2), m(0, 2) - m(2, 0), m(1, 0) - m(0, 1));
        // 4xy, 4xz, 4yz.
        let (xy, xz, yz) = (m(0, 1) + m(1, 0), m(0, 2) + m(2, 0), m(1, 2) + m(2, 1));
        let [dw, dx, dy, dz] = diagonal;
        let largest = dw.max(dx).max(dy).max(dz);
        let mut q = if largest == dw {
            [dw, wx, wy, wz]
        } else if largest == dx {
            [wx, dx, xy, xz]
        } else if largest == dy {
            [wy, xy, dy, yz]
        } else {
            [wz, xz, yz, dz]
        };
        if q[0] < 0 {
            q = q.map(|v| -v);
        }
        // Components are below 4.0 (Q30): a quarter keeps the sum of squares inside i64.
        let [w, x, y, z] = q.map(|v| v >> 2);
        let norm = sqrt(x * x + y * y + z * z);
        if norm == 0 {
            return ([ONE, 0, 0], Angle::ZERO);
        }
        let half = atan2(norm, w);
        ([x, y, z].map(|v| ratio(v << 30, norm)), half.add(half))
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

/// A rigid transform: rotate, then translate by `position` ([`Len`] units). Build it with
/// [`Transform::from_pose`] or from this crate's results: arbitrary field values (a rotation that
/// is not orthonormal, positions beyond a few [`POSITION_LIMIT_TENTH_MM`]) can overflow.
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

#[cfg(test)]
mod tests {
    use super::*;

    fn max_difference(a: &Rotation, b: &Rotation) -> i64 {
        (0..3)
            .flat_map(|r| (0..3).map(move |c| (r, c)))
            .map(|(r, c)| (a.at(r, c) - b.at(r, c)).abs())
            .max()
            .unwrap_or(0)
    }

    /// 1e-6 in Q30: far below the 0.01 deg (1.7e-4) the wire shows.
    const CLOSE: i64 = 1 << 10;

    #[test]
    fn rpy_round_trips_away_from_gimbal_lock() {
        for rx in (-17_900..=18_000).step_by(1_300) {
            for ry in (-8_900..=8_900).step_by(700) {
                for rz in (-18_000..=17_900).step_by(1_100) {
                    let pose = Pose {
                        rx,
                        ry,
                        rz,
                        ..Pose::default()
                    };
                    let back = Transform::from_pose(&pose).to_pose();
                    let same = |a: i32, b: i32| {
                        (a - b).rem_euclid(36_000).min((b - a).rem_euclid(36_000)) <= 1
                    };
                    assert!(
                        same(back.rx, rx) && same(back.ry, ry) && same(back.rz, rz),
                        "{pose:?} -> {back:?}"
                    );
                }
            }
        }
    }

    #[test]
    fn gimbal_lock_keeps_the_rotation() {
        for ry in [9_000, -9_000] {
            let pose = Pose {
                rx: 3_000,
                ry,
                rz: 2_000,
                ..Pose::default()
            };
            let t = Transform::from_pose(&pose);
            let back = t.to_pose();
            assert_eq!(back.rz, 0, "{back:?}");
            assert!(max_difference(&Transform::from_pose(&back).rotation, &t.rotation) < 1 << 17);
        }
    }

    #[test]
    fn axis_angle_reproduces_the_rotation_up_to_a_half_turn() {
        for rx in (-18_000..18_000).step_by(2_300) {
            for ry in (-9_000..=9_000).step_by(1_700) {
                for rz in (-18_000..18_000).step_by(2_900) {
                    let r = Transform::from_pose(&Pose {
                        rx,
                        ry,
                        rz,
                        ..Pose::default()
                    })
                    .rotation;
                    let (axis, angle) = r.to_axis_angle();
                    assert!(angle.to_centideg() >= 0, "{angle:?}");
                    let back = Rotation::about_axis(&axis, angle);
                    assert!(
                        max_difference(&back, &r) < CLOSE,
                        "{rx} {ry} {rz}: {back:?} vs {r:?}"
                    );
                }
            }
        }
        // Exactly half a turn about a skew axis, and the identity.
        let r = Transform::from_pose(&Pose {
            rx: 18_000,
            rz: 9_000,
            ..Pose::default()
        })
        .rotation;
        let (axis, angle) = r.to_axis_angle();
        assert_eq!(angle.to_centideg().abs(), 18_000);
        assert!(max_difference(&Rotation::about_axis(&axis, angle), &r) < CLOSE);
        assert_eq!(Rotation::IDENTITY.to_axis_angle().1, Angle::ZERO);
    }

    #[test]
    fn inverse_undoes_the_transform() {
        let t = Transform::from_pose(&Pose {
            x: 1234,
            y: -4321,
            z: 999,
            rx: 4500,
            ry: -3000,
            rz: 12_000,
        });
        let id = t.then(&t.inverse());
        assert!(max_difference(&id.rotation, &Rotation::IDENTITY) < CLOSE);
        assert!(id.position.iter().all(|v| v.abs() <= 4), "{id:?}");
    }

    #[test]
    fn huge_positions_saturate_instead_of_overflowing() {
        let t = Transform::from_pose(&Pose {
            x: i32::MAX,
            y: i32::MIN,
            z: 5,
            ..Pose::default()
        });
        let p = t.then(&t).to_pose();
        assert_eq!(
            (p.x, p.y, p.z),
            (
                2 * POSITION_LIMIT_TENTH_MM,
                -2 * POSITION_LIMIT_TENTH_MM,
                10
            )
        );
    }
}
