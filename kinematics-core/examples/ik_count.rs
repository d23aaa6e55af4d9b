//! Runs `N` (first argument, default 0) calls of `ik` (seeded with the answer's neighbourhood),
//! `ik-far` (seeded with the zero pose) or `fk` (second argument), for counting instructions
//! with callgrind; see `benches/callgrind.sh`.
#![allow(missing_docs)]

use kinematics_core::{JointAngles, Kinematics};
use std::hint::black_box;

fn main() {
    let n: u32 = std::env::args()
        .nth(1)
        .and_then(|s| s.parse().ok())
        .unwrap_or(0);
    let what = std::env::args().nth(2).unwrap_or_else(|| "ik".into());
    let kin = Kinematics::new();
    let q = JointAngles([1_000, -3_000, -6_000, 1_500, 2_000, 500]);
    let pose = kin.forward(&q);
    let mut acc = 0i32;
    for _ in 0..n {
        acc ^= match what.as_str() {
            "fk" => kin.forward(black_box(&q)).x,
            // Seeded far from the answer (a large move).
            "ik-far" => kin
                .inverse(black_box(&pose), black_box(&JointAngles::default()))
                .map_or(0, |s| s.0[0]),
            _ => kin
                .inverse(black_box(&pose), black_box(&q))
                .map_or(0, |s| s.0[0]),
        };
    }
    println!("{acc}");
}
