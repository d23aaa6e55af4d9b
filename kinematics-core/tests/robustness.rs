//! Nothing a host can send makes the kinematics panic or return an out-of-limit answer: poses,
//! seeds, limits and frames over the whole i32 range (debug builds check every overflow).

use kinematics_core::{JointAngles, JointLimits, Kinematics, LinearPath, Pose};
use proptest::prelude::*;

fn any_pose() -> impl Strategy<Value = Pose> {
    (
        any::<i32>(),
        any::<i32>(),
        any::<i32>(),
        any::<i32>(),
        any::<i32>(),
        any::<i32>(),
    )
        .prop_map(|(x, y, z, rx, ry, rz)| Pose {
            x,
            y,
            z,
            rx,
            ry,
            rz,
        })
}

/// Poses the wire can carry (i16) and near the arm, where solutions exist.
fn wire_pose() -> impl Strategy<Value = Pose> {
    (
        -3_000..3_000i32,
        -3_000..3_000i32,
        -1_000..4_500i32,
        -18_000..18_000i32,
        -9_000..9_000i32,
        -18_000..18_000i32,
    )
        .prop_map(|(x, y, z, rx, ry, rz)| Pose {
            x,
            y,
            z,
            rx,
            ry,
            rz,
        })
}

fn any_joints() -> impl Strategy<Value = JointAngles> {
    prop::array::uniform6(any::<i32>()).prop_map(JointAngles)
}

proptest! {
    #![proptest_config(ProptestConfig {
        cases: if cfg!(debug_assertions) { 300 } else { 3_000 },
        failure_persistence: None,
        ..ProptestConfig::default()
    })]

    #[test]
    fn any_input_is_answered_without_panic(
        target in prop_oneof![any_pose(), wire_pose()],
        seed in any_joints(),
        tool in proptest::option::of(any_pose()),
        world in proptest::option::of(any_pose()),
    ) {
        let mut kin = Kinematics::new();
        kin.set_tool(tool);
        kin.set_world(world);
        let _ = kin.forward(&seed);
        if let Ok(q) = kin.inverse(&target, &seed) {
            prop_assert!(kin.limits().contains(&q));
        }
        let _ = kin.inverse_all(&target, &seed);
    }

    #[test]
    fn targets_next_to_the_seed_are_answered_without_panic(
        seed in prop::array::uniform6(-15_000..15_000i32),
        delta in prop::array::uniform6(-30..30i32),
        tool in proptest::option::of(wire_pose()),
    ) {
        // Exercises the seed-keeping paths (shoulder, elbow, wrist) with overflow checks on.
        let mut kin = Kinematics::new();
        kin.set_tool(tool);
        let seed = JointAngles(seed);
        let p = kin.forward(&seed);
        let target = Pose {
            x: p.x + delta[0],
            y: p.y + delta[1],
            z: p.z + delta[2],
            rx: p.rx + delta[3],
            ry: p.ry + delta[4],
            rz: p.rz + delta[5],
        };
        if let Ok(q) = kin.inverse(&target, &seed) {
            prop_assert!(kin.limits().contains(&q));
        }
    }

    #[test]
    fn any_limits_are_respected(
        target in wire_pose(),
        seed in any_joints(),
        min in prop::array::uniform6(-40_000..40_000i32),
        max in prop::array::uniform6(-40_000..40_000i32),
    ) {
        let mut kin = Kinematics::new();
        kin.set_limits(JointLimits { min, max });
        if let Ok(q) = kin.inverse(&target, &seed) {
            prop_assert!(kin.limits().contains(&q), "{q:?}");
        }
    }

    #[test]
    fn any_linear_path_starts_or_refuses_without_panic(
        start in any_joints(),
        target in prop_oneof![any_pose(), wire_pose()],
        step in any::<i32>(),
    ) {
        let kin = Kinematics::new();
        if let Ok(mut path) = LinearPath::new(&kin, &start, &target, step) {
            for _ in 0..5 {
                match path.next(&kin) {
                    Some(Ok(q)) => prop_assert!(kin.limits().contains(&q)),
                    Some(Err(e)) => prop_assert!(matches!(e.protocol_code(), 33 | 34)),
                    None => break,
                }
            }
        }
    }
}
