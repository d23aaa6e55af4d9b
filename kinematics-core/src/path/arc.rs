//! A circular arc through three poses: the position moves along the circle through the start,
//! the via point and the end, the orientation turns from the start's to the via's and on to the
//! end's, each about one axis (the shortest rotation), in proportion to the way along each part.
//!
//! The circle is found in integer arithmetic: with a = via - start and b = end - start (in
//! micrometres), its centre is start + (|a|^2 b - |b|^2 a) x (a x b) / (2 |a x b|^2), computed in
//! `i128` and checked, so no input overflows or panics. Points along it are centre + r (cos t e1 +
//! sin t e2) with e1 the unit vector towards the start and e2 = n x e1 in the arc's plane (n the
//! unit normal of a x b, so that turning from the start by increasing t meets the via point before
//! the end); t is a binary angle (2^32 per turn). Rounding keeps every point within a micrometre
//! of the exact circle (tests compare with f64 geometry).

use crate::fixed::{Angle, ONE, atan2, checked_div_i128, isqrt_u128, mul, ratio, sqrt};
use crate::transform::{LEN_PER_TENTH_MM, Rotation, Transform};

use super::{Path, UM_PER_CENTIDEG};

/// Internal length units per micrometre.
const LEN_PER_UM: i64 = LEN_PER_TENTH_MM / 100;

/// Closest two of the three points may be, and closest the via point may be to the straight
/// line from start to end, in micrometres: 0.1 mm, the wire's resolution. Nearer than that
/// the points say nothing about a circle ([`Arc::through`] gives `None`).
pub const MIN_SEPARATION_UM: i64 = 100;

/// Largest radius of an arc, in micrometres (10 m): beyond it the three points are as good as
/// collinear and the circle through them leaves any arm's reach.
pub const MAX_RADIUS_UM: i64 = 10_000_000;

/// One turn in binary-angle units.
const TURN: i64 = 1 << 32;

/// 2 pi in Q30 (round(2 pi * 2^30)).
const TAU_Q30: i128 = 6_746_518_852;

/// One part of an arc (start to via, or via to end): where it starts on the circle and how far
/// it turns there, and the orientation it starts with and turns through.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
struct Part {
    /// Circle angle at the part's start, binary units (0..2^32).
    from: i64,
    /// Circle angle the part turns through, binary units (> 0).
    sweep: i64,
    /// Orientation at the part's start.
    rotation: Rotation,
    /// Unit axis (Q30, in the part's start frame) and angle of the orientation's turn.
    axis: [i64; 3],
    angle: Angle,
    /// Length of the part, micrometres (a degree of turn counting as a millimetre).
    length_um: i64,
}

impl Part {
    fn new(
        from: i64,
        sweep: i64,
        radius_um: i64,
        rotation: Rotation,
        to: &Rotation,
    ) -> Option<Self> {
        let (axis, angle) = rotation.transpose().mul(to).to_axis_angle();
        let arc_um = i64::try_from(
            i128::from(radius_um)
                .checked_mul(i128::from(sweep))?
                .checked_mul(TAU_Q30)?
                >> 62,
        )
        .ok()?;
        let turn_um = i64::from(angle.to_centideg().abs()) * UM_PER_CENTIDEG;
        Some(Self {
            from,
            sweep,
            rotation,
            axis,
            angle,
            length_um: arc_um.max(turn_um).max(1),
        })
    }

    /// The circle angle and orientation `at_um` into this part (0..=length).
    fn at(&self, at_um: i64) -> (i64, Rotation) {
        // max/min rather than clamp, which asserts its bounds (a panic path).
        let at = at_um.max(0).min(self.length_um);
        let t = self.from + ratio(self.sweep * at, self.length_um);
        let turn = Angle(ratio(i64::from(self.angle.0) * at, self.length_um) as i32);
        (
            t,
            self.rotation.mul(&Rotation::about_axis(&self.axis, turn)),
        )
    }
}

/// A circular arc from a start pose through a via pose to an end pose. See the
/// [module doc](self).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct Arc {
    /// Centre of the circle, internal length units.
    centre: [i64; 3],
    /// Radius, internal length units.
    radius: i64,
    /// Unit vectors (Q30) in the arc's plane: towards the start, and a quarter turn on.
    e1: [i64; 3],
    e2: [i64; 3],
    /// Start to via, via to end.
    first: Part,
    second: Part,
    start: Transform,
    end: Transform,
}

impl Arc {
    /// The arc from `start` through `via` to `end`; `None` if the three positions define no
    /// circle: two of them closer than [`MIN_SEPARATION_UM`], the via point within that of the
    /// straight line from start to end (collinear), or a radius above [`MAX_RADIUS_UM`].
    pub fn through(start: Transform, via: Transform, end: Transform) -> Option<Self> {
        let p0 = start.position;
        let um = |p: &[i64; 3]| -> [i128; 3] {
            [0, 1, 2].map(|i| {
                let d = p.get(i).copied().unwrap_or(0) - p0.get(i).copied().unwrap_or(0);
                i128::from(ratio(d, LEN_PER_UM))
            })
        };
        let a = um(&via.position);
        let b = um(&end.position);
        let ab = sub(&b, &a);
        let min2 = i128::from(MIN_SEPARATION_UM * MIN_SEPARATION_UM);
        if dot(&a, &a)? < min2 || dot(&b, &b)? < min2 || dot(&ab, &ab)? < min2 {
            return None;
        }
        let w = cross(&a, &b)?;
        let w2 = dot(&w, &w)?;
        // Distance of the via point from the line start..end is |a x b| / |b|.
        if w2 < min2.checked_mul(dot(&b, &b)?)? {
            return None;
        }
        let aa = dot(&a, &a)?;
        let bb = dot(&b, &b)?;
        let num = [0, 1, 2].map(|i| {
            let (ai, bi) = (
                a.get(i).copied().unwrap_or(0),
                b.get(i).copied().unwrap_or(0),
            );
            aa.checked_mul(bi)?.checked_sub(bb.checked_mul(ai)?)
        });
        let [n0, n1, n2] = num;
        let num = [n0?, n1?, n2?];
        let offset_num = cross(&num, &w)?;
        // Centre offset from the start, internal units: offset_num / (2 |w|^2) micrometres.
        let den = w2.checked_mul(2)?;
        let mut centre = p0;
        for (c, n) in centre.iter_mut().zip(offset_num) {
            let scaled = checked_div_i128(n.checked_mul(i128::from(LEN_PER_UM))?, den)?;
            *c = c.checked_add(i64::try_from(scaled).ok()?)?;
        }
        let [s0, s1, s2] = [0, 1, 2].map(|i| {
            p0.get(i)
                .copied()
                .unwrap_or(0)
                .checked_sub(centre.get(i).copied().unwrap_or(0))
        });
        let to_start = [s0?, s1?, s2?];
        let radius = sqrt(
            to_start
                .iter()
                .try_fold(0i64, |s, v| s.checked_add(v.checked_mul(*v)?))?,
        );
        if radius == 0 || radius / LEN_PER_UM > MAX_RADIUS_UM {
            return None;
        }
        let e1 = to_start.map(|v| ratio(v * ONE, radius));
        let w_len = isqrt_i128(w2);
        let n = [0, 1, 2].map(|i| {
            let wi = w.get(i).copied().unwrap_or(0);
            i64::try_from(checked_div_i128(wi.checked_mul(i128::from(ONE))?, w_len)?).ok()
        });
        let [n0, n1, n2] = n;
        let [n0, n1, n2] = [n0?, n1?, n2?];
        let [x1, y1, z1] = e1;
        let e2 = [
            mul(n1, z1) - mul(n2, y1),
            mul(n2, x1) - mul(n0, z1),
            mul(n0, y1) - mul(n1, x1),
        ];
        let angle_of = |p: &[i64; 3]| -> i64 {
            let v = [0, 1, 2]
                .map(|i| p.get(i).copied().unwrap_or(0) - centre.get(i).copied().unwrap_or(0));
            let along = |e: &[i64; 3]| e.iter().zip(&v).map(|(e, v)| mul(*e, *v)).sum::<i64>();
            let t = i64::from(atan2(along(&e2), along(&e1)).0);
            if t <= 0 { t + TURN } else { t }
        };
        let via_t = angle_of(&via.position);
        let end_t = angle_of(&end.position);
        if via_t >= end_t {
            return None;
        }
        let radius_um = radius / LEN_PER_UM;
        let first = Part::new(0, via_t, radius_um, start.rotation, &via.rotation)?;
        let second = Part::new(via_t, end_t - via_t, radius_um, via.rotation, &end.rotation)?;
        Some(Self {
            centre,
            radius,
            e1,
            e2,
            first,
            second,
            start,
            end,
        })
    }

    /// Radius of the circle, micrometres.
    pub fn radius_um(&self) -> i64 {
        self.radius / LEN_PER_UM
    }

    /// Centre of the circle, internal length units (1/16 um).
    pub fn centre(&self) -> [i64; 3] {
        self.centre
    }

    /// How far along the arc the via point is, micrometres (the end of its first part).
    pub fn via_at_um(&self) -> i64 {
        self.first.length_um
    }

    /// The point of the circle at angle `t` (binary units from the start).
    fn point(&self, t: i64) -> [i64; 3] {
        // Binary angles wrap: the low 32 bits are the angle.
        let (s, c) = Angle(t as u32 as i32).sin_cos();
        [0, 1, 2].map(|i| {
            let e1 = self.e1.get(i).copied().unwrap_or(0);
            let e2 = self.e2.get(i).copied().unwrap_or(0);
            let unit = mul(c, e1) + mul(s, e2);
            self.centre.get(i).copied().unwrap_or(0) + mul(self.radius, unit)
        })
    }
}

impl Path for Arc {
    fn length_um(&self) -> i64 {
        self.first.length_um + self.second.length_um
    }

    fn pose_at(&self, at_um: i64) -> Transform {
        if at_um >= self.length_um() {
            return self.end;
        }
        if at_um <= 0 {
            return self.start;
        }
        let (t, rotation) = if at_um <= self.first.length_um {
            self.first.at(at_um)
        } else {
            self.second.at(at_um - self.first.length_um)
        };
        Transform {
            rotation,
            position: self.point(t),
        }
    }
}

fn sub(a: &[i128; 3], b: &[i128; 3]) -> [i128; 3] {
    [0, 1, 2].map(|i| a.get(i).copied().unwrap_or(0) - b.get(i).copied().unwrap_or(0))
}

fn dot(a: &[i128; 3], b: &[i128; 3]) -> Option<i128> {
    a.iter()
        .zip(b)
        .try_fold(0i128, |s, (x, y)| s.checked_add(x.checked_mul(*y)?))
}

fn cross(a: &[i128; 3], b: &[i128; 3]) -> Option<[i128; 3]> {
    let [a0, a1, a2] = *a;
    let [b0, b1, b2] = *b;
    Some([
        a1.checked_mul(b2)?.checked_sub(a2.checked_mul(b1)?)?,
        a2.checked_mul(b0)?.checked_sub(a0.checked_mul(b2)?)?,
        a0.checked_mul(b1)?.checked_sub(a1.checked_mul(b0)?)?,
    ])
}

/// Square root of a non-negative `i128`, rounded down; 0 for negative input.
fn isqrt_i128(v: i128) -> i128 {
    if v <= 0 {
        0
    } else {
        isqrt_u128(v.unsigned_abs()) as i128
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::{JointAngles, Kinematics, PathWalker, Pose};

    type V = [f64; 3];

    fn mm(p: &[i64; 3]) -> V {
        p.map(|v| v as f64 / (LEN_PER_TENTH_MM as f64 * 10.0))
    }

    fn vsub(a: &V, b: &V) -> V {
        [a[0] - b[0], a[1] - b[1], a[2] - b[2]]
    }

    fn vdot(a: &V, b: &V) -> f64 {
        a[0] * b[0] + a[1] * b[1] + a[2] * b[2]
    }

    fn vcross(a: &V, b: &V) -> V {
        [
            a[1] * b[2] - a[2] * b[1],
            a[2] * b[0] - a[0] * b[2],
            a[0] * b[1] - a[1] * b[0],
        ]
    }

    fn norm(a: &V) -> f64 {
        vdot(a, a).sqrt()
    }

    /// The circle through three points in f64: centre, radius and unit normal.
    fn circle(p0: &V, p1: &V, p2: &V) -> (V, f64, V) {
        let a = vsub(p1, p0);
        let b = vsub(p2, p0);
        let w = vcross(&a, &b);
        let w2 = vdot(&w, &w);
        let num: V = std::array::from_fn(|i| vdot(&a, &a) * b[i] - vdot(&b, &b) * a[i]);
        let off = vcross(&num, &w);
        let centre = std::array::from_fn(|i| p0[i] + off[i] / (2.0 * w2));
        let radius = norm(&vsub(p0, &centre));
        let n = w.map(|v| v / w2.sqrt());
        (centre, radius, n)
    }

    /// Distance of `p` from the circle (centre, radius, normal), mm.
    fn off_circle(p: &V, centre: &V, radius: f64, n: &V) -> f64 {
        let v = vsub(p, centre);
        let out_of_plane = vdot(&v, n);
        let in_plane: V = std::array::from_fn(|i| v[i] - out_of_plane * n[i]);
        (out_of_plane.powi(2) + (norm(&in_plane) - radius).powi(2)).sqrt()
    }

    fn at(x: i32, y: i32, z: i32, rx: i32, ry: i32, rz: i32) -> Transform {
        Transform::from_pose(&Pose {
            x,
            y,
            z,
            rx,
            ry,
            rz,
        })
    }

    /// Angle between two rotations, centidegrees.
    fn angle_between(a: &Rotation, b: &Rotation) -> i32 {
        a.transpose().mul(b).to_axis_angle().1.to_centideg().abs()
    }

    #[test]
    fn every_point_lies_on_the_f64_circle_through_the_three_points() {
        let cases = [
            // A quarter circle in a horizontal plane, a tilted plane, a major arc, a tiny arc,
            // and a shallow one (via 2 mm off the chord of 200 mm).
            (
                at(2000, 0, 1500, 18000, 0, 0),
                at(1414, 1414, 1500, 18000, 0, 0),
                at(0, 2000, 1500, 18000, 0, 0),
            ),
            (
                at(1500, -800, 2000, 17000, 500, 300),
                at(1800, 0, 2600, -17500, 1000, 0),
                at(1300, 900, 2300, 17900, -800, -1200),
            ),
            (
                at(2000, 0, 1000, 18000, 0, 0),
                at(-2000, 10, 1000, 18000, 0, 9000),
                at(1990, -200, 1000, 18000, 0, -9000),
            ),
            (
                at(1500, 0, 1500, 18000, 0, 0),
                at(1505, 5, 1500, 18000, 0, 0),
                at(1500, 10, 1500, 18000, 0, 0),
            ),
            (
                at(1000, -1000, 1800, 18000, 0, 0),
                at(1000, 0, 1820, 18000, 0, 0),
                at(1000, 1000, 1800, 18000, 0, 0),
            ),
        ];
        for (start, via, end) in cases {
            let arc = Arc::through(start, via, end).expect("a circle");
            let (p0, p1, p2) = (mm(&start.position), mm(&via.position), mm(&end.position));
            let (centre, radius, n) = circle(&p0, &p1, &p2);
            assert!(
                (arc.radius_um() as f64 / 1000.0 - radius).abs() < 0.002,
                "radius {} vs {radius}",
                arc.radius_um()
            );
            let length = arc.length_um();
            let mut worst: f64 = 0.0;
            let mut previous = p0;
            let mut travelled = 0.0;
            for k in 0..=2000 {
                let p = mm(&arc.pose_at(length * k / 2000).position);
                worst = worst.max(off_circle(&p, &centre, radius, &n));
                travelled += norm(&vsub(&p, &previous));
                previous = p;
            }
            assert!(worst < 0.001, "{worst} mm off the circle");
            // It passes through the via point and ends at the end.
            let at_via = arc.pose_at(arc.via_at_um());
            assert!(norm(&vsub(&mm(&at_via.position), &p1)) < 0.001);
            assert!(angle_between(&at_via.rotation, &via.rotation) <= 1);
            assert_eq!(arc.pose_at(length), end);
            assert_eq!(arc.pose_at(0), start);
            // The way along matches the f64 arc's length (where position, not turn, sets it).
            let sweep = {
                let (u, v) = (vsub(&p0, &centre), vsub(&p2, &centre));
                let t = vdot(&vcross(&u, &v), &n).atan2(vdot(&u, &v));
                if t <= 0.0 {
                    t + std::f64::consts::TAU
                } else {
                    t
                }
            };
            assert!(
                (travelled - radius * sweep).abs() < 0.01,
                "{travelled} vs {}",
                radius * sweep
            );
        }
    }

    #[test]
    fn the_orientation_turns_through_the_via_orientation() {
        let start = at(2000, 0, 1500, 18000, 0, 0);
        let via = at(1414, 1414, 1500, 18000, 1500, 0);
        let end = at(0, 2000, 1500, 18000, 1500, 3000);
        let arc = Arc::through(start, via, end).unwrap();
        let first = angle_between(&start.rotation, &via.rotation);
        let total = first + angle_between(&via.rotation, &end.rotation);
        // How far the orientation has turned, counted along start -> via -> end.
        let turned = |at_um: i64| {
            let r = arc.pose_at(at_um).rotation;
            if at_um <= arc.via_at_um() {
                angle_between(&start.rotation, &r)
            } else {
                first + angle_between(&via.rotation, &r)
            }
        };
        let mut previous = 0;
        for k in 0..=100 {
            let done = turned(arc.length_um() * k / 100);
            assert!(done + 2 >= previous, "turned back at {k}%");
            assert!(done <= total + 2, "turned too far at {k}%");
            previous = done;
        }
        assert_eq!(previous, total);
    }

    #[test]
    fn collinear_and_coincident_points_make_no_arc() {
        let a = at(2000, 0, 1500, 18000, 0, 0);
        let b = at(1500, 500, 1500, 18000, 0, 0);
        let c = at(1000, 1000, 1500, 18000, 0, 0);
        assert!(Arc::through(a, b, c).is_none(), "collinear");
        assert!(
            Arc::through(a, c, b).is_none(),
            "collinear, via beyond the end"
        );
        assert!(Arc::through(a, a, c).is_none(), "via on the start");
        assert!(Arc::through(a, b, a).is_none(), "end on the start");
        assert!(Arc::through(a, b, b).is_none(), "end on the via");
        // 0.05 mm off the line: still collinear at the wire's resolution.
        let nearly = at(1500, 500, 1500, 18000, 0, 0);
        // 566 units (35 um) along x and y: 0.05 mm from the line x + y = const.
        let nearly = Transform {
            position: [
                nearly.position[0] + 566,
                nearly.position[1] + 566,
                nearly.position[2],
            ],
            ..nearly
        };
        assert!(Arc::through(a, nearly, c).is_none());
        // Far outside any workspace: no overflow, no panic.
        let far = Transform {
            position: [i64::MAX / 4, 0, 0],
            ..a
        };
        assert!(Arc::through(a, far, c).is_none());
    }

    #[test]
    fn an_arc_is_walked_by_the_joints_on_the_circle() {
        let kin = Kinematics::new();
        let q0 = JointAngles([0, -3_000, -6_000, 0, 0, 0]);
        let start = kin.forward_transform(&q0);
        let s = start.to_pose();
        let via = Transform::from_pose(&Pose {
            x: s.x - 400,
            y: s.y + 400,
            ..s
        });
        let end = Transform::from_pose(&Pose { y: s.y + 800, ..s });
        let arc = Arc::through(start, via, end).unwrap();
        let (centre, radius, n) =
            circle(&mm(&start.position), &mm(&via.position), &mm(&end.position));
        let mut walker = PathWalker::new(arc, q0);
        let mut worst: f64 = 0.0;
        while let Some(step) = walker.advance(&kin, 2_000, 300, 500) {
            let (q, _) = step.unwrap();
            let p = mm(&kin.forward_transform(&q).position);
            worst = worst.max(off_circle(&p, &centre, radius, &n));
        }
        assert_eq!(walker.remaining_um(), 0);
        // Joint angles are whole centidegrees: 0.01 deg moves the flange up to ~0.04 mm.
        assert!(
            worst < 0.05,
            "joints put the flange {worst} mm off the circle"
        );
    }
}
