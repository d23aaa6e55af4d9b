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
//!   parallel: t6 is free and keeps its seed value, unless that value moves the frame-4 origin,
//!   which circles the wrist at radius d5 as t6 turns, out of the elbow's reach; then it turns
//!   to the nearest value that reaches, see [`reachable_turn`]);
//! * removing A1, A5 and A6 leaves a planar two-link chain a2, a3 in frame 1 whose end is the
//!   origin of frame 4: the law of cosines gives t3 (elbow up/down), then t2, and t4 is what
//!   remains of t2 + t3 + t4, read from the rotation.
//!
//! Every acos is computed as atan2(sqrt(max(0, ...)), ...) with a small reach tolerance, so the
//! stretched elbow (q3 = 0) and the shoulder singularity (both present at the zero pose) solve.

use crate::fixed::{Angle, atan2, mul, sqrt};
use crate::geometry::Links;
use crate::transform::{LEN_PER_TENTH_MM, Len, Transform};

/// Why a pose has no joint solution (protocol error 32, see [`IkError::PROTOCOL_CODE`]).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum IkError {
    /// The pose is out of the arm's reach (too far, or too close to the J1 axis).
    Unreachable,
    /// The pose is reachable, but every branch puts some joint outside its limits.
    OutsideLimits,
    /// The geometry degenerates (the two-link chain folds onto the J2 axis) so the joints are
    /// not determined; impossible with the vendor link lengths, kept for calibrated ones.
    Singular,
}

impl IkError {
    /// The 0x07 error code for "IK has no solution".
    pub const PROTOCOL_CODE: u8 = 32;
}

/// How far (0.2 mm) a target may lie beyond the arm's reach, or inside the shoulder's dead
/// cylinder, and still be solved as the nearest reachable pose: the wire's 0.1 mm rounding puts
/// poses read at the stretched or shoulder-singular configurations (the zero pose) just outside.
const REACH_TOLERANCE: Len = 2 * LEN_PER_TENTH_MM;

/// How far (2 um) beyond reach a branch may be and still count as exact: the fixed-point
/// error of a consistent target. Branches clamped by more are [`Fit::Clamped`].
const EXACT_SLACK: Len = 2 * LEN_PER_TENTH_MM / 100;

/// |sin t5| (Q30, 2.4e-4, i.e. q5 within 0.014 deg of +-90) below which the wrist is singular
/// and t6 is free (the seed's value). The orientation error this causes is at most |sin t5|
/// times the change of t6 (0.044 deg if the seed is opposite, far less when it is the current
/// angle). Above it, t6 follows from the orientation, which the wire's 0.01 deg rounding (up to
/// 3e-4 rad) makes arbitrary near the singularity: see [`NEAR_SINGULAR_SIN`].
const WRIST_SINGULAR_SIN: i64 = 1 << 18;

/// |sin t5| (Q30, 2e-3, q5 within 0.11 deg of +-90) below which a t6 that leaves the target out
/// of the elbow's reach is replaced by the seed's (then turned into reach), at an orientation
/// error of at most |sin t5| times the change of t6. Wire rounding alone reaches 3e-4 here.
const NEAR_SINGULAR_SIN: i64 = 1 << 21;

/// Distance (0.05 mm) kept from the elbow's reach limits when t6 is chosen at the wrist
/// singularity (covers the d6 * sin t5 the singular model neglects).
const SINGULAR_REACH_MARGIN: Len = LEN_PER_TENTH_MM / 2;

/// Right shift that brings the squared lengths of [`reachable_turn`] (up to 2^52) to a range
/// whose squares fit `i64`.
const TURN_SCALE_SHIFT: u32 = 24;

/// How far (0.1 mm, the wire's rounding) a free t6 may leave the frame-4 origin beyond the
/// elbow's reach and keep its value (the reach clamp absorbs that); farther, t6 is turned.
const FREE_T6_SLACK: Len = LEN_PER_TENTH_MM;

/// How far (0.05 mm) the reached point may move to let an ill-conditioned joint keep the seed's
/// angle: t1 next to the shoulder singularity, where the wire's rounding would otherwise swing
/// t1 (and t5) by a degree or more for the same pose, and t3 next to the stretched elbow.
const SEED_SLACK: Len = LEN_PER_TENTH_MM / 2;

/// Largest distance of a seed angle from the nominal one that [`SEED_SLACK`] can absorb (it
/// allows under 2 deg).
const SEED_WINDOW: Angle = Angle::from_centideg(300);

/// Wrist points farther than this (2 m) from the base axes are unreachable without further
/// arithmetic (and keep every square inside `i64`).
const MAX_WRIST_COORD: Len = 20_000 * LEN_PER_TENTH_MM;

/// The most branches: shoulder x wrist x elbow.
pub(crate) const MAX_BRANCHES: usize = 8;

/// How well a branch reaches the target, best first.
#[derive(Clone, Copy, Debug, PartialEq, Eq, PartialOrd, Ord)]
pub(crate) enum Fit {
    /// Reaches it (within the fixed-point error).
    Exact,
    /// The target was up to [`REACH_TOLERANCE`] beyond reach and was clamped.
    Clamped,
    /// Next to the wrist singularity, the seed's t6 replaced an unreachable exact one: the
    /// orientation is off by up to |sin t5| times the change of t6 (below 0.4 deg).
    NearSingular,
}

/// One IK solution in DH angles.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub(crate) struct Branch {
    /// DH angles theta 1..6.
    pub theta: [Angle; 6],
    /// How well it reaches the target.
    pub fit: Fit,
    /// Within [`ILL_CONDITIONED`] of a singularity, where the wire's rounding of the target can
    /// move joints by more than a few hundredths of a degree.
    pub ill_conditioned: bool,
}

/// Distance from a singularity (20 deg: of the shoulder angle phi, the elbow angle t3, or t5
/// from +-90 deg) within which a branch counts as ill-conditioned.
const ILL_CONDITIONED: Angle = Angle::from_centideg(2_000);

/// Each branch that exists, indexed shoulder * 4 + wrist * 2 + elbow.
pub(crate) type Branches = [Option<Branch>; MAX_BRANCHES];

/// The flange seen from frame 1, M = A1^-1 * T06, as far as the solver needs it.
///
/// With A1 = Rz(t1) * Tz(d1) * Rx(90 deg), A1^-1 = Rx(-90 deg) * Tz(-d1) * Rz(-t1), so M's
/// rotation rows are (c1 r0 + s1 r1, r2, s1 r0 - c1 r1) (r_i the target rotation's rows) and its
/// origin is (c1 px + s1 py, pz - d1, s1 px - c1 py), of which the third is never used.
struct FlangeInFrame1 {
    /// M's rotation, Q30.
    rotation: [[i64; 3]; 3],
    /// x and y of M's origin.
    origin: [Len; 2],
}

impl FlangeInFrame1 {
    /// M for the target `target` and t1 = atan2(`s1`, `c1`), shoulder height `d1`.
    fn new(target: &Transform, s1: i64, c1: i64, d1: Len) -> Self {
        let [[r00, r01, r02], [r10, r11, r12], row2] = target.rotation.0;
        let [px, py, pz] = target.position;
        // (c1, s1) . (a, b) and (s1, -c1) . (a, b).
        let along = |a: i64, b: i64| (a * c1 + b * s1) >> 30;
        let across = |a: i64, b: i64| (a * s1 - b * c1) >> 30;
        Self {
            rotation: [
                [along(r00, r10), along(r01, r11), along(r02, r12)],
                row2,
                [across(r00, r10), across(r01, r11), across(r02, r12)],
            ],
            origin: [along(px, py), pz - d1],
        }
    }

    /// The rotation of frame 4 seen from frame 1, t2 + t3 + t4, at the wrist angles
    /// (sin t5, cos t5) and (sin t6, cos t6) (Q30).
    ///
    /// T14 = M * A56^-1, with A5 = Rz(t5) * Tz(d5) * Rx(-90 deg) and A6 = Rz(t6) * Tz(d6). Its
    /// x axis is M.R times row 0 of R56, (c5 c6, -c5 s6, -s5).
    fn frame4_angle(&self, (s5, c5): (i64, i64), (s6, c6): (i64, i64)) -> Angle {
        let [row0, row1, _] = &self.rotation;
        let x_axis = [mul(c5, c6), -mul(c5, s6), -s5];
        atan2(dot(row1, &x_axis), dot(row0, &x_axis))
    }

    /// The origin of frame 4 seen from frame 1 (x, y) at the wrist angle (sin t6, cos t6) (Q30),
    /// for the wrist offsets `d5` and `d6`; it does not depend on t5.
    ///
    /// p14 = M.p - M.R * R56^T * p56, and R56^T * p56 = (-d5 s6, -d5 c6, d6) (see
    /// [`FlangeInFrame1::frame4_angle`] for A5 and A6).
    fn frame4_origin(&self, (s6, c6): (i64, i64), d5: Len, d6: Len) -> [Len; 2] {
        let [row0, row1, _] = &self.rotation;
        let wrist = [-mul(d5, s6), -mul(d5, c6), d6];
        let [ox, oy] = self.origin;
        [ox - dot(row0, &wrist), oy - dot(row1, &wrist)]
    }
}

/// The dot product of a Q30 row and a vector, in the vector's unit.
#[inline]
fn dot(row: &[i64; 3], v: &[i64; 3]) -> i64 {
    let ([a, b, c], [x, y, z]) = (*row, *v);
    (a * x + b * y + c * z) >> 30
}

/// At the wrist singularity the frame-4 origin e = c + d5 (-sin t234, cos t234) moves on a
/// circle about c as t6 (and with it t234) turns. The smallest change of t234 that brings |e|
/// into [lo, hi], or `None` if no point of the circle is.
fn reachable_turn(ex: Len, ey: Len, t234: Angle, d5: Len, lo: Len, hi: Len) -> Option<Angle> {
    let (s, c) = t234.sin_cos();
    let (cx, cy) = (ex + mul(d5, s), ey - mul(d5, c));
    let c_len = sqrt(cx * cx + cy * cy);
    if c_len == 0 {
        return None;
    }
    // |e|^2 = |c|^2 + d5^2 + 2 d5 |c| cos(u), u = t234 + 90 deg - angle of c.
    let u = t234.add(Angle::QUARTER).sub(atan2(cy, cx));
    let base = c_len * c_len + d5 * d5;
    let den = (2 * d5 * c_len) >> TURN_SCALE_SHIFT;
    // The |u| (binary angle) where |e| = `len`: acos((len^2 - base) / den), clamped.
    let bound = |len: Len| -> i64 {
        let num = (len * len - base) >> TURN_SCALE_SHIFT;
        if num >= den {
            0
        } else if num <= -den {
            1 << 31
        } else {
            i64::from(atan2(sqrt(den * den - num * num), num).0).abs()
        }
    };
    let (u_min, u_max) = (bound(hi), bound(lo.max(0)));
    if u_min > u_max {
        return None;
    }
    let now = i64::from(u.0).abs();
    let wanted = now.clamp(u_min, u_max);
    let turn = if u.0 < 0 { now - wanted } else { wanted - now };
    Some(Angle(turn as i32))
}

/// Whether `low <= sqrt(v) <= high` (lengths), with `low` clamped at zero.
fn within(v: i64, low: Len, high: Len) -> bool {
    let low = low.max(0);
    v >= low * low && v <= high * high
}

/// All IK branches for the flange pose `target` (base frame). The seed's DH angles `seed_theta`
/// settle what the pose leaves open or ill-conditioned: t1 next to the shoulder singularity, t3
/// next to the stretched elbow and t6 at the wrist singularity.
pub(crate) fn solve(
    links: &Links,
    target: &Transform,
    seed_theta: &[Angle; 6],
) -> Result<Branches, IkError> {
    let [seed_theta1, _, seed_theta3, _, _, seed_theta6] = *seed_theta;
    let near = |a: Angle, b: Angle| a.sub(b).0.unsigned_abs() < SEED_WINDOW.0.unsigned_abs();
    let [d1, _, _, d4, d5, d6] = links.d;
    let [_, a2, a3, _, _, _] = links.a;
    let z = target.rotation.column(2);
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
    // t1 = psi + 90 deg +- phi with tan(phi) = h / d4, h^2 = r^2 - d4^2. Next to the shoulder
    // singularity (h -> 0) a wrist-point error e changes h^2 by 2 r e, which swings phi widely
    // while the pose hardly changes: keep the seed's phi if a wrist point within SEED_SLACK
    // of the target's allows it.
    let h2 = r2 - d4 * d4;
    let phi = atan2(sqrt(h2), d4);
    let seed_phi = seed_theta1.sub(psi).sub(Angle::QUARTER);
    let keep_seed = |seed_side: Angle| {
        // The slack allows a few degrees at most: skip the bounds for seeds farther off.
        near(seed_side, phi) && {
            let h2_slack = 2 * sqrt(r2) * SEED_SLACK;
            (atan2(sqrt(h2 - h2_slack), d4).0..=atan2(sqrt(h2 + h2_slack), d4).0)
                .contains(&seed_side.0)
        }
    };

    let (s_len, d_len) = (a2.abs() + a3.abs(), (a2.abs() - a3.abs()).abs());
    // |e|^2 the seed's elbow angle reaches.
    let seed_sin_cos3 = seed_theta3.sin_cos();
    let seed_l2 = a2 * a2 + a3 * a3 + 2 * a2 * mul(a3, seed_sin_cos3.1);
    let cos_sign = if (a2 < 0) == (a3 < 0) { 1 } else { -1 };
    let mut out: Branches = [None; MAX_BRANCHES];
    let mut degenerate = false;
    for (shoulder, seed_side) in [seed_phi, seed_phi.neg()].into_iter().enumerate() {
        let phi = if keep_seed(seed_side) { seed_side } else { phi };
        let t1 = if shoulder == 0 {
            psi.add(phi)
        } else {
            psi.sub(phi)
        };
        let t1 = t1.add(Angle::QUARTER);
        let (s1, c1) = t1.sin_cos();
        // The flange in frame 1: its z axis is (-s5 c234, -s5 s234, c5) and the last row of its
        // rotation (s5 c6, -s5 s6, c5).
        let m = FlangeInFrame1::new(target, s1, c1, d1);
        let [[_, _, x1], [_, _, y1], [s5_cos6, minus_s5_sin6, c5]] = m.rotation;
        let s5 = sqrt(x1 * x1 + y1 * y1);
        let free_t6 = s5 < WRIST_SINGULAR_SIN;
        // Wrist 0 has sin t5 >= 0. Wrist 1 negates t5, which turns t6 by half a turn (unless t6
        // is free), and with it t234 (so the x axis of frame 4 is the same).
        let t5_up = atan2(s5, c5);
        let t6_up = if free_t6 {
            seed_theta6
        } else {
            atan2(-minus_s5_sin6, s5_cos6)
        };
        let (sin6, cos6) = t6_up.sin_cos();
        let t234_up = m.frame4_angle((s5, c5), (sin6, cos6));
        let origin_up = m.frame4_origin((sin6, cos6), d5, d6);
        for (wrist, sign5) in [1i64, -1].into_iter().enumerate() {
            // (sin t5, cos t5) up to the length of z (1 within the rotation's rounding).
            let sin_cos5 = (sign5 * s5, c5);
            let (t5, mut t6, mut t234, [mut ex, mut ey]) = if wrist == 0 {
                (t5_up, t6_up, t234_up, origin_up)
            } else if free_t6 {
                let t234 = m.frame4_angle(sin_cos5, (sin6, cos6));
                (t5_up.neg(), t6_up, t234, origin_up)
            } else {
                let origin = m.frame4_origin((-sin6, -cos6), d5, d6);
                (
                    t5_up.neg(),
                    t6_up.add(Angle::HALF),
                    t234_up.add(Angle::HALF),
                    origin,
                )
            };
            let frame4 = |t6: Angle| {
                let sin_cos6 = t6.sin_cos();
                let [ex, ey] = m.frame4_origin(sin_cos6, d5, d6);
                (m.frame4_angle(sin_cos5, sin_cos6), ex, ey)
            };
            // Near the wrist singularity t6 moves the frame-4 origin on a d5 circle. If this t6
            // puts it out of the elbow's reach by more than the wire's rounding, treat t6 as
            // free: start from the seed's and turn to the nearest t6 that reaches. Inside the
            // singular band that is exact; in the near band it is the fallback for poses whose
            // rounding made them unreachable.
            let reachable = |ex: Len, ey: Len| {
                within(
                    ex * ex + ey * ey,
                    d_len - FREE_T6_SLACK,
                    s_len + FREE_T6_SLACK,
                )
            };
            let mut approximate_wrist = false;
            if s5 < NEAR_SINGULAR_SIN && !reachable(ex, ey) {
                if !free_t6 {
                    t6 = seed_theta6;
                    approximate_wrist = true;
                    (t234, ex, ey) = frame4(t6);
                }
                let (lo, hi) = (d_len + SINGULAR_REACH_MARGIN, s_len - SINGULAR_REACH_MARGIN);
                if !reachable(ex, ey)
                    && let Some(turn) = reachable_turn(ex, ey, t234, d5, lo, hi)
                {
                    // At t5 = 0, t234 + t6 is fixed; at t5 = 180 deg, t234 - t6 is.
                    t6 = if c5 >= 0 { t6.sub(turn) } else { t6.add(turn) };
                    (t234, ex, ey) = frame4(t6);
                }
            }
            let l2 = ex * ex + ey * ey;
            if !within(l2, d_len - REACH_TOLERANCE, s_len + REACH_TOLERANCE) {
                continue;
            }
            if l2 == 0 {
                degenerate = true;
                continue;
            }
            let fit = if approximate_wrist {
                Fit::NearSingular
            } else if shoulder_exact && within(l2, d_len - EXACT_SLACK, s_len + EXACT_SLACK) {
                Fit::Exact
            } else {
                Fit::Clamped
            };
            // cos t3 = (l2 - a2^2 - a3^2) / (2 a2 a3); sin t3 = sqrt((S^2 - l2)(l2 - D^2)) / (2 |a2 a3|).
            let sin3 = sqrt(s_len * s_len - l2) * sqrt(l2 - d_len * d_len);
            let cos3 = cos_sign * (l2 - a2 * a2 - a3 * a3);
            let toward_e = atan2(ey, ex);
            // Elbow 0 has sin t3 >= 0; elbow 1 mirrors it, negating t3 and the angle of e seen
            // from frame 2, (a2 + a3 c3, a3 s3): times 2 |a2 a3| / |a3| that is
            // (2 |a2| a2 + sgn(a3) cos3, sgn(a3) sin3), so it needs no sine and cosine of t3.
            let t3_up = atan2(sin3, cos3);
            let e_in_frame2_up = atan2(a3.signum() * sin3, 2 * a2.abs() * a2 + a3.signum() * cos3);
            for (elbow, nominal_t3, nominal_e_in_frame2) in [
                (0, t3_up, e_in_frame2_up),
                (1, t3_up.neg(), e_in_frame2_up.neg()),
            ] {
                // Next to the stretched elbow t3 is ill-conditioned too: keep the seed's t3 if
                // it reaches within SEED_SLACK of |e| and lies on this branch's side.
                let (t3, e_in_frame2) = if near(seed_theta3, nominal_t3)
                    && (seed_theta3.0 >= 0) == (nominal_t3.0 >= 0)
                    && (seed_l2 - l2).abs() <= 2 * sqrt(l2) * SEED_SLACK
                {
                    let (s3, c3) = seed_sin_cos3;
                    (seed_theta3, atan2(mul(a3, s3), a2 + mul(a3, c3)))
                } else {
                    (nominal_t3, nominal_e_in_frame2)
                };
                let t2 = toward_e.sub(e_in_frame2);
                let t4 = t234.sub(t2).sub(t3);
                let ill_conditioned = [phi, t3, t5, t5.sub(Angle::HALF)]
                    .iter()
                    .any(|a| a.0.unsigned_abs() < ILL_CONDITIONED.0.unsigned_abs());
                if let Some(slot) = out.get_mut(shoulder * 4 + wrist * 2 + elbow) {
                    *slot = Some(Branch {
                        theta: [t1, t2, t3, t4, t5, t6],
                        fit,
                        ill_conditioned,
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
