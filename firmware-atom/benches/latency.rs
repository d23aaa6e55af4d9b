//! Latency and refresh-rate harness: the Atom with simulated servos under virtual time, while a
//! motion runs and the state refresh is active, answering get_angles sent by a Basic-like
//! host at pseudo-random moments. Prints the median / p99 / max time from the request's last
//! byte to the reply's first byte (leaving the Atom) and last byte, and the refresh rate.
//!
//! `cargo bench -p firmware-atom --bench latency`
#![allow(clippy::unwrap_used, clippy::expect_used, clippy::indexing_slicing)]

#[path = "../tests/support/mod.rs"]
mod support;

use protocol_core::Frame;
use protocol_core::timing::{BUS_BAUD, wire_time_us};
use support::rig::{Rig, be};

const SAMPLES: usize = 2000;

fn percentile(sorted: &[u64], p: f64) -> u64 {
    let i = ((sorted.len() as f64 - 1.0) * p).round() as usize;
    sorted[i]
}

fn main() {
    for echo in [true, false] {
        let mut rig = Rig::with(
            firmware_atom::AtomConfig {
                powered_at_boot: true,
                ..Default::default()
            },
            echo,
        );
        let get_angles = Frame::new(0x20, &[]).unwrap();
        let reply_wire_us = wire_time_us(12 + 5, BUS_BAUD);
        let mut to_end = Vec::with_capacity(SAMPLES);
        let mut seed: u64 = 0x2545_F491_4F6C_DD1D;
        let start_us = rig.now();
        let rounds_before = rig.atom.refresh_rounds();
        let mut forward = true;
        for i in 0..SAMPLES {
            if i % 200 == 0 {
                // Keep a motion running: swing all joints back and forth.
                let a: i16 = if forward { 6000 } else { -6000 };
                forward = !forward;
                let mut data = be(&[a, a / 2, a / 2, a, a, a]);
                data.push(40);
                rig.request(&Frame::new(0x22, &data).unwrap()).unwrap();
            }
            // xorshift: a pseudo-random pause of 0..5 ms so requests hit every phase of the
            // bus schedule.
            seed ^= seed << 13;
            seed ^= seed >> 7;
            seed ^= seed << 17;
            rig.run_us(seed % 5000);
            let Some((reply, us)) = rig.request_timed(&get_angles) else {
                panic!("no reply: echo {echo} sample {i} at {} us", rig.now());
            };
            assert_eq!(reply.cmd(), 0x20);
            to_end.push(us);
        }
        let elapsed_s = (rig.now() - start_us) as f64 / 1e6;
        let rounds = rig.atom.refresh_rounds() - rounds_before;
        to_end.sort_unstable();
        let to_start: Vec<u64> = to_end
            .iter()
            .map(|t| t.saturating_sub(reply_wire_us))
            .collect();
        println!(
            "echo {echo:5}: get_angles reply leaves after median {} us, p99 {} us, max {} us \
             (last byte: median {} us, p99 {} us); state refresh {:.0} Hz over {:.1} s \
             ({} servo transactions)",
            percentile(&to_start, 0.5),
            percentile(&to_start, 0.99),
            to_start.last().unwrap(),
            percentile(&to_end, 0.5),
            percentile(&to_end, 0.99),
            f64::from(rounds) / elapsed_s,
            elapsed_s,
            rig.bus.instructions,
        );
    }
}
