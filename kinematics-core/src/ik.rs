//! Closed-form inverse kinematics of the flange, derived from the geometry.
//!
//! The arm is of the Universal-Robots type: joints 2, 3 and 4 are parallel, so
//! * the wrist point w = flange - d6 * z (z = flange z axis) must lie d4 off the plane through
//!   the J1 axis: w . (sin t1, -cos t1, 0) = d4 gives t1 = atan2(wy, wx) + 90 deg +- acos(d4 / |w_xy|)
//!   (shoulder left/right);
//! * the flange z axis seen from frame 1 is (-s5 c234, -s5 s234, c5), so c5 = z . (s1, -c1, 0)
//!   and |s5| = the length of the other two components (wrist up/down); computing |s5| from
//!   those components, not from sqrt(1 - c5^2), keeps t5 accurate next to the wrist singularity;
//! * the last row of R16 is (s5 c6, -s5 s6, c5), which gives t6 unless s5 = 0 (J4 and J6
//!   parallel: t6 is free and keeps its seed value);
//! * removing A1, A5 and A6 leaves a planar two-link chain a2, a3 in frame 1 whose end is the
//!   origin of frame 4: the law of cosines gives t3 (elbow up/down), then t2, and t4 is what
//!   remains of t2 + t3 + t4, read from the rotation.
//!
//! Every acos is computed as atan2(sqrt(max(0, ...)), ...) with a small reach tolerance, so the
//! stretched elbow (q3 = 0) and the shoulder singularity (both present at the zero pose) solve.

use crate::IkError;
use crate::fixed::{Angle, atan2, mul, sqrt};
use crate::geometry::Links;
use crate::transform::{LEN_PER_TENTH_MM, Len, Transform};

/// How far (0.2 mm) a target may lie beyond the arm's reach, or inside the shoulder's dead
/// cylinder, and still be solved as the nearest reachable pose: the wire's 0.1 mm rounding puts
/// poses read at the stretched or shoulder-singular configurations (the zero pose) just outside.
const REACH_TOLERANCE: Len = 2 * LEN_PER_TENTH_MM;

/// How far (2 um) beyond reach a branch may be and still count as exact: the fixed-point
/// error of a consistent target. Branches clamped by more are approximate and chosen only when
/// no exact branch fits the limits.
const EXACT_SLACK: Len = 2 * LEN_PER_TENTH_MM / 100;

/// |sin t5| (Q30, 2.4e-4, i.e. q5 within 0.014 deg of +-90) below which the wrist is singular
/// and t6 keeps its seed value. The orientation error this causes is at most |sin t5| times the
/// change of t6 (0.044 deg if the seed is opposite, far less when it is the current angle), and
/// it is what lets a pose read at the singularity and rounded to the wire's 0.01 deg (an
/// orientation noise of 1e-4 rad, which would swing an exact t6 arbitrarily and move the frame-4
/// origin on a d5-radius circle) be solved back to where it was read.
const WRIST_SINGULAR_SIN: i64 = 1 << 18;

/// Wrist points farther than this (2 m) from the base axes are unreachable without further
/// arithmetic (and keep every square inside `i64`).
const MAX_WRIST_COORD: Len = 20_000 * LEN_PER_TENTH_MM;

/// The most branches: shoulder x wrist x elbow.
pub(crate) const MAX_BRANCHES: usize = 8;

/// One IK solution in DH angles.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub(crate) struct Branch {
    /// DH angles theta 1..6.
    pub theta: [Angle; 6],
    /// False if the target was beyond reach by more than [`EXACT_SLACK`] and was clamped.
    pub exact: bool,
}

/// Each branch that exists, indexed shoulder * 4 + wrist * 2 + elbow.
pub(crate) type Branches = [Option<Branch>; MAX_BRANCHES];

/// Whether `low <= sqrt(v) <= high` (lengths), with `low` clamped at zero.
fn within(v: i64, low: Len, high: Len) -> bool {
    let low = low.max(0);
    v >= low * low && v <= high * high
}

/// All IK branches for the flange pose `target` (base frame). `seed_theta6` is used for t6 at
/// the wrist singularity.
pub(crate) fn solve(
    links: &Links,
    target: &Transform,
    seed_theta6: Angle,
) -> Result<Branches, IkError> {
    let [_, _, _, d4, _, d6] = links.d;
    let [_, a2, a3, _, _, _] = links.a;
    let r = &target.rotation;
    let z = r.column(2);
    let [px, py, pz] = target.position;
    let w = [px - mul(d6, z[0]), py - mul(d6, z[1]), pz - mul(d6, z[2])];
    if w.iter().any(|c| c.abs() > MAX_WRIST_COORD) {
        return Err(IkError::Unreachable);
    }
    let [wx, wy, _] = w;
    let r2 = wx * wx + wy * wy;
    if !within(r2, d4 - REACH_TOLERANCE, 2 * MAX_WRIST_COORD) {
        return Err(IkError::Unreachable);
    }
    let shoulder_exact = within(r2, d4 - EXACT_SLACK, 2 * MAX_WRIST_COORD);
    let psi = atan2(wy, wx);
    let phi = atan2(sqrt(r2 - d4 * d4), d4);

    let (s_len, d_len) = (a2.abs() + a3.abs(), (a2.abs() - a3.abs()).abs());
    let cos_sign = if (a2 < 0) == (a3 < 0) { 1 } else { -1 };
    let mut out: Branches = [None; MAX_BRANCHES];
    let mut degenerate = false;
    for (shoulder, t1) in [psi.add(phi), psi.sub(phi)].into_iter().enumerate() {
        let t1 = t1.add(Angle::QUARTER);
        let (s1, c1) = t1.sin_cos();
        let c5 = mul(z[0], s1) - mul(z[1], c1);
        let (x1, y1) = (mul(z[0], c1) + mul(z[1], s1), z[2]);
        let s5 = sqrt(x1 * x1 + y1 * y1);
        // The flange in frame 1: M = A1^-1 * T06.
        let m = links.link(0, t1).inverse().then(target);
        for (wrist, sign5) in [1i64, -1].into_iter().enumerate() {
            let t5 = atan2(sign5 * s5, c5);
            let t6 = if s5 < WRIST_SINGULAR_SIN {
                seed_theta6
            } else {
                let sin6 = mul(c1, r.at(1, 1)) - mul(s1, r.at(0, 1));
                let cos6 = mul(s1, r.at(0, 0)) - mul(c1, r.at(1, 0));
                atan2(sign5 * sin6, sign5 * cos6)
            };
            // T14 = M * A56^-1; only its rotation's first column and position are needed:
            // R14 e_x = M.R * (row 0 of R56), p14 = M.p - M.R * R56^T * p56.
            let a56 = links.link(4, t5).then(&links.link(5, t6));
            let r56 = &a56.rotation;
            let [x14_x, x14_y, _] = m
                .rotation
                .apply(&[r56.at(0, 0), r56.at(0, 1), r56.at(0, 2)]);
            let [bx, by, _] = m.rotation.apply(&r56.transpose().apply(&a56.position));
            let t234 = atan2(x14_y, x14_x);
            let (ex, ey) = (m.position[0] - bx, m.position[1] - by);
            let l2 = ex * ex + ey * ey;
            if !within(l2, d_len - REACH_TOLERANCE, s_len + REACH_TOLERANCE) {
                continue;
            }
            let exact = shoulder_exact && within(l2, d_len - EXACT_SLACK, s_len + EXACT_SLACK);
            if l2 == 0 {
                degenerate = true;
                continue;
            }
            // cos t3 = (l2 - a2^2 - a3^2) / (2 a2 a3); sin t3 = sqrt((S^2 - l2)(l2 - D^2)) / (2 |a2 a3|).
            let sin3 = sqrt(s_len * s_len - l2) * sqrt(l2 - d_len * d_len);
            let cos3 = cos_sign * (l2 - a2 * a2 - a3 * a3);
            for (elbow, sign3) in [1i64, -1].into_iter().enumerate() {
                let t3 = atan2(sign3 * sin3, cos3);
                let (s3, c3) = t3.sin_cos();
                let t2 = atan2(ey, ex).sub(atan2(mul(a3, s3), a2 + mul(a3, c3)));
                let t4 = t234.sub(t2).sub(t3);
                if let Some(slot) = out.get_mut(shoulder * 4 + wrist * 2 + elbow) {
                    *slot = Some(Branch {
                        theta: [t1, t2, t3, t4, t5, t6],
                        exact,
                    });
                }
            }
        }
    }
    if out.iter().any(Option::is_some) {
        Ok(out)
    } else if degenerate {
        Err(IkError::Singular)
    } else {
        Err(IkError::Unreachable)
    }
}
