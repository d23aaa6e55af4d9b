//! [`Kinematics`]: the robot model (link geometry, joint limits, tool and world frames) and its
//! forward and inverse kinematics.

use crate::fixed::Angle;
use crate::geometry::{ArmGeometry, Links};
use crate::ik::{self, IkError};
use crate::limits::JointLimits;
use crate::pose::{JointAngles, Pose};
use crate::transform::{self, Transform};

/// An ill-conditioned solution (next to a singularity) farther than this (0.5 deg) from the
/// seed in some joint makes [`Kinematics::inverse`] check whether the seed already is at the
/// target.
const SEED_CHECK_CENTIDEG: i32 = 50;

/// Position distance (0.09 mm) within which a pose counts as the target: the wire's 0.1 mm
/// rounding of three coordinates moves a pose by up to 0.087 mm.
const ROUNDING_POSITION: transform::Len = 9 * transform::LEN_PER_TENTH_MM / 10;

/// Largest rotation-matrix entry difference (Q30, 1.75e-4 = 0.01 deg) within which an
/// orientation counts as the target's: the wire's 0.01 deg rounding of three angles turns it by
/// up to 0.0087 deg.
const ROUNDING_ROTATION_Q30: i64 = 187_904;

/// The robot model: link geometry, joint limits, and the tool and world frames.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct Kinematics {
    links: Links,
    limits: JointLimits,
    /// Tool pose in the flange frame, and its inverse.
    tool: Option<(Transform, Transform)>,
    /// Base pose in the world frame, and its inverse.
    world: Option<(Transform, Transform)>,
}

impl Default for Kinematics {
    fn default() -> Self {
        Self::new()
    }
}

impl Kinematics {
    /// Vendor DH table, default limits, identity frames.
    pub fn new() -> Self {
        Self::with_geometry(&ArmGeometry::MYCOBOT_280)
    }

    /// A model with a calibrated geometry, default limits, identity frames.
    pub fn with_geometry(geometry: &ArmGeometry) -> Self {
        Self {
            links: Links::new(geometry),
            limits: JointLimits::default(),
            tool: None,
            world: None,
        }
    }

    /// The joint limits every solution respects.
    pub fn limits(&self) -> &JointLimits {
        &self.limits
    }

    /// Replaces the joint limits (protocol 0x4C / 0x4D).
    pub fn set_limits(&mut self, limits: JointLimits) {
        self.limits = limits;
    }

    /// Sets the tool pose in the flange frame (end type TOOL), or `None` for the flange itself.
    pub fn set_tool(&mut self, tool: Option<Pose>) {
        self.tool = tool.map(|p| with_inverse(Transform::from_pose(&p)));
    }

    /// Sets the base pose in the world frame (reference frame WORLD), or `None` for the base.
    pub fn set_world(&mut self, world: Option<Pose>) {
        self.world = world.map(|p| with_inverse(Transform::from_pose(&p)));
    }

    /// The end pose (tool in world, per the selected frames) at joint angles `q`.
    pub fn forward(&self, q: &JointAngles) -> Pose {
        self.forward_transform(q).to_pose()
    }

    /// The end pose as a full-precision transform (1/16 um, Q30 rotation).
    pub fn forward_transform(&self, q: &JointAngles) -> Transform {
        let mut t = self.links.flange(q);
        if let Some((world, _)) = &self.world {
            t = world.then(&t);
        }
        if let Some((tool, _)) = &self.tool {
            t = t.then(tool);
        }
        t
    }

    /// The joint angles that put the end (per the selected frames) at `target`: of all branches
    /// within the limits (each joint wrapped by +-360 deg), the best fit (exact, then clamped to
    /// reach by up to 0.2 mm, then traded at the wrist singularity), and of those the one nearest
    /// `seed` (squared distance in joint space). If that answer is far from the seed (or there is
    /// none) but the seed itself is within the wire's rounding of the target (0.09 mm, 0.01 deg),
    /// the seed is the answer: resending the coordinates just read never moves the arm.
    pub fn inverse(&self, target: &Pose, seed: &JointAngles) -> Result<JointAngles, IkError> {
        self.inverse_transform(&Transform::from_pose(target), seed)
    }

    /// [`Kinematics::inverse`] for a full-precision target transform (a rotation and a position
    /// within the range [`Transform::from_pose`] produces).
    pub fn inverse_transform(
        &self,
        target: &Transform,
        seed: &JointAngles,
    ) -> Result<JointAngles, IkError> {
        let branches = ik::solve(&self.links, &self.flange_of(target), &self.seed_theta(seed));
        let best = branches.and_then(|branches| {
            self.best_branch(&branches, seed)
                .ok_or(IkError::OutsideLimits)
        });
        // Next to a singularity the wire's rounding can move the solution far from the seed, or
        // out of reach, although the seed itself is at the target to within that rounding (a
        // user resending the coordinates just read): then the arm stays where it is.
        let check_seed = best.map_or(true, |(q, ill_conditioned)| {
            ill_conditioned
                && q.0
                    .iter()
                    .zip(seed.0.iter())
                    .any(|(a, b)| (a - b).abs() > SEED_CHECK_CENTIDEG)
        });
        if check_seed && self.limits.contains(seed) && self.reaches(seed, target) {
            return Ok(*seed);
        }
        best.map(|(q, _)| q)
    }

    /// Whether the end at `q` is within the wire's rounding of `target`.
    fn reaches(&self, q: &JointAngles, target: &Transform) -> bool {
        let at = self.forward_transform(q);
        let [dx, dy, dz] = core::array::from_fn(|i| {
            at.position.get(i).copied().unwrap_or(0) - target.position.get(i).copied().unwrap_or(0)
        });
        let turned = (0..3)
            .flat_map(|r| (0..3).map(move |c| (r, c)))
            .map(|(r, c)| (at.rotation.at(r, c) - target.rotation.at(r, c)).abs())
            .max()
            .unwrap_or(0);
        [dx, dy, dz].iter().all(|d| d.abs() <= ROUNDING_POSITION)
            && dx * dx + dy * dy + dz * dz <= ROUNDING_POSITION * ROUNDING_POSITION
            && turned <= ROUNDING_ROTATION_Q30
    }

    /// Every branch for `target` as joint angles wrapped into the limits near `seed` (`None` for
    /// a branch that does not exist or does not fit the limits), indexed
    /// shoulder * 4 + wrist * 2 + elbow. Only the branches of the best fit are listed: those that
    /// reach the target exactly, else those that clamp it (up to 0.2 mm beyond reach), else
    /// those next to the wrist singularity that trade a little orientation for reach.
    pub fn inverse_all(
        &self,
        target: &Pose,
        seed: &JointAngles,
    ) -> Result<[Option<JointAngles>; 8], IkError> {
        self.inverse_all_transform(&Transform::from_pose(target), seed)
    }

    /// [`Kinematics::inverse_all`] for a full-precision target transform.
    pub fn inverse_all_transform(
        &self,
        target: &Transform,
        seed: &JointAngles,
    ) -> Result<[Option<JointAngles>; 8], IkError> {
        let branches = ik::solve(&self.links, &self.flange_of(target), &self.seed_theta(seed))?;
        let best = branches.iter().flatten().map(|b| b.fit).min();
        Ok(branches.map(|b| {
            b.filter(|b| Some(b.fit) == best)
                .and_then(|b| self.in_limits_near(&b.theta, seed))
                .map(|(q, _)| q)
        }))
    }

    /// The DH angles of the seed.
    fn seed_theta(&self, seed: &JointAngles) -> [Angle; 6] {
        core::array::from_fn(|i| self.links.theta(i, seed.0.get(i).copied().unwrap_or(0)))
    }

    /// The flange pose (base frame) that puts the end at `target` (selected frames).
    fn flange_of(&self, target: &Transform) -> Transform {
        let mut flange = *target;
        if let Some((_, world_inv)) = &self.world {
            flange = world_inv.then(&flange);
        }
        if let Some((_, tool_inv)) = &self.tool {
            flange = flange.then(tool_inv);
        }
        flange
    }

    /// Of the branches whose joints all fit the limits, the best fit (exact, clamped,
    /// near-singular), then the nearest `seed` (squared distance in joint space), the first of
    /// equals: its protocol angles and whether it is ill-conditioned.
    fn best_branch(
        &self,
        branches: &ik::Branches,
        seed: &JointAngles,
    ) -> Option<(JointAngles, bool)> {
        let placements = self.placements(seed);
        let mut best: Option<(ik::Fit, i64, JointAngles, bool)> = None;
        for branch in branches.iter().flatten() {
            if best.as_ref().is_some_and(|(fit, ..)| branch.fit > *fit) {
                continue;
            }
            let Some((q, distance)) = self.place_all(&placements, &branch.theta) else {
                continue;
            };
            if best
                .as_ref()
                .is_none_or(|(fit, least, ..)| (branch.fit, distance) < (*fit, *least))
            {
                best = Some((branch.fit, distance, q, branch.ill_conditioned));
            }
        }
        best.map(|(_, _, q, ill_conditioned)| (q, ill_conditioned))
    }

    /// DH angles `theta` as protocol angles wrapped into the limits nearest `seed`, with the
    /// squared distance to the seed; `None` if some joint cannot fit.
    fn in_limits_near(&self, theta: &[Angle; 6], seed: &JointAngles) -> Option<(JointAngles, i64)> {
        self.place_all(&self.placements(seed), theta)
    }

    /// Each joint's [`Placement`] for the seed `seed`.
    fn placements(&self, seed: &JointAngles) -> [Placement; 6] {
        core::array::from_fn(|joint| {
            let (min, max) = (
                self.limits.min.get(joint).copied().unwrap_or(0),
                self.limits.max.get(joint).copied().unwrap_or(0),
            );
            let seed = seed.0.get(joint).copied().unwrap_or(0);
            // wrap_into moves q by the turns that bring it nearest the seed clamped into the
            // limits; none when that seed - q is in [-180, 180) deg.
            let seed_in_limits = seed.clamp(min, max.max(min));
            Placement {
                offset: self.links.offset.get(joint).copied().unwrap_or(Angle::ZERO),
                seed,
                kept_from: min.max(seed_in_limits.saturating_sub(HALF_TURN_CENTIDEG - 1)),
                kept_to: max.min(seed_in_limits.saturating_add(HALF_TURN_CENTIDEG)),
            }
        })
    }

    /// [`Kinematics::place`] for every joint, with the sum of the squared distances; `None` if
    /// some joint cannot fit.
    fn place_all(
        &self,
        placements: &[Placement; 6],
        theta: &[Angle; 6],
    ) -> Option<(JointAngles, i64)> {
        let mut q = [0i32; 6];
        let mut distance = 0i64;
        for (joint, ((slot, placement), &t)) in q
            .iter_mut()
            .zip(placements.iter())
            .zip(theta.iter())
            .enumerate()
        {
            let (angle, squared) = self.place(joint, placement, t)?;
            *slot = angle;
            distance = distance.saturating_add(squared);
        }
        Some((JointAngles(q), distance))
    }

    /// Joint `joint`'s DH angle `theta` as the protocol angle wrapped by +-360 deg into the
    /// limits nearest the seed ([`JointLimits::wrap_into`]), with its squared distance from the
    /// seed; `None` if no turn of it fits.
    fn place(&self, joint: usize, placement: &Placement, theta: Angle) -> Option<(i32, i64)> {
        let q = theta.sub(placement.offset).to_centideg();
        // What wrap_into gives when q itself is the turn nearest the seed and fits, without its
        // division; any other case goes to wrap_into.
        let angle = if (placement.kept_from..=placement.kept_to).contains(&q) {
            q
        } else {
            self.limits.wrap_into(joint, q, placement.seed)?
        };
        let d = i64::from(angle) - i64::from(placement.seed);
        Some((angle, d.saturating_mul(d)))
    }
}

/// Half a turn in centidegrees.
const HALF_TURN_CENTIDEG: i32 = 18_000;

/// What choosing a joint's angle needs, computed once per solve: its DH offset, the seed's
/// angle, and the protocol angles that [`JointLimits::wrap_into`] keeps as they are (within the
/// limits and less than half a turn from the seed clamped into them).
#[derive(Clone, Copy, Debug)]
struct Placement {
    /// DH angle at protocol angle 0.
    offset: Angle,
    /// The seed's angle, centidegrees.
    seed: i32,
    /// Lowest angle kept as it is, centidegrees.
    kept_from: i32,
    /// Highest angle kept as it is, centidegrees.
    kept_to: i32,
}

/// A transform paired with its inverse.
fn with_inverse(t: Transform) -> (Transform, Transform) {
    (t, t.inverse())
}
