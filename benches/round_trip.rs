//! get_angles (0x20) round trips through the Basic, hop by hop, under virtual time (no
//! hardware, deterministic).
//!
//! A client like pymycobot asks, waits for the whole reply, thinks for a while and asks again
//! (lock step), on the Basic's USB serial at 115 200 baud, while the Atom refreshes the servos'
//! state on the bus. Every byte on both wires is traced ([`HopTrace`]) and each round trip cut
//! into its hops ([`HOP_NAMES`]): the USB wire in, the Basic's decision, its wait for a gap on
//! the bus, the bus wire both ways, the Atom's turnaround, the Basic's store or cut-through, the
//! USB wire out. It prints each hop's distribution and the round trips' (median, p90, p99, max)
//! and their rate, for a client that thinks 0 us (the wire's and the firmware's limit) and one
//! that thinks a random 0..1 ms (samples every phase of the Atom's refresh cycle), each with
//! the Basic as shipped and with its reply cut-through and bus hold off (the firmware before
//! them), and what the servo refresh got meanwhile.
//!
//! With `--pty` it measures the real-time front end instead (`src/host/realtime.rs`, what
//! `cargo run --release` serves): the robot runs on the wall clock behind a pseudo-terminal, and
//! a client thread in this process (no Python) writes each request and reads its reply. Each
//! round trip is split into what the front end adds and the virtual hops: the client's write
//! until the loop hands the bytes to the robot, the virtual round trip, the reply's last byte's
//! virtual arrival until the loop reads it, and the loop's write to the pty until the client has
//! read it. Wall-clock figures: they depend on the machine and its load.
//!
//! `cargo bench -p open-mycobot --bench round_trip` (optionally `-- <requests>`, default 5000;
//! `-- --pty <requests>`).
#![allow(clippy::unwrap_used, clippy::expect_used, clippy::indexing_slicing)] // a bench: a panic is a failed run

use firmware_basic::BasicConfig;
use open_mycobot::sim::hops::{HOP_NAMES, HopTrace, Hops};
use open_mycobot::sim::{BusByte, RobotConfig, StationId, VirtualRobot};
use protocol_core::command::{Request, cmd};
use protocol_core::servo::{Instruction, PacketDecoder};
use protocol_core::timing::HOST_REPLY_DEADLINE_US;
use protocol_core::{Frame, FrameDecoder};

/// How often the simulated client looks for its reply, in ns of virtual time.
const CLIENT_POLL_NS: u64 = 1_000;

fn percentile(sorted: &[u64], p: f64) -> u64 {
    if sorted.is_empty() {
        return 0;
    }
    let i = ((sorted.len() - 1) as f64 * p).round() as usize;
    sorted[i.min(sorted.len() - 1)]
}

/// Median, p90, p99 and max of `values` (ns), in us.
fn distribution(mut values: Vec<u64>) -> [f64; 4] {
    values.sort_unstable();
    [0.5, 0.9, 0.99, 1.0].map(|p| percentile(&values, p) as f64 / 1_000.0)
}

/// A small deterministic generator for the client's think times.
struct Xorshift(u64);

impl Xorshift {
    fn below(&mut self, n: u64) -> u64 {
        self.0 ^= self.0 << 13;
        self.0 ^= self.0 >> 7;
        self.0 ^= self.0 << 17;
        self.0 % n.max(1)
    }
}

/// Runs `requests` lock-step get_angles on `config`, the client thinking `think_us(i)` after
/// reply `i`; prints the hop table and the round trips.
fn measure(label: &str, config: RobotConfig, requests: usize, mut think_us: impl FnMut() -> u64) {
    let wall = std::time::Instant::now();
    let mut robot = VirtualRobot::new(config);
    // Booted, the Basic's first questions to the Atom asked and answered.
    robot.run_for(1_500_000);
    let basic = robot.basic_station().expect("the robot has a Basic");
    let atom = robot.atom_station();
    robot.set_hop_tracing(true);
    let request = Request::GetAngles.to_frame().to_bytes();
    let mut trace = HopTrace::default();
    let mut lost = 0;
    let start_ns = robot.now_ns();
    for _ in 0..requests {
        robot.host_write(&request);
        let deadline_ns = robot.now_ns() + HOST_REPLY_DEADLINE_US * 1_000;
        let mut decoder = FrameDecoder::new();
        let mut reply: Option<Frame> = None;
        while reply.is_none() && robot.now_ns() < deadline_ns {
            robot.run_until_ns(robot.now_ns() + CLIENT_POLL_NS);
            let mut bytes = Vec::new();
            robot.host_read(&mut bytes);
            decoder.feed(&bytes, |f| {
                reply.get_or_insert(f);
            });
        }
        if reply.is_none_or(|f| f.cmd() != cmd::GET_ANGLES) {
            lost += 1;
        }
        robot.run_until_ns(robot.now_ns() + think_us() * 1_000);
        trace.extend(robot.take_hop_trace());
    }
    let elapsed_s = (robot.now_ns() - start_ns) as f64 / 1e9;
    let trips: Vec<Hops> = trace.round_trips(basic, atom, cmd::GET_ANGLES);

    println!("{label}: {requests} get_angles, {elapsed_s:.2} s virtual, lost {lost}");
    println!(
        "  {:<52} {:>8} {:>8} {:>8} {:>8}",
        "hop (us)", "median", "p90", "p99", "max"
    );
    for (i, name) in HOP_NAMES.iter().enumerate() {
        let [median, p90, p99, max] = distribution(trips.iter().map(|h| h.hops_ns()[i]).collect());
        println!("  {name:<52} {median:>8.1} {p90:>8.1} {p99:>8.1} {max:>8.1}");
    }
    let round_trips: Vec<u64> = trips.iter().map(Hops::round_trip_ns).collect();
    let mean_us = round_trips.iter().sum::<u64>() as f64 / round_trips.len().max(1) as f64 / 1e3;
    let [median, p90, p99, max] = distribution(round_trips);
    println!(
        "  {:<52} {median:>8.1} {p90:>8.1} {p99:>8.1} {max:>8.1}",
        "round trip (request's first byte -> reply's last)"
    );
    let resent = trips.iter().filter(|h| h.bus_copies > 1).count();
    println!(
        "  rate {:.0} round trips/s (client thinking included), {:.0}/s on the wire alone \
         (1 / mean round trip {mean_us:.1} us); {} of {requests} followed, {resent} sent twice on the bus",
        requests as f64 / elapsed_s,
        1e6 / mean_us,
        trips.len(),
    );
    // What holding the bus for requests costs the servo refresh: state reads per servo.
    let reads = state_reads(&trace.bus, atom);
    println!(
        "  servo state reads per second, servos 1..7: {}; the Basic's bytes on the bus that \
         were no frame (holding the bus): {}",
        reads
            .iter()
            .map(|n| format!("{:.0}", *n as f64 / elapsed_s))
            .collect::<Vec<_>>()
            .join(" "),
        held_bytes(&trace.bus, basic)
    );
    println!(
        "  simulated in {:.2} s of wall time\n",
        wall.elapsed().as_secs_f64()
    );
}

/// READs of each servo 1..7 the Atom put on the bus.
fn state_reads(bus: &[BusByte], atom: StationId) -> [u64; 7] {
    let mut counts = [0u64; 7];
    let bytes: Vec<u8> = bus
        .iter()
        .filter(|b| b.from == atom)
        .map(|b| b.byte)
        .collect();
    PacketDecoder::new().feed(&bytes, |p| {
        if let Ok(Instruction::Read { .. }) = Instruction::parse(&p)
            && let Some(c) = usize::from(p.id())
                .checked_sub(1)
                .and_then(|i| counts.get_mut(i))
        {
            *c += 1;
        }
    });
    counts
}

/// The Basic's bytes on the bus outside its frames.
fn held_bytes(bus: &[BusByte], basic: StationId) -> usize {
    let bytes: Vec<u8> = bus
        .iter()
        .filter(|b| b.from == basic)
        .map(|b| b.byte)
        .collect();
    let mut in_frames = 0;
    FrameDecoder::new().feed(&bytes, |f| in_frames += f.encoded_len());
    bytes.len() - in_frames
}

fn main() {
    let requests: usize = std::env::args()
        .skip(1)
        .find_map(|a| a.parse().ok())
        .unwrap_or(5_000);
    if std::env::args().any(|a| a == "--pty") {
        realtime::measure(requests);
        return;
    }
    let slow = RobotConfig {
        atom_loop_us: 200,
        basic_loop_us: 50,
        ..RobotConfig::default()
    };
    for (label, base, random) in [
        (
            "client thinking 0 us (the wire's and the firmware's limit)",
            RobotConfig::default(),
            false,
        ),
        (
            "client thinking 0..1000 us at random (every phase of the Atom's refresh)",
            RobotConfig::default(),
            true,
        ),
        (
            "slow main loops (Atom 200 us, Basic 50 us per pass), client thinking 0..1000 us",
            slow,
            true,
        ),
    ] {
        for (firmware, cut_through, bus_hold) in [
            ("as shipped", true, true),
            (
                "replies stored whole, bus not held (before #30)",
                false,
                false,
            ),
        ] {
            let config = RobotConfig {
                basic: BasicConfig {
                    cut_through,
                    bus_hold,
                    ..base.basic
                },
                ..base
            };
            let mut rng = Xorshift(0x2545_f491_4f6c_dd1d);
            measure(&format!("{label}, {firmware}"), config, requests, || {
                if random { rng.below(1_000) } else { 0 }
            });
        }
    }
}

/// The real-time front end's share of a round trip (`--pty`).
mod realtime {
    use std::fs::OpenOptions;
    use std::io::{Read, Write};
    use std::sync::Arc;
    use std::sync::atomic::{AtomicBool, Ordering};
    use std::time::Instant;

    use open_mycobot::host::pty::PseudoTerminal;
    use open_mycobot::host::realtime::{RealtimeDriver, RealtimeRobot};
    use open_mycobot::sim::hops::{HOP_NAMES, Hops};
    use open_mycobot::sim::{HostLink, RobotConfig, VirtualRobot};
    use protocol_core::command::{Request, cmd};

    use super::distribution;

    /// The robot, noting when (wall clock and virtual time) the loop handed it the client's
    /// bytes and took its replies.
    struct Timed {
        robot: VirtualRobot,
        /// Wall time and virtual ns of each hand-over of client bytes.
        writes: Vec<(Instant, u64)>,
        /// Wall time, virtual ns and byte count of each read that took reply bytes.
        reads: Vec<(Instant, u64, usize)>,
    }

    impl RealtimeRobot for Timed {
        fn now_us(&self) -> u64 {
            self.robot.now_us()
        }
        fn host_write(&mut self, bytes: &[u8]) {
            self.writes.push((Instant::now(), self.robot.now_ns()));
            self.robot.host_write(bytes);
        }
        fn host_read(&mut self, out: &mut Vec<u8>) {
            let before = out.len();
            self.robot.host_read(out);
            if out.len() > before {
                self.reads
                    .push((Instant::now(), self.robot.now_ns(), out.len() - before));
            }
        }
        fn run_until(&mut self, t_us: u64) {
            self.robot.run_until(t_us);
        }
        fn next_output_us(&self) -> Option<u64> {
            self.robot
                .link_next_arrival_ns(HostLink::Basic)
                .map(|ns| ns.div_ceil(1_000))
        }
    }

    fn ns(d: std::time::Duration) -> u64 {
        u64::try_from(d.as_nanos()).unwrap_or(u64::MAX)
    }

    pub(super) fn measure(requests: usize) {
        let mut robot = VirtualRobot::new(RobotConfig::default());
        robot.run_for(1_500_000);
        robot.set_hop_tracing(true);
        let timed = Timed {
            robot,
            writes: Vec::new(),
            reads: Vec::new(),
        };
        let driver = RealtimeDriver::new(timed, PseudoTerminal::open().unwrap(), None);
        let mut client = OpenOptions::new()
            .read(true)
            .write(true)
            .open(driver.pty().slave_path())
            .unwrap();
        let stop = Arc::new(AtomicBool::new(false));
        let loop_stop = Arc::clone(&stop);
        let handle = std::thread::spawn(move || driver.run(&loop_stop).unwrap());

        let request = Request::GetAngles.to_frame().to_bytes();
        let reply_len = 17;
        // Wall time of each write and of each reply read whole.
        let mut calls: Vec<(Instant, Instant)> = Vec::with_capacity(requests);
        let start = Instant::now();
        for _ in 0..requests {
            let t0 = Instant::now();
            client.write_all(&request).unwrap();
            let mut reply = [0u8; 17];
            client.read_exact(&mut reply[..reply_len]).unwrap();
            calls.push((t0, Instant::now()));
            assert_eq!(reply[3], cmd::GET_ANGLES, "{reply:02x?}");
        }
        let elapsed = start.elapsed();
        stop.store(true, Ordering::Relaxed);
        let mut timed = handle.join().unwrap();

        let trace = timed.robot.take_hop_trace();
        let basic = timed.robot.basic_station().unwrap();
        let trips: Vec<Hops> =
            trace.round_trips(basic, timed.robot.atom_station(), cmd::GET_ANGLES);
        // Each client call: its hand-over (the loop's first write after the client's), its
        // virtual hops, the read that took the reply's last byte.
        let mut input = Vec::new();
        let mut tick = Vec::new();
        let mut output = Vec::new();
        let mut wall = Vec::new();
        let mut virtual_rt = Vec::new();
        let mut hops: Vec<[u64; 8]> = Vec::new();
        let mut trips_iter = trips.iter().peekable();
        for &(t0, t_done) in &calls {
            let Some(&(w_wall, w_virtual)) = timed.writes.iter().find(|(w, _)| *w >= t0) else {
                continue;
            };
            while trips_iter
                .peek()
                .is_some_and(|h| h.request_start_ns < w_virtual)
            {
                trips_iter.next();
            }
            let Some(trip) = trips_iter.next() else {
                break;
            };
            let Some(&(r_wall, r_virtual, _)) =
                timed.reads.iter().find(|(_, v, _)| *v >= trip.usb_end_ns)
            else {
                continue;
            };
            input.push(ns(w_wall.duration_since(t0)));
            virtual_rt.push(trip.round_trip_ns());
            hops.push(trip.hops_ns());
            tick.push(r_virtual - trip.usb_end_ns);
            output.push(ns(t_done.saturating_duration_since(r_wall)));
            wall.push(ns(t_done.duration_since(t0)));
        }
        timed.reads.clear();
        println!(
            "real-time front end on a pty, a Rust client in this process: {} get_angles in \
             {:.2} s = {:.0} round trips/s ({} followed)",
            requests,
            elapsed.as_secs_f64(),
            requests as f64 / elapsed.as_secs_f64(),
            wall.len()
        );
        println!(
            "  {:<52} {:>8} {:>8} {:>8} {:>8}",
            "hop (us)", "median", "p90", "p99", "max"
        );
        let row = |name: &str, values: Vec<u64>| {
            let [median, p90, p99, max] = distribution(values);
            println!("  {name:<52} {median:>8.1} {p90:>8.1} {p99:>8.1} {max:>8.1}");
        };
        row("client write -> loop hands the bytes over (wall)", input);
        for (i, name) in HOP_NAMES.iter().enumerate() {
            row(name, hops.iter().map(|h| h[i]).collect());
        }
        row("reply's last byte in -> loop reads it (virtual)", tick);
        row("loop writes it to the pty -> client has it (wall)", output);
        row("virtual round trip", virtual_rt);
        row("client's round trip (wall)", wall);
    }
}
