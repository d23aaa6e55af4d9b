//! Latency harness of the real firmware under virtual time (no hardware, deterministic).
//!
//! While the arm runs a long motion and the Atom refreshes the servo state, a host sends
//! get_angles (0x20) again and again through the Basic. From a trace of every byte on the bus
//! it measures:
//!
//! * Atom reply latency: from the request's last byte on the bus (as the Basic forwarded it) to
//!   the first byte of the Atom's reply. Targets: median <= 0.3 ms, p99 <= 1.5 ms.
//! * State refresh rate: servo state reads (READ / SYNC READ covering register 56) per joint
//!   per second on the wire. Target >= 100 Hz.
//! * The Basic's added forwarding latency, beyond wire time, both ways: request fully received
//!   on USB -> first byte on the bus; reply's last byte on the bus -> first byte to the host.
//!
//! `cargo bench -p open-mycobot --bench sim_latency` (optionally `-- <requests>`).
#![allow(clippy::unwrap_used, clippy::expect_used, clippy::indexing_slicing)] // a test harness: a panic is a failed check

use open_mycobot::sim::{BusByte, RobotConfig, StationId, VirtualRobot};
use protocol_core::command::{Request, cmd};
use protocol_core::servo::{BROADCAST_ID, Instruction, PacketDecoder, reg};
use protocol_core::timing::{HOST_BAUD, HOST_REPLY_DEADLINE_US, wire_time_ns};
use protocol_core::units::{Centideg, SpeedPercent};
use protocol_core::{Frame, FrameDecoder};

const ATOM_MEDIAN_TARGET_US: f64 = 300.0;
const ATOM_P99_TARGET_US: f64 = 1_500.0;
const REFRESH_TARGET_HZ: f64 = 100.0;

/// A host frame one station sent, with the times of its first and last byte on the bus.
struct SentFrame {
    cmd: u8,
    /// Whether another transmission overlapped any of its bytes.
    garbled: bool,
    first_start_ns: u64,
    last_end_ns: u64,
}

/// The host frames `station` put on the bus, in order.
fn frames_from(trace: &[BusByte], station: StationId) -> Vec<SentFrame> {
    let bytes: Vec<&BusByte> = trace.iter().filter(|b| b.from == station).collect();
    let mut decoder = FrameDecoder::new();
    let mut out = Vec::new();
    for (i, b) in bytes.iter().enumerate() {
        let mut found = decoder.push(b.byte);
        while let Some(frame) = found {
            let first = i + 1 - frame.encoded_len().min(i + 1);
            out.push(SentFrame {
                cmd: frame.cmd(),
                garbled: bytes
                    .get(first..=i)
                    .is_some_and(|f| f.iter().any(|b| b.garbled)),
                first_start_ns: bytes[first].start_ns,
                last_end_ns: b.end_ns,
            });
            found = decoder.next_frame();
        }
    }
    out
}

/// Servo state reads per servo id sent by `station`.
fn state_reads(trace: &[BusByte], station: StationId) -> [u64; 8] {
    let mut counts = [0u64; 8];
    let mut decoder = PacketDecoder::new();
    let bytes: Vec<u8> = trace
        .iter()
        .filter(|b| b.from == station)
        .map(|b| b.byte)
        .collect();
    decoder.feed(&bytes, |p| match Instruction::parse(&p) {
        Ok(Instruction::Read { addr, count })
            if (addr..addr.saturating_add(count)).contains(&reg::PRESENT_POSITION) =>
        {
            if let Some(c) = counts.get_mut(usize::from(p.id())) {
                *c += 1;
            }
        }
        Ok(Instruction::SyncRead { addr, count, ids })
            if p.id() == BROADCAST_ID
                && (addr..addr.saturating_add(count)).contains(&reg::PRESENT_POSITION) =>
        {
            for &id in ids {
                if let Some(c) = counts.get_mut(usize::from(id)) {
                    *c += 1;
                }
            }
        }
        _ => {}
    });
    counts
}

fn percentile(sorted: &[f64], p: f64) -> f64 {
    if sorted.is_empty() {
        return f64::NAN;
    }
    let i = ((sorted.len() - 1) as f64 * p).round() as usize;
    sorted[i.min(sorted.len() - 1)]
}

fn summary(name: &str, mut values: Vec<f64>) -> (f64, f64) {
    values.sort_by(f64::total_cmp);
    let (median, p99) = (percentile(&values, 0.5), percentile(&values, 0.99));
    println!(
        "{name:<44} n={:<4} median {median:>8.1} us  p99 {p99:>8.1} us  max {:>8.1} us",
        values.len(),
        values.last().copied().unwrap_or(f64::NAN)
    );
    (median, p99)
}

fn verdict(ok: bool) -> &'static str {
    if ok { "ok" } else { "MISSED" }
}

fn send_motion(robot: &mut VirtualRobot, degrees: i16) {
    let frame = Request::SendAngles {
        angles: [Centideg(degrees * 100); 6],
        speed: SpeedPercent::new(15).unwrap_or(SpeedPercent::MAX),
    }
    .to_frame();
    // Fire and forget: the reply is drained with the next get_angles.
    robot.host_write(&frame.to_bytes());
}

fn main() {
    let requests: usize = std::env::args()
        .skip(1)
        .find_map(|a| a.parse().ok())
        .unwrap_or(300);
    measure(
        "the real arm (both boards hear their echo)",
        RobotConfig::default(),
        requests,
    );
    println!();
    measure(
        "no echo on either board",
        RobotConfig {
            atom_hears_echo: false,
            basic_hears_echo: false,
            ..RobotConfig::default()
        },
        requests,
    );
    println!();
    measure(
        "slow main loops (Atom 200 us, Basic 50 us per pass)",
        RobotConfig {
            atom_loop_us: 200,
            basic_loop_us: 50,
            ..RobotConfig::default()
        },
        requests,
    );
}

/// Runs the get_angles-during-motion session on a robot built from `config` and prints the
/// figures.
fn measure(label: &str, config: RobotConfig, requests: usize) {
    let wall = std::time::Instant::now();
    let mut robot = VirtualRobot::new(config);
    robot.run_for(1_500_000);
    let basic = robot.basic_station().unwrap_or(robot.atom_station());
    let atom = robot.atom_station();
    robot.bus_mut().set_tracing(true);
    send_motion(&mut robot, 60);
    robot.run_for(50_000);
    let mut drain = Vec::new();
    robot.host_read(&mut drain);

    let request = Request::GetAngles.to_frame();
    let request_wire_ns = wire_time_ns(request.encoded_len() as u32, HOST_BAUD);
    let byte_ns = wire_time_ns(1, HOST_BAUD);
    let mut all_writes_ns = Vec::new();
    let mut writes_ns = Vec::new();
    let mut host_first_byte_ns = Vec::new();
    let mut round_trips = Vec::new();
    let mut lost = 0;
    let mut trace = Vec::new();
    let measure_start_ns = robot.now_ns();
    for i in 0..requests {
        if i % 100 == 50 {
            send_motion(&mut robot, if i % 200 == 50 { -60 } else { 60 });
            robot.run_for(20_000);
            let mut drain = Vec::new();
            robot.host_read(&mut drain);
        }
        let t_write = robot.now_ns();
        all_writes_ns.push(t_write);
        robot.host_write(&request.to_bytes());
        let mut decoder = FrameDecoder::new();
        let mut first_byte: Option<u64> = None;
        let mut reply: Option<Frame> = None;
        while reply.is_none() && robot.now_ns() < t_write + HOST_REPLY_DEADLINE_US * 1_000 {
            robot.run_for(10);
            let mut bytes = Vec::new();
            robot.host_read(&mut bytes);
            if !bytes.is_empty() && first_byte.is_none() {
                first_byte = Some(robot.now_ns());
            }
            decoder.feed(&bytes, |f| {
                reply.get_or_insert(f);
            });
        }
        match (reply, first_byte) {
            (Some(f), Some(first)) if f.cmd() == cmd::GET_ANGLES => {
                writes_ns.push(t_write);
                host_first_byte_ns.push(first);
                round_trips.push((robot.now_ns() - t_write) as f64 / 1_000.0);
            }
            _ => {
                lost += 1;
                println!(
                    "lost: request #{i} sent at {} us got no get_angles reply within 0.5 s",
                    t_write / 1_000
                );
            }
        }
        trace.extend(robot.bus_mut().take_trace());
        // Ask again after 2..7 ms, like a client polling in a loop, sampling every phase of
        // the Atom's refresh cycle.
        robot.run_for(2_000 + (i as u64 * 1_237) % 5_000);
        let mut drain = Vec::new();
        robot.host_read(&mut drain);
    }
    trace.extend(robot.bus_mut().take_trace());
    let measured_s = (robot.now_ns() - measure_start_ns) as f64 / 1e9;

    let basic_frames = frames_from(&trace, basic);
    let atom_frames = frames_from(&trace, atom);
    let mut atom_latency = Vec::new();
    let mut basic_in = Vec::new();
    let mut basic_out = Vec::new();
    for &t_write in &all_writes_ns {
        let received_ns = t_write + request_wire_ns;
        if let Some(f) = basic_frames
            .iter()
            .find(|f| f.cmd == cmd::GET_ANGLES && f.first_start_ns >= t_write)
        {
            basic_in.push(f.first_start_ns.saturating_sub(received_ns) as f64 / 1_000.0);
        }
    }
    for (&t_write, &first) in writes_ns.iter().zip(&host_first_byte_ns) {
        let received_ns = t_write + request_wire_ns;
        let Some(reply) = atom_frames
            .iter()
            .find(|f| f.cmd == cmd::GET_ANGLES && f.first_start_ns >= received_ns)
        else {
            continue;
        };
        // The forwarded copy the Atom answered: the last one before its reply.
        let Some(forwarded) = basic_frames.iter().rev().find(|f| {
            f.cmd == cmd::GET_ANGLES
                && f.first_start_ns >= t_write
                && f.last_end_ns <= reply.first_start_ns
        }) else {
            continue;
        };
        atom_latency.push((reply.first_start_ns - forwarded.last_end_ns) as f64 / 1_000.0);
        // The first byte arrived one byte time after it started (+ up to 10 us of polling).
        let started = first.saturating_sub(byte_ns);
        basic_out.push(started.saturating_sub(reply.last_end_ns) as f64 / 1_000.0);
    }

    println!(
        "virtual robot latency harness, {label}: {requests} get_angles during motion, \
         {measured_s:.2} s virtual"
    );
    let (median, p99) = summary(
        "Atom reply (request end on bus -> reply start)",
        atom_latency,
    );
    println!(
        "  targets median <= {ATOM_MEDIAN_TARGET_US} us: {}, p99 <= {ATOM_P99_TARGET_US} us: {}",
        verdict(median <= ATOM_MEDIAN_TARGET_US),
        verdict(p99 <= ATOM_P99_TARGET_US)
    );
    summary("Basic added, host -> bus (beyond wire time)", basic_in);
    summary("Basic added, bus -> host (10 us resolution)", basic_out);
    summary("host round trip (write -> reply complete)", round_trips);
    let reads = state_reads(&trace, atom);
    let rates: Vec<f64> = (1..=6).map(|id| reads[id] as f64 / measured_s).collect();
    let slowest = rates.iter().copied().fold(f64::INFINITY, f64::min);
    println!(
        "state reads per joint (Hz): {}  gripper {:.1}",
        rates
            .iter()
            .map(|r| format!("{r:.1}"))
            .collect::<Vec<_>>()
            .join(" "),
        reads[7] as f64 / measured_s
    );
    println!(
        "  target >= {REFRESH_TARGET_HZ} Hz on every joint: {}",
        verdict(slowest >= REFRESH_TARGET_HZ)
    );
    let busy_ns: u64 = trace.iter().map(|b| b.end_ns - b.start_ns).sum();
    println!(
        "bus busy {:.0} % of the time",
        busy_ns as f64 / (measured_s * 1e9) * 100.0
    );
    let forwarded = basic_frames.len();
    let hit = basic_frames.iter().filter(|f| f.garbled).count();
    let replies_hit = atom_frames.iter().filter(|f| f.garbled).count();
    println!(
        "frames hit by a collision: {hit} of {forwarded} sent by the Basic, {replies_hit} of {} \
         sent by the Atom",
        atom_frames.len()
    );
    println!(
        "lost replies: {lost}, bus bytes garbled by collisions: {}",
        robot.bus().collisions()
    );
    let virtual_s = robot.now_ns() as f64 / 1e9;
    let wall_s = wall.elapsed().as_secs_f64();
    println!(
        "simulated {virtual_s:.2} s in {wall_s:.2} s of wall time ({:.1}x real time)",
        virtual_s / wall_s
    );
}
