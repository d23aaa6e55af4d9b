//! Measuring the arm as it really is: the flange pose from the shafts' true angles, in floating
//! point, independent of the firmware's fixed-point kinematics (same DH table,
//! [`kinematics_core::ArmGeometry::MYCOBOT_280`]).

use kinematics_core::ArmGeometry;

/// A 3x3 rotation, row-major.
pub type Rotation = [[f64; 3]; 3];

/// The flange pose in the base frame: position in millimetres and orientation.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct FlangePose {
    /// x, y, z in millimetres.
    pub position_mm: [f64; 3],
    /// Orientation of the flange frame in the base frame.
    pub rotation: Rotation,
}

/// DH alpha of each joint, degrees (`docs/kinematics.md`).
const ALPHA_DEG: [f64; 6] = [90.0, 0.0, 0.0, 90.0, -90.0, 0.0];

/// The flange pose at joint angles `q_deg` (degrees, the protocol's joint angles).
pub fn flange(q_deg: &[f64; 6]) -> FlangePose {
    let g = ArmGeometry::MYCOBOT_280;
    let mm = |um: i32| f64::from(um) / 1000.0;
    let d = [mm(g.d1_um), 0.0, 0.0, mm(g.d4_um), mm(g.d5_um), mm(g.d6_um)];
    let a = [0.0, mm(g.a2_um), mm(g.a3_um), 0.0, 0.0, 0.0];
    let mut rotation = [[1.0, 0.0, 0.0], [0.0, 1.0, 0.0], [0.0, 0.0, 1.0]];
    let mut position = [0.0; 3];
    let links = q_deg
        .iter()
        .zip(g.theta_offset_centideg)
        .zip(ALPHA_DEG)
        .zip(d.iter().zip(a));
    for (((q, offset), alpha), (d, a)) in links {
        let theta = (q + f64::from(offset) / 100.0).to_radians();
        let alpha = alpha.to_radians();
        let (st, ct, sa, ca) = (theta.sin(), theta.cos(), alpha.sin(), alpha.cos());
        // Standard DH: Rz(theta) Tz(d) Tx(a) Rx(alpha).
        let link_r = [
            [ct, -st * ca, st * sa],
            [st, ct * ca, -ct * sa],
            [0.0, sa, ca],
        ];
        let moved = apply(&rotation, &[a * ct, a * st, *d]);
        position = add(&position, &moved);
        rotation = mul(&rotation, &link_r);
    }
    FlangePose {
        position_mm: position,
        rotation,
    }
}

/// Distance in millimetres from `p` to the segment from `a` to `b`.
pub fn distance_to_segment_mm(p: &[f64; 3], a: &[f64; 3], b: &[f64; 3]) -> f64 {
    let ab = sub(b, a);
    let ap = sub(p, a);
    let len2 = dot(&ab, &ab);
    let t = if len2 > 0.0 {
        (dot(&ap, &ab) / len2).clamp(0.0, 1.0)
    } else {
        0.0
    };
    let closest = add(a, &ab.map(|v| v * t));
    norm(&sub(p, &closest))
}

/// The circle through three points, for measuring arcs.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Circle {
    /// Centre, millimetres.
    pub centre_mm: [f64; 3],
    /// Radius, millimetres.
    pub radius_mm: f64,
    /// Unit normal of the circle's plane (turning about it takes `a` to `b` to `c`).
    pub normal: [f64; 3],
}

impl Circle {
    /// The circle through `a`, `b` and `c` (millimetres); `None` if they are collinear.
    pub fn through(a: &[f64; 3], b: &[f64; 3], c: &[f64; 3]) -> Option<Self> {
        let (u, v) = (sub(b, a), sub(c, a));
        let w = cross(&u, &v);
        let w2 = dot(&w, &w);
        if w2 < 1e-12 {
            return None;
        }
        let num = sub(&v.map(|x| x * dot(&u, &u)), &u.map(|x| x * dot(&v, &v)));
        let off = cross(&num, &w);
        let centre_mm = add(a, &off.map(|x| x / (2.0 * w2)));
        Some(Self {
            centre_mm,
            radius_mm: norm(&sub(a, &centre_mm)),
            normal: w.map(|x| x / w2.sqrt()),
        })
    }

    /// Distance in millimetres from `p` to the circle.
    pub fn distance_mm(&self, p: &[f64; 3]) -> f64 {
        let v = sub(p, &self.centre_mm);
        let out_of_plane = dot(&v, &self.normal);
        let in_plane = sub(&v, &self.normal.map(|x| x * out_of_plane));
        (out_of_plane.powi(2) + (norm(&in_plane) - self.radius_mm).powi(2)).sqrt()
    }
}

/// Distance in millimetres between two points.
pub fn distance_mm(a: &[f64; 3], b: &[f64; 3]) -> f64 {
    norm(&sub(a, b))
}

/// Angle in degrees between two orientations.
pub fn angle_between_deg(r1: &Rotation, r2: &Rotation) -> f64 {
    // trace(r1^T r2): the sum of the element-wise products.
    let trace: f64 = r1
        .iter()
        .flatten()
        .zip(r2.iter().flatten())
        .map(|(a, b)| a * b)
        .sum();
    ((trace - 1.0) / 2.0).clamp(-1.0, 1.0).acos().to_degrees()
}

fn column(m: &Rotation, c: usize) -> [f64; 3] {
    m.map(|row| row.get(c).copied().unwrap_or(0.0))
}

fn mul(x: &Rotation, y: &Rotation) -> Rotation {
    x.map(|row| std::array::from_fn(|c| dot(&row, &column(y, c))))
}

fn apply(r: &Rotation, v: &[f64; 3]) -> [f64; 3] {
    r.map(|row| dot(&row, v))
}

fn add(a: &[f64; 3], b: &[f64; 3]) -> [f64; 3] {
    let mut sum = *a;
    for (s, v) in sum.iter_mut().zip(b) {
        *s += v;
    }
    sum
}

fn sub(a: &[f64; 3], b: &[f64; 3]) -> [f64; 3] {
    add(a, &b.map(|v| -v))
}

fn cross(a: &[f64; 3], b: &[f64; 3]) -> [f64; 3] {
    [
        a[1] * b[2] - a[2] * b[1],
        a[2] * b[0] - a[0] * b[2],
        a[0] * b[1] - a[1] * b[0],
    ]
}

fn dot(a: &[f64; 3], b: &[f64; 3]) -> f64 {
    a.iter().zip(b).map(|(x, y)| x * y).sum()
}

fn norm(a: &[f64; 3]) -> f64 {
    dot(a, a).sqrt()
}

#[cfg(test)]
mod tests {
    use super::*;
    use kinematics_core::{JointAngles, Kinematics};

    #[test]
    fn agrees_with_the_firmware_kinematics() {
        let kin = Kinematics::new();
        for q in [
            [0, 0, 0, 0, 0, 0],
            [3_000, -4_500, 6_000, 1_000, -2_000, 9_000],
        ] {
            let fixed = kin.forward(&JointAngles(q));
            let ours = flange(&q.map(|c| f64::from(c) / 100.0));
            for (mm, tenths) in ours.position_mm.iter().zip([fixed.x, fixed.y, fixed.z]) {
                assert!(
                    (mm * 10.0 - f64::from(tenths)).abs() <= 0.6,
                    "{ours:?} {fixed:?}"
                );
            }
        }
    }

    #[test]
    fn a_circle_through_three_points() {
        let c = Circle::through(&[10.0, 0.0, 5.0], &[0.0, 10.0, 5.0], &[-10.0, 0.0, 5.0])
            .expect("a circle");
        assert!(distance_mm(&c.centre_mm, &[0.0, 0.0, 5.0]) < 1e-9);
        assert!((c.radius_mm - 10.0).abs() < 1e-9);
        assert!((c.distance_mm(&[0.0, -13.0, 9.0]) - 5.0).abs() < 1e-9);
        assert!(Circle::through(&[0.0; 3], &[1.0, 1.0, 1.0], &[2.0, 2.0, 2.0]).is_none());
    }

    #[test]
    fn distance_to_a_segment() {
        let (a, b) = ([0.0, 0.0, 0.0], [10.0, 0.0, 0.0]);
        assert_eq!(distance_to_segment_mm(&[5.0, 3.0, 4.0], &a, &b), 5.0);
        assert_eq!(distance_to_segment_mm(&[13.0, 4.0, 0.0], &a, &b), 5.0);
    }
}
