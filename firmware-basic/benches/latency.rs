//! Forwarding latency of the transponder, in virtual time: how long after the last byte of a
//! request arrives the first byte of the forwarded frame leaves, host -> bus (115200 in, 1 Mbaud
//! out), and when the reply's first byte leaves to the host against the reply's last byte on
//! the bus, bus -> host (1 Mbaud in, 115200 out; negative: passed on before it ended, the
//! cut-through). That is the latency the Basic adds beyond the wire time of the frame itself;
//! the target is under 50 us each way. The Basic is polled every `poll` microseconds (a board's
//! loop is far faster; the virtual robot polls every 10 us). Also reports the host CPU time of
//! one poll.
//!
//! Run: `cargo bench -p firmware-basic --bench latency`.
#![allow(clippy::unwrap_used, clippy::indexing_slicing, missing_docs)]

#[path = "../tests/common/mod.rs"]
mod common;

use std::time::Instant;

use common::{Rig, ack_everything, frame};
use firmware_basic::{BasicConfig, EchoMode};
use protocol_core::timing;

/// Latencies in ns of `rounds` exchanges of `request` (host -> bus and bus -> host), on an
/// idle wire or one busy with the Atom's servo polling.
fn measure(
    request: &[u8],
    echo: bool,
    poll_ns: u64,
    rounds: usize,
    servo_traffic: bool,
) -> (Vec<i64>, Vec<i64>) {
    let config = BasicConfig {
        echo: EchoMode::Auto,
        power_on_at_boot: false,
        probe_interval_us: 0,
        ..BasicConfig::default()
    };
    let mut rig = Rig::new(config, echo);
    rig.atom = ack_everything();
    rig.step_ns = poll_ns;
    let mut to_bus = Vec::new();
    let mut to_host = Vec::new();
    for round in 0..rounds {
        rig.run_us(1_000);
        // Vary where the request and the reply fall against the poll period: shift the poll
        // grid by one odd step, and give the Atom an off-grid turnaround.
        let saved = rig.step_ns;
        rig.step_ns = 1 + (round as u64 * 337) % poll_ns;
        rig.step();
        rig.step_ns = saved;
        rig.atom_delay_ns = 150_000 + (round as u64 * 3_331) % 10_000;
        if servo_traffic {
            // The Atom polls a servo by its bus schedule (29-byte transactions, 100 us gaps,
            // held while the Basic talks in a gap), from a varying phase.
            let now = rig.now_ns;
            rig.wire()
                .poll_servos(now + (round as u64 * 7_919) % 400_000, now + 6_000_000);
        }
        let sent_before = rig.wire().basic_sent.len();
        let host_before = rig.host.from_basic.len();
        let arrived = rig.host.send(request);
        assert!(rig.run_until_host_has(host_before + 1, 20_000), "no reply");
        // The request's first byte (bytes before it held the bus for it).
        let sent = &rig.wire().basic_sent[sent_before..];
        let first_out = sent
            .windows(2)
            .find(|w| w[0].1 == 0xFE && w[1].1 == 0xFE)
            .map_or(sent[0].0, |w| w[0].0);
        to_bus.push(first_out as i64 - arrived as i64);
        let (reply_start, reply) = rig.atom_sent.last().unwrap().clone();
        let reply_end = reply_start + reply.len() as u64 * common::BUS_BYTE_NS;
        // Let the whole reply out before the next request.
        rig.run_us(if servo_traffic { 6_000 } else { 3_000 });
        to_host.push(rig.host.from_basic[host_before].0 as i64 - reply_end as i64);
    }
    (to_bus, to_host)
}

fn summary(ns: &mut [i64]) -> String {
    ns.sort_unstable();
    let pct = |p: usize| ns[(ns.len() - 1) * p / 100] as f64 / 1_000.0;
    format!(
        "median {:6.1} us  p99 {:6.1} us  max {:6.1} us",
        pct(50),
        pct(99),
        pct(100)
    )
}

fn main() {
    let rounds = 200;
    let requests: [(&str, Vec<u8>); 2] = [
        ("get_angles (5 B)", frame(0x20, &[])),
        (
            "send_angles (18 B)",
            frame(
                0x22,
                &[0, 100, 0xFF, 0x9C, 0, 0, 0, 0, 0x12, 0x34, 0xFE, 0xFA, 50],
            ),
        ),
    ];
    println!("Basic forwarding latency beyond the frame's own wire time (virtual time)");
    for poll_us in [1u64, 5, 10] {
        for echo in [true, false] {
            for (name, request) in &requests {
                let (mut to_bus, mut to_host) =
                    measure(request, echo, poll_us * 1_000, rounds, false);
                println!(
                    "poll {poll_us:2} us, echo {:5}, {name:18}: host->bus {} | bus->host {}",
                    echo,
                    summary(&mut to_bus),
                    summary(&mut to_host)
                );
            }
        }
    }

    println!(
        "With the Atom polling servos (29-byte transactions, {} us gaps): the Basic waits for \
         a free slot early in a gap ({}..{} us of quiet)",
        timing::ATOM_TRANSACTION_GAP_US,
        timing::BUS_QUIET_BEFORE_SEND_US,
        firmware_basic::forwarder::LATEST_START_IN_GAP_US
    );
    for echo in [true, false] {
        let (name, request) = &requests[0];
        let (mut to_bus, mut to_host) = measure(request, echo, 10_000, rounds, true);
        println!(
            "poll 10 us, echo {:5}, {name:18}: host->bus {} | bus->host {}",
            echo,
            summary(&mut to_bus),
            summary(&mut to_host)
        );
    }

    // CPU cost of one poll on this machine: idle, and while forwarding a stream of requests.
    let mut rig = Rig::new(BasicConfig::default(), true);
    rig.step_ns = 1_000;
    let polls = 200_000;
    let t = Instant::now();
    for _ in 0..polls {
        rig.step();
    }
    let idle_ns = t.elapsed().as_nanos() as f64 / polls as f64;
    let t = Instant::now();
    // One get_angles after another, each sent when the previous 17-byte reply is complete.
    let mut replied_bytes = rig.host.from_basic.len();
    for _ in 0..polls {
        if rig.host.from_basic.len() >= replied_bytes {
            rig.host.send(&frame(0x20, &[]));
            replied_bytes += 17;
        }
        rig.step();
    }
    let busy_ns = t.elapsed().as_nanos() as f64 / polls as f64;
    println!(
        "RAM of one Basic (all buffers included): {} bytes",
        std::mem::size_of::<firmware_basic::Basic>()
    );
    println!(
        "host CPU per rig step (Basic poll + simulated wire): idle {idle_ns:.0} ns, busy {busy_ns:.0} ns"
    );
}
