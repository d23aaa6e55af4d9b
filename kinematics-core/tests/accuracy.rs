//! Accuracy of the fixed-point kinematics against an independent f64 model of the DH table,
//! over random joint vectors spread across the whole limit box.
//!
//! The sample count is 100 000 in release builds (CI) and smaller in debug builds. Run with
//! `--nocapture` to see the measured worst errors and success rates.

// Test code on fixed-size f64 matrices, read clearest with indices.
#![allow(
    clippy::indexing_slicing,
    clippy::unwrap_used,
    clippy::needless_range_loop
)]

use kinematics_core::{ArmGeometry, IkError, JointAngles, JointLimits, Kinematics, Pose};

#[cfg(debug_assertions)]
const SAMPLES: usize = 10_000;
#[cfg(not(debug_assertions))]
const SAMPLES: usize = 100_000;

/// Units of the fixed-point transform per millimetre.
const LEN_PER_MM: f64 = 16_000.0;

type Mat = [[f64; 4]; 4];

/// The vendor DH table (d mm, a mm, alpha deg, theta offset deg), as in docs/kinematics.md.
const DH: [(f64, f64, f64, f64); 6] = [
    (131.22, 0.0, 90.0, 0.0),
    (0.0, -110.4, 0.0, -90.0),
    (0.0, -96.0, 0.0, 0.0),
    (63.4, 0.0, 90.0, -90.0),
    (75.05, 0.0, -90.0, 90.0),
    (45.6, 0.0, 0.0, 0.0),
];

fn matmul(a: &Mat, b: &Mat) -> Mat {
    let mut m = [[0.0; 4]; 4];
    for r in 0..4 {
        for c in 0..4 {
            m[r][c] = (0..4).map(|k| a[r][k] * b[k][c]).sum();
        }
    }
    m
}

fn identity() -> Mat {
    let mut m = [[0.0; 4]; 4];
    for (i, row) in m.iter_mut().enumerate() {
        row[i] = 1.0;
    }
    m
}

/// Flange in base, f64, q in degrees.
fn fk_f64(q_deg: &[f64; 6]) -> Mat {
    let mut t = identity();
    for (i, &(d, a, alpha, offset)) in DH.iter().enumerate() {
        let th = (q_deg[i] + offset).to_radians();
        let al = alpha.to_radians();
        let (s, c, sa, ca) = (th.sin(), th.cos(), al.sin(), al.cos());
        let link = [
            [c, -s * ca, s * sa, a * c],
            [s, c * ca, -c * sa, a * s],
            [0.0, sa, ca, d],
            [0.0, 0.0, 0.0, 1.0],
        ];
        t = matmul(&t, &link);
    }
    t
}

/// The f64 transform of a wire pose (mm, deg, R = Rz Ry Rx).
fn pose_f64(p: &Pose) -> Mat {
    let (a, b, c) = (
        (p.rx as f64 / 100.0).to_radians(),
        (p.ry as f64 / 100.0).to_radians(),
        (p.rz as f64 / 100.0).to_radians(),
    );
    let (sa, ca, sb, cb, sc, cc) = (a.sin(), a.cos(), b.sin(), b.cos(), c.sin(), c.cos());
    [
        [
            cc * cb,
            cc * sb * sa - sc * ca,
            cc * sb * ca + sc * sa,
            p.x as f64 / 10.0,
        ],
        [
            sc * cb,
            sc * sb * sa + cc * ca,
            sc * sb * ca - cc * sa,
            p.y as f64 / 10.0,
        ],
        [-sb, cb * sa, cb * ca, p.z as f64 / 10.0],
        [0.0, 0.0, 0.0, 1.0],
    ]
}

/// (position error mm, orientation error deg) between two transforms.
fn distance(a: &Mat, b: &Mat) -> (f64, f64) {
    let dp = (0..3)
        .map(|i| (a[i][3] - b[i][3]).powi(2))
        .sum::<f64>()
        .sqrt();
    // For rotations |Ra - Rb| (Frobenius) = 2 sqrt(2) sin(angle / 2); unlike acos of the trace
    // this stays linear in small errors.
    let frobenius = (0..3)
        .flat_map(|r| (0..3).map(move |c| (r, c)))
        .map(|(r, c)| (a[r][c] - b[r][c]).powi(2))
        .sum::<f64>()
        .sqrt();
    let angle = (2.0 * (frobenius / (2.0 * 2f64.sqrt())).min(1.0).asin()).to_degrees();
    (dp, angle)
}

fn to_deg(q: &JointAngles) -> [f64; 6] {
    q.0.map(|v| v as f64 / 100.0)
}

/// Deterministic xorshift generator.
struct Rng(u64);

impl Rng {
    fn next(&mut self) -> u64 {
        self.0 ^= self.0 << 13;
        self.0 ^= self.0 >> 7;
        self.0 ^= self.0 << 17;
        self.0
    }

    fn in_range(&mut self, lo: i32, hi: i32) -> i32 {
        lo + (self.next() % (hi - lo + 1) as u64) as i32
    }

    fn joints(&mut self, limits: &JointLimits) -> JointAngles {
        JointAngles(std::array::from_fn(|i| {
            self.in_range(limits.min[i], limits.max[i])
        }))
    }
}

/// Degrees by which `q` is away from the nearest singularity: wrist (q5 = +-90), elbow (q3 = 0)
/// and shoulder (wrist point at d4 from the J1 axis, as the angle acos(d4 / r)).
fn singularity_margin_deg(q: &JointAngles) -> f64 {
    let deg = to_deg(q);
    let t = fk_f64(&deg);
    let wrist = [t[0][3] - 45.6 * t[0][2], t[1][3] - 45.6 * t[1][2]];
    let r = (wrist[0] * wrist[0] + wrist[1] * wrist[1]).sqrt();
    let shoulder = (63.4 / r).clamp(-1.0, 1.0).acos().to_degrees();
    let wrist_margin = (deg[4].abs() - 90.0).abs();
    shoulder.min(wrist_margin).min(deg[2].abs())
}

#[test]
fn forward_matches_f64_reference_over_the_workspace() {
    let kin = Kinematics::new();
    let mut rng = Rng(0x9E37_79B9_7F4A_7C15);
    let (mut worst_mm, mut worst_deg, mut worst_rounded_mm, mut worst_rounded_deg) =
        (0.0f64, 0.0f64, 0.0f64, 0.0f64);
    for _ in 0..SAMPLES {
        let q = rng.joints(kin.limits());
        let want = fk_f64(&to_deg(&q));
        let (mm, deg) = distance(&transform_f64(&kin.forward_transform(&q)), &want);
        worst_mm = worst_mm.max(mm);
        worst_deg = worst_deg.max(deg);
        // The wire pose adds only its own rounding (0.05 mm per axis, 0.005 deg per angle).
        let (mm, deg) = distance(&pose_f64(&kin.forward(&q)), &want);
        worst_rounded_mm = worst_rounded_mm.max(mm);
        worst_rounded_deg = worst_rounded_deg.max(deg);
    }
    println!(
        "FK over {SAMPLES} samples: worst {worst_mm:.6} mm, {worst_deg:.6} deg; \
         as a wire pose {worst_rounded_mm:.4} mm, {worst_rounded_deg:.4} deg"
    );
    assert!(worst_mm <= 0.05 && worst_deg <= 0.01);
    assert!(worst_rounded_mm <= 0.05 * 3f64.sqrt() + 0.001 && worst_rounded_deg <= 0.02);
}

#[test]
fn zero_pose_is_the_documented_pose() {
    let kin = Kinematics::new();
    let p = kin.forward(&JointAngles::default());
    assert_eq!(
        p,
        Pose {
            x: 456,
            y: -634,
            z: 4127,
            rx: -9000,
            ry: 0,
            rz: -9000
        }
    );
}

/// The full-precision transform as an f64 matrix in mm.
fn transform_f64(t: &kinematics_core::Transform) -> Mat {
    let mut m = identity();
    for r in 0..3 {
        for c in 0..3 {
            m[r][c] = t.rotation.0[r][c] as f64 / (1u64 << 30) as f64;
        }
        m[r][3] = t.position[r] as f64 / LEN_PER_MM;
    }
    m
}

/// Whether every joint of `q` is at least `margin` centidegrees inside its limits.
fn inside_limits_by(q: &JointAngles, limits: &JointLimits, margin: i32) -> bool {
    (0..6).all(|i| q.0[i] - margin >= limits.min[i] && q.0[i] + margin <= limits.max[i])
}

#[test]
fn inverse_of_exact_forward_reaches_the_target() {
    let kin = Kinematics::new();
    let mut rng = Rng(0x1234_5678_9ABC_DEF1);
    let (mut failures, mut far_failures) = (Vec::new(), 0usize);
    let (mut worst_mm, mut worst_deg) = (0.0f64, 0.0f64);
    for i in 0..SAMPLES {
        let q = rng.joints(kin.limits());
        let target = kin.forward_transform(&q);
        // Half the time seed with the answer itself, half with the zero pose.
        let seed = if i % 2 == 0 {
            q
        } else {
            JointAngles::default()
        };
        let reached = kin.inverse_transform(&target, &seed).map(|sol| {
            assert!(kin.limits().contains(&sol), "{sol:?} outside limits");
            distance(&fk_f64(&to_deg(&sol)), &transform_f64(&target))
        });
        if let Ok((mm, deg)) = reached {
            worst_mm = worst_mm.max(mm);
            worst_deg = worst_deg.max(deg);
        }
        if !matches!(reached, Ok((mm, deg)) if mm <= 0.1 && deg <= 0.05) {
            let margin = singularity_margin_deg(&q);
            if margin > 1.0 {
                far_failures += 1;
            }
            failures.push((q, reached, margin));
        }
    }
    let rate = 1.0 - failures.len() as f64 / SAMPLES as f64;
    println!(
        "IK of exact FK over {SAMPLES} samples: success {:.4} %, worst {worst_mm:.4} mm, {worst_deg:.4} deg",
        rate * 100.0
    );
    for (q, reached, margin) in &failures {
        println!("  failed: q {q:?} -> {reached:?}, singularity margin {margin:.3} deg");
    }
    assert_eq!(far_failures, 0);
    // At most 0.01 % fail; a small debug run is allowed the one known double-singular case.
    assert!(
        failures.len() * 10_000 <= SAMPLES.max(10_000),
        "success rate {rate}"
    );
}

/// What a user does: read the coordinates (rounded to 0.1 mm / 0.01 deg) and send them back.
/// Near a singularity the rounding itself can make the pose unreachable or move the solution
/// past a limit; the seed (the configuration read) must still be found.
#[test]
fn inverse_of_wire_pose_round_trips() {
    let kin = Kinematics::new();
    let mut rng = Rng(0x5555_0123_4567_89AB);
    let (mut failed, mut clear_failures) = (0usize, Vec::new());
    let (mut worst_mm, mut worst_deg) = (0.0f64, 0.0f64);
    for _ in 0..SAMPLES {
        let q = rng.joints(kin.limits());
        let target = kin.forward(&q);
        let reached = kin
            .inverse(&target, &q)
            .map(|sol| distance(&fk_f64(&to_deg(&sol)), &pose_f64(&target)));
        if let Ok((mm, deg)) = reached {
            worst_mm = worst_mm.max(mm);
            worst_deg = worst_deg.max(deg);
        }
        if !matches!(reached, Ok((mm, deg)) if mm <= 0.1 && deg <= 0.05) {
            failed += 1;
            println!(
                "  failed: q {q:?} target {target:?} -> {reached:?}, singularity margin {:.2} deg",
                singularity_margin_deg(&q)
            );
            if singularity_margin_deg(&q) > 5.0 && inside_limits_by(&q, kin.limits(), 100) {
                clear_failures.push((q, target, reached));
            }
        }
    }
    println!(
        "IK of wire-rounded FK over {SAMPLES} samples: success {:.4} %, worst {worst_mm:.4} mm, {worst_deg:.4} deg",
        100.0 - failed as f64 * 100.0 / SAMPLES as f64
    );
    assert!(clear_failures.is_empty(), "{clear_failures:?}");
    assert!(failed * 10_000 <= SAMPLES, "{failed} failures");
}

#[test]
fn every_branch_reaches_the_target() {
    let mut free = Kinematics::new();
    free.set_limits(JointLimits {
        min: [-36_000; 6],
        max: [36_000; 6],
    });
    let mut rng = Rng(0xDEAD_BEEF_CAFE_F00D);
    let mut counts = [0usize; 9];
    for _ in 0..SAMPLES / 10 {
        let q = rng.joints(&JointLimits::default());
        let target = free.forward_transform(&q);
        let branches = free.inverse_all_transform(&target, &q).unwrap();
        counts[branches.iter().flatten().count()] += 1;
        for sol in branches.iter().flatten() {
            let (mm, deg) = distance(&fk_f64(&to_deg(sol)), &transform_f64(&target));
            assert!(
                mm <= 0.1 && deg <= 0.05,
                "branch {sol:?} of {q:?}: {mm} mm {deg} deg"
            );
        }
        // With no limits the original configuration is one of the branches (away from the
        // singularities, where the joints are ill-conditioned and neighbouring branches merge).
        if singularity_margin_deg(&q) > 5.0 {
            assert!(
                branches.iter().flatten().any(|s| s
                    .0
                    .iter()
                    .zip(q.0.iter())
                    .all(|(a, b)| (a - b).abs() <= 3)),
                "{q:?} not among {branches:?}"
            );
        }
    }
    println!("branches found (0..=8): {counts:?}");
}

#[test]
fn singular_poses_solve() {
    let kin = Kinematics::new();
    for q in [
        [0, 0, 0, 0, 0, 0],                      // zero pose: elbow and shoulder singular
        [3000, 0, 0, 0, 9000, 4500],             // stretched and wrist singular
        [0, 4000, 0, -2000, -9000, 0],           // stretched, wrist singular
        [1000, 2000, 3000, 0, 9000, 0],          // wrist singular only
        [7545, 2264, 4119, -3988, 9000, -13001], // wrist singular, J6 far from zero
        [-6000, -3000, 1500, 7000, -9000, 17000],
    ] {
        let q = JointAngles(q);
        let target = kin.forward(&q);
        // Seeded with the configuration itself, with zero, and with J6 half a turn away: at the
        // wrist singularity J6 is free, and a seed whose J6 puts the elbow out of reach must
        // still find a solution.
        let mut flipped = q;
        flipped.0[5] = if q.0[5] > 0 {
            q.0[5] - 18_000
        } else {
            q.0[5] + 18_000
        };
        for seed in [q, JointAngles::default(), flipped] {
            let sol = kin
                .inverse(&target, &seed)
                .unwrap_or_else(|e| panic!("{q:?} seed {seed:?}: {e:?}"));
            let (mm, deg) = distance(&fk_f64(&to_deg(&sol)), &pose_f64(&target));
            assert!(
                mm <= 0.1 && deg <= 0.05,
                "{q:?} seed {seed:?} -> {sol:?}: {mm} mm {deg} deg"
            );
            // At the wrist singularity J6 keeps the seed's value when it can.
            if seed == q && q.0[4].abs() == 9000 {
                assert!((sol.0[5] - q.0[5]).abs() <= 2, "{sol:?}");
            }
        }
    }
}

#[test]
fn nearest_branch_to_the_seed_wins() {
    let kin = Kinematics::new();
    let q = JointAngles([2000, -3000, 6000, 2000, 4000, -1000]);
    let target = kin.forward(&q);
    let sol = kin.inverse(&target, &q).unwrap();
    assert!(
        sol.0
            .iter()
            .zip(q.0.iter())
            .all(|(a, b)| (a - b).abs() <= 10),
        "{sol:?}"
    );
    // Seeded from the elbow-flipped configuration, the flipped branch is chosen.
    let all = kin.inverse_all(&target, &q).unwrap();
    let other = all
        .iter()
        .flatten()
        .find(|s| (s.0[2] - q.0[2]).abs() > 1000)
        .copied()
        .unwrap();
    let sol = kin.inverse(&target, &other).unwrap();
    assert!(
        sol.0
            .iter()
            .zip(other.0.iter())
            .all(|(a, b)| (a - b).abs() <= 3),
        "{sol:?} vs {other:?}"
    );
}

#[test]
fn unreachable_and_limit_violations_are_reported() {
    let mut kin = Kinematics::new();
    let far = Pose {
        x: 3000,
        y: 0,
        z: 1000,
        rx: 0,
        ry: 0,
        rz: 0,
    };
    assert_eq!(
        kin.inverse(&far, &JointAngles::default()),
        Err(IkError::Unreachable)
    );
    let huge = Pose {
        x: i32::MAX,
        y: i32::MIN,
        z: i32::MAX,
        rx: i32::MAX,
        ry: i32::MIN,
        rz: 7,
    };
    assert_eq!(
        kin.inverse(&huge, &JointAngles::default()),
        Err(IkError::Unreachable)
    );
    // Reachable only with J1 at 100 deg; limit J1 to +-90 deg.
    let q = JointAngles([10_000, -2000, 3000, 1000, 2000, 0]);
    let target = kin.forward(&q);
    let mut limits = JointLimits::default();
    limits.min[0] = -9000;
    limits.max[0] = 9000;
    kin.set_limits(limits);
    let result = kin.inverse(&target, &q);
    // Another branch may still reach it within the limits; if so it must respect them.
    match result {
        Ok(sol) => assert!(kin.limits().contains(&sol)),
        Err(e) => assert_eq!(e, IkError::OutsideLimits),
    }
}

#[test]
fn tool_and_world_frames_apply_both_ways() {
    let mut kin = Kinematics::new();
    let tool = Pose {
        x: 120,
        y: -35,
        z: 880,
        rx: 1500,
        ry: -2000,
        rz: 9000,
    };
    let world = Pose {
        x: 2500,
        y: -1000,
        z: 300,
        rx: 0,
        ry: 0,
        rz: 4500,
    };
    kin.set_tool(Some(tool));
    kin.set_world(Some(world));
    let mut rng = Rng(0x0F0F_1234_5555_AAAA);
    for _ in 0..SAMPLES / 20 {
        let q = rng.joints(kin.limits());
        let want = matmul(
            &matmul(&pose_f64(&world), &fk_f64(&to_deg(&q))),
            &pose_f64(&tool),
        );
        let got = kin.forward(&q);
        let (mm, deg) = distance(&pose_f64(&got), &want);
        assert!(mm <= 0.1 && deg <= 0.02, "{q:?}: {mm} mm {deg} deg");
        let exact = kin.forward_transform(&q);
        let sol = kin.inverse_transform(&exact, &q).unwrap();
        let reached = matmul(
            &matmul(&pose_f64(&world), &fk_f64(&to_deg(&sol))),
            &pose_f64(&tool),
        );
        let (mm, deg) = distance(&reached, &transform_f64(&exact));
        assert!(
            mm <= 0.1 && deg <= 0.05,
            "{q:?} -> {sol:?}: {mm} mm {deg} deg"
        );
    }
    // Back to identity frames.
    kin.set_tool(None);
    kin.set_world(None);
    assert_eq!(kin.forward(&JointAngles::default()).z, 4127);
}

/// A user reads the coordinates and sends them back: the arm must not move, also at the
/// singular configurations users start from (the arm upright, any base angle).
#[test]
fn resending_the_read_coordinates_keeps_the_joints() {
    let kin = Kinematics::new();
    for q in [
        [0, 0, 0, 0, 0, 0],
        [1234, 0, 0, 0, 0, 0],
        [-4500, 0, 0, 0, 0, 0],
        [3000, 0, 0, 0, 0, 3000],
        [0, 0, 0, 0, 9000, 0],
        [2000, 0, 0, 0, -9000, 4500],
        [0, -3000, -3000, 0, 0, 0],
        [9000, -4500, -9000, 4500, 0, 0],
        [-2500, 3000, -6000, 3000, 0, 0],
        [0, 1000, -2000, 1000, 0, 0],
        [1234, 1000, -500, 1000, 3000, -2000],
        // Next to the wrist singularity and the stretched elbow: the rounded pose itself is
        // out of reach.
        [5434, 7768, 330, 7340, 9111, -15960],
        [12208, 8320, 1122, -8970, -9014, 3089],
    ] {
        let q = JointAngles(q);
        let sol = kin.inverse(&kin.forward(&q), &q).unwrap();
        assert!(
            sol.0
                .iter()
                .zip(q.0.iter())
                .all(|(a, b)| (a - b).abs() <= 5),
            "{q:?} -> {sol:?}"
        );
    }
}

/// A calibrated geometry (here the URDF's link lengths) replaces the vendor table everywhere.
#[test]
fn a_calibrated_geometry_solves_too() {
    let urdf = ArmGeometry {
        d1_um: 131_560,
        d4_um: 64_620,
        d5_um: 73_180,
        ..ArmGeometry::MYCOBOT_280
    };
    let kin = Kinematics::with_geometry(&urdf);
    assert_ne!(
        kin.forward(&JointAngles::default()),
        Kinematics::new().forward(&JointAngles::default())
    );
    let mut rng = Rng(0xC0FF_EE00_1234_5678);
    for _ in 0..SAMPLES / 20 {
        let q = rng.joints(kin.limits());
        let target = kin.forward_transform(&q);
        let sol = kin.inverse_transform(&target, &q).unwrap();
        let (mm, deg) = distance(
            &transform_f64(&kin.forward_transform(&sol)),
            &transform_f64(&target),
        );
        assert!(
            mm <= 0.1 && deg <= 0.05,
            "{q:?} -> {sol:?}: {mm} mm {deg} deg"
        );
    }
}
