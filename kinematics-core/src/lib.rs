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
//!   0.050 mm, 0.020 deg), singular configurations included.
//! * IK of the FK rounded to the wire (what `get_coords` then `send_coords` does), seeded with
//!   the configuration read: 100 % within 0.1 mm / 0.05 deg (worst 0.086 mm, the rounding
//!   itself). Next to singularities the rounded pose can be unreachable or far in joint space;
//!   a seed that is already at the target to within the wire's rounding is returned as is.
//!
//! Host cost (x86-64, release): FK about 0.3 us and 2 150 instructions, IK (all branches and the
//! selection) about 0.7 us and 4 700 (seeded far from the answer) to 5 100 (seeded next to it)
//! instructions per call:
//! * `cargo bench -p kinematics-core` (criterion: FK, IK, a 27-step linear path; the times above
//!   are the fastest of repeated runs, what an idle core gives; a busy machine reads up to three
//!   times more);
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
mod model;
pub mod path;
mod pose;
pub mod transform;

pub use geometry::ArmGeometry;
pub use ik::IkError;
pub use limits::JointLimits;
pub use model::Kinematics;
pub use path::arc::Arc;
pub use path::{Line, LinearPath, Path, PathError, PathWalker, Ray, Turn, check_path};
pub use pose::{JointAngles, Pose};
pub use transform::{Rotation, Transform};
