//! Fixed-point kinematics of the myCobot 280 M5 (`docs/kinematics.md`): forward and closed-form
//! inverse kinematics of the flange for the vendor DH table, tool and world frames, joint
//! limits as data, and Cartesian paths: straight lines, rays (jogs), turns and circular arcs.
//!
//! Everything is integer arithmetic (no floating point, no allocation, no panics), so it runs
//! the same on the host and on a core without an FPU. Inputs and outputs use the protocol's
//! units: joint angles and orientations in centidegrees, positions in tenths of a millimetre.
//! Internally lengths are 1/16 um and ratios Q30 (see [`fixed`] and [`transform`]).
//!
//! ```
//! use kinematics_core::{JointAngles, Kinematics};
//! let kin = Kinematics::new();
//! let pose = kin.forward(&JointAngles([0; 6]));
//! assert_eq!((pose.x, pose.y, pose.z), (456, -634, 4127)); // 45.6, -63.4, 412.7 mm
//! let q = kin.inverse(&pose, &JointAngles([0; 6])).unwrap();
//! assert!(q.0.iter().all(|a| a.abs() <= 2));
//! ```
//!
//! # What callers get
//!
//! * [`Kinematics::forward`]: the end pose (tool in world, per [`Kinematics::set_tool`] and
//!   [`Kinematics::set_world`]) of joint angles, RPY as in `docs/kinematics.md` (at ry = +-90 deg,
//!   rz = 0).
//! * [`Kinematics::inverse`]: all up to 8 closed-form branches, each joint wrapped by +-360 deg
//!   into the [`JointLimits`], the best fit (exact, then up to 0.2 mm clamped, then traded at the
//!   wrist singularity) nearest the seed; or an [`IkError`] (protocol error 32). The zero pose,
//!   the stretched elbow and the wrist singularity (J6 keeps the seed's angle) all solve.
//! * [`Path`]s ([`Line`], [`Ray`], [`Turn`], [`Arc`]) walked by [`PathWalker`] (and checked
//!   whole by [`check_path`]), and [`LinearPath`] (a line in equal steps): straight-line and
//!   circular moves and Cartesian jogs, stopping with [`PathError`] (33 / 34) instead of a joint
//!   jump or an unreachable step.
//! * [`Transform`]-level variants (`forward_transform`, `inverse_transform`) for callers that
//!   chain small Cartesian steps and should not round to the wire's units in between.
//!
//! # Accuracy and cost (measured)
//!
//! Against an f64 model of the DH table, 100 000 random in-limit joint vectors
//! (`cargo test --release -p kinematics-core --test accuracy -- --nocapture`):
//! * FK: worst 0.0005 mm and 0.000001 deg before rounding to the wire (0.085 mm / 0.011 deg
//!   after, which is the wire's own rounding).
//! * IK of the exact FK, answers rounded to 0.01 deg: 100 % within 0.1 mm / 0.05 deg (worst
//!   0.050 mm, 0.022 deg), singular configurations included.
//! * IK of the FK rounded to the wire (what `get_coords` then `send_coords` does), seeded with
//!   the configuration read: 100 % within 0.1 mm / 0.05 deg (worst 0.086 mm, the rounding
//!   itself). Next to singularities the rounded pose can be unreachable or far in joint space;
//!   a seed that is already at the target to within the wire's rounding is returned as is.
//!
//! Host cost (x86-64, release): FK about 0.5 us and 2 300 instructions, IK (all branches and the
//! selection) about 2 us and 8 900 to 9 500 instructions per call:
//! * `cargo bench -p kinematics-core` (criterion: FK, IK, a 27-step linear path);
//! * `kinematics-core/benches/callgrind.sh` (instructions per call, via valgrind's callgrind:
//!   the difference between runs of `examples/ik_count.rs` with N and with 0 calls);
//! * `kinematics-core/benches/riscv_check.sh` builds for `riscv32imc-unknown-none-elf` (no FPU)
//!   and checks the library references no floating-point routine and no panic.
#![cfg_attr(not(test), no_std)]
#![forbid(unsafe_code)]

pub mod fixed;
pub mod geometry;
mod ik;
pub mod limits;
pub mod path;
pub mod transform;

pub use geometry::ArmGeometry;
pub use limits::JointLimits;
pub use path::{Arc, Line, LinearPath, Path, PathError, PathWalker, Ray, Turn, check_path};
pub use transform::{Rotation, Transform};

use fixed::Angle;
use geometry::Links;

/// Joint angles q (protocol angles, not DH theta), centidegrees, joints 1..6.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Default)]
pub struct JointAngles(pub [i32; 6]);

/// A pose: x, y, z in tenths of a millimetre; rx, ry, rz in centidegrees,
/// R = Rz(rz) * Ry(ry) * Rx(rx).
#[derive(Clone, Copy, Debug, PartialEq, Eq, Default)]
pub struct Pose {
    /// x, 0.1 mm.
    pub x: i32,
    /// y, 0.1 mm.
    pub y: i32,
    /// z, 0.1 mm.
    pub z: i32,
    /// Roll about the fixed x axis, 0.01 deg.
    pub rx: i32,
    /// Pitch about the fixed y axis, 0.01 deg.
    pub ry: i32,
    /// Yaw about the fixed z axis, 0.01 deg.
    pub rz: i32,
}

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
        // The best fit first (exact, clamped, near-singular), then the nearest to the seed.
        let best = branches.and_then(|branches| {
            branches
                .iter()
                .flatten()
                .filter_map(|b| Some((self.in_limits_near(&b.theta, seed)?, b)))
                .min_by_key(|((_, distance), b)| (b.fit, *distance))
                .map(|((q, _), b)| (q, b.ill_conditioned))
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

    /// DH angles `theta` as protocol angles wrapped into the limits nearest `seed`, with the
    /// squared distance to the seed; `None` if some joint cannot fit.
    fn in_limits_near(&self, theta: &[Angle; 6], seed: &JointAngles) -> Option<(JointAngles, i64)> {
        let mut q = [0i32; 6];
        let mut distance = 0i64;
        for (i, ((slot, &t), &s)) in q
            .iter_mut()
            .zip(theta.iter())
            .zip(seed.0.iter())
            .enumerate()
        {
            let offset = self.links.offset.get(i).copied().unwrap_or(Angle::ZERO);
            *slot = self.limits.wrap_into(i, t.sub(offset).to_centideg(), s)?;
            let d = i64::from(*slot) - i64::from(s);
            distance = distance.saturating_add(d.saturating_mul(d));
        }
        Some((JointAngles(q), distance))
    }
}

/// A transform paired with its inverse.
fn with_inverse(t: Transform) -> (Transform, Transform) {
    (t, t.inverse())
}
