//! Host timing of forward kinematics, full inverse kinematics (all branches + selection) and a
//! linear-path step: `cargo bench -p kinematics-core`. Instruction counts per call:
//! `kinematics-core/benches/callgrind.sh`.
#![allow(missing_docs, clippy::indexing_slicing)] // bench harness; indices cycle within the arrays

use criterion::{Criterion, criterion_group, criterion_main};
use kinematics_core::{JointAngles, Kinematics, LinearPath, Pose};
use std::hint::black_box;

/// A spread of in-limit configurations (none singular).
const CONFIGS: [[i32; 6]; 4] = [
    [1_000, -3_000, -6_000, 1_500, 2_000, 500],
    [-4_500, 2_000, 7_000, -3_000, -6_000, 9_000],
    [12_000, -8_000, 4_000, 6_000, 3_000, -12_000],
    [-15_000, 6_000, -11_000, -9_000, 12_000, 3_000],
];

fn bench(c: &mut Criterion) {
    let kin = Kinematics::new();
    let configs = CONFIGS.map(JointAngles);
    let poses = configs.map(|q| kin.forward(&q));

    // One call per iteration, cycling through the configurations.
    let mut i = 0;
    c.bench_function("forward, per call", |b| {
        b.iter(|| {
            i = (i + 1) % configs.len();
            kin.forward(black_box(&configs[i]))
        })
    });
    c.bench_function("inverse (all branches + nearest), per call", |b| {
        b.iter(|| {
            i = (i + 1) % configs.len();
            kin.inverse(black_box(&poses[i]), black_box(&configs[i]))
        })
    });
    let start = configs[0];
    let from = poses[0];
    let to = Pose {
        x: from.x - 400,
        y: from.y + 300,
        z: from.z - 200,
        ..from
    };
    c.bench_function("linear path, 27 steps of 2 mm", |b| {
        b.iter(|| {
            let mut steps = 0;
            if let Ok(mut path) = LinearPath::new(&kin, black_box(&start), black_box(&to), 20) {
                while let Some(Ok(_)) = path.next(&kin) {
                    steps += 1;
                }
            }
            steps
        })
    });
}

criterion_group!(benches, bench);
criterion_main!(benches);
