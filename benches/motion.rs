//! Motion quality of the real firmware under virtual time, measured at the simulated servos'
//! shafts (their true, unquantised positions) through an independent f64 model of the arm:
//!
//! * **Stopping**: joint 1 jogs at 30, 60 and 100 % (45, 90, 150 deg/s), then stop (0x29);
//!   how far it travels after the stop request's last byte, and how long until it is at rest.
//!   Also pause (0x26) during a send_angles at 100 %.
//! * **Streams**: fresh mode, send_angles of a smooth sine on all joints at 20, 50 and 100 Hz
//!   (as mycobot_ros does on every joint state): the lag behind the stream beyond one period,
//!   the residual after removing the lag (RMS and worst), and whether the stream's end is a
//!   clean stop at its last target. Then 50 Hz streams as a busy host sends them: samples late
//!   by up to 5, 10 or 20 ms, 10 % or 30 % of them dropped, and bursts (the samples held up by
//!   a stall of 60, 100 or 200 ms sent back to back), and samples taken late by up to 10 or
//!   20 ms (carrying the sine at the time they were sent, as a client that samples when it gets
//!   to send): lag, residual and worst error for each.
//! * **Lines**: send_coords mode 1 and jog_coord at speed 50: the flange's largest distance from
//!   the straight segment, and its largest turn from the orientation.
//! * **Arcs**: move_c_coords (0x8C) from the present pose through two more at speed 50 and 100:
//!   the flange's largest distance from the circle through the three poses, how close it passes
//!   the middle one, and where it ends.
//!
//! `cargo bench --bench motion [stop|stream|irregular|line|arc]` (`stream` includes `irregular`). Figures, not pass/fail; targets are printed
//! next to them. `MOTION_TRACE=1` also prints each line's distance from its segment over time.
#![allow(clippy::unwrap_used, clippy::expect_used, clippy::indexing_slicing)] // a test harness: a panic is a failed check

use std::f64::consts::TAU;

use open_mycobot::sim::measure::{self, Circle, FlangePose};
use open_mycobot::sim::{RobotConfig, VirtualRobot};
use protocol_core::command::{Axis, Direction, JointId, MoveMode, Pose, Reply, Request};
use protocol_core::timing::{HOST_BAUD, wire_time_us};
use protocol_core::units::{Centideg, DeciMm, SpeedPercent};

/// How often the shafts are sampled, in us.
const SAMPLE_US: u64 = 500;

fn speed(percent: u8) -> SpeedPercent {
    SpeedPercent::new(percent).expect("1..=100")
}

fn booted() -> VirtualRobot {
    let mut robot = VirtualRobot::new(RobotConfig::default());
    robot.run_for(1_500_000);
    robot
}

fn ask(robot: &mut VirtualRobot, request: Request) -> Reply {
    robot
        .ask(&request)
        .unwrap_or_else(|e| panic!("{request:?}: {e:?}"))
}

fn wait_until_still(robot: &mut VirtualRobot) {
    for _ in 0..400 {
        robot.run_for(50_000);
        if ask(robot, Request::IsMoving) == Reply::Byte(0) {
            return;
        }
    }
    panic!("still moving");
}

fn move_to(robot: &mut VirtualRobot, degrees: [f64; 6]) {
    let angles = degrees.map(|d| Centideg((d * 100.0).round() as i16));
    ask(
        robot,
        Request::SendAngles {
            angles,
            speed: speed(100),
        },
    );
    wait_until_still(robot);
    robot.run_for(300_000);
}

/// Writes `request` on the Basic's USB without waiting; returns when its last byte has
/// arrived at the Basic, in us.
fn send(robot: &mut VirtualRobot, request: &Request) -> u64 {
    let bytes = request.to_frame().to_bytes();
    robot.host_write(&bytes);
    robot.now_us() + wire_time_us(bytes.len() as u32, HOST_BAUD)
}

fn drain(robot: &mut VirtualRobot) {
    let mut sink = Vec::new();
    robot.host_read(&mut sink);
}

/// Travel of joint 1 after a request sent at full motion, and the time until it rests.
struct Stop {
    speed_deg_per_s: f64,
    travel_deg: f64,
    rest_s: f64,
}

fn measure_stop(robot: &mut VirtualRobot, request: Request, joint: usize) -> Stop {
    let before = robot.shaft_angles_deg()[joint];
    robot.run_for(10_000);
    let speed_deg_per_s = (robot.shaft_angles_deg()[joint] - before) * 100.0;
    let last_byte_us = send(robot, &request);
    robot.run_until(last_byte_us);
    let at_request = robot.shaft_angles_deg()[joint];
    let sign = speed_deg_per_s.signum();
    let (mut furthest, mut previous) = (0.0f64, at_request);
    let mut last_motion_us = last_byte_us;
    for _ in 0..(1_500_000 / SAMPLE_US) {
        robot.run_for(SAMPLE_US);
        let a = robot.shaft_angles_deg()[joint];
        furthest = furthest.max((a - at_request) * sign);
        if (a - previous).abs() > 1e-6 {
            last_motion_us = robot.now_us();
        }
        previous = a;
    }
    drain(robot);
    Stop {
        speed_deg_per_s: speed_deg_per_s.abs(),
        travel_deg: furthest,
        rest_s: (last_motion_us - last_byte_us) as f64 / 1e6,
    }
}

fn stops() {
    println!("== stopping (target: <= 3 deg after the request's last byte, at rest <= 0.15 s)");
    for percent in [30, 60, 100] {
        let mut robot = booted();
        move_to(&mut robot, [-160.0, 0.0, 0.0, 0.0, 0.0, 0.0]);
        let joint = JointId::new(1).expect("joint 1");
        ask(
            &mut robot,
            Request::JogAngle {
                joint,
                direction: Direction::Positive,
                speed: speed(percent),
            },
        );
        robot.run_for(1_200_000);
        let s = measure_stop(&mut robot, Request::Stop, 0);
        println!(
            "stop  from jog {percent:>3} %: {:6.1} deg/s -> travel {:5.2} deg, at rest after {:.3} s",
            s.speed_deg_per_s, s.travel_deg, s.rest_s
        );
    }
    let mut robot = booted();
    move_to(&mut robot, [-120.0, 0.0, 0.0, 0.0, 0.0, 0.0]);
    let angles = [120.0, 0.0, 0.0, 0.0, 0.0, 0.0].map(|d: f64| Centideg((d * 100.0) as i16));
    ask(
        &mut robot,
        Request::SendAngles {
            angles,
            speed: speed(100),
        },
    );
    robot.run_for(1_000_000);
    let s = measure_stop(&mut robot, Request::Pause, 0);
    println!(
        "pause during send_angles 100 %: {:6.1} deg/s -> travel {:5.2} deg, at rest after {:.3} s",
        s.speed_deg_per_s, s.travel_deg, s.rest_s
    );
}

/// The sine the stream follows: joint angles in degrees at `t_s` seconds.
fn sine(t_s: f64) -> [f64; 6] {
    const AMPLITUDE: [f64; 6] = [40.0, 25.0, 30.0, 35.0, 30.0, 45.0];
    const CENTRE: [f64; 6] = [0.0, -20.0, -40.0, 10.0, 0.0, 0.0];
    const HZ: f64 = 0.4;
    std::array::from_fn(|j| CENTRE[j] + AMPLITUDE[j] * (TAU * HZ * t_s + j as f64 * 0.7).sin())
}

fn to_wire(degrees: &[f64; 6]) -> [Centideg; 6] {
    degrees.map(|d| Centideg((d * 100.0).round() as i16))
}

/// When each sample of a stream arrives (us after the stream's start) and the time on the
/// sine it carries (s): what the client sent and when it reached the robot.
type Schedule = Vec<(u64, f64)>;

/// A regular stream: one sample every `period_us` for `duration_us`, each carrying the sine at
/// the moment it is sent.
fn regular(period_us: u64, duration_us: u64) -> Schedule {
    (0..duration_us / period_us)
        .map(|k| (k * period_us, (k * period_us) as f64 / 1e6))
        .collect()
}

/// How well the arm followed a stream: the lag of the sine that fits the shafts best (after a
/// 1 s start), the residual after removing it (RMS and worst, deg), and at the end how far
/// the arm rests from the last target (deg) and whether it still moves.
struct Following {
    lag_ms: i64,
    rms_deg: f64,
    worst_deg: f64,
    /// The same against what arrived: the samples' targets at their arrival times, joined by
    /// straight lines, with the lag that fits them best. A stall's missing samples are no
    /// error of the arm here.
    sent: (i64, f64, f64),
    end_deg: f64,
    moving: bool,
}

/// Feeds the firmware the stream `schedule` (send_angles at 100 %, fresh mode) and measures
/// how the shafts followed the sine its samples carry.
fn follow(schedule: &Schedule) -> Following {
    let mut robot = booted();
    move_to(&mut robot, sine(0.0));
    let start_us = robot.now_us();
    let duration_us = schedule.last().map_or(0, |(at, _)| *at) + SAMPLE_US;
    let mut trace: Vec<(f64, [f64; 6])> = Vec::new();
    let mut samples = schedule.iter().peekable();
    let mut last_target = sine(0.0);
    while robot.now_us() < start_us + duration_us {
        while let Some((_, t)) = samples.next_if(|(at, _)| start_us + at <= robot.now_us()) {
            last_target = sine(*t);
            send(
                &mut robot,
                &Request::SendAngles {
                    angles: to_wire(&last_target),
                    speed: speed(100),
                },
            );
        }
        robot.run_for(SAMPLE_US);
        drain(&mut robot);
        let t = (robot.now_us() - start_us) as f64 / 1e6;
        trace.push((t, robot.shaft_angles_deg()));
    }
    let steady: Vec<&(f64, [f64; 6])> = trace.iter().filter(|(t, _)| *t >= 1.0).collect();
    let (lag_ms, rms_deg, worst_deg) = best_fit(&steady, sine);
    let arrived: Vec<(f64, [f64; 6])> = schedule
        .iter()
        .map(|(at, t)| (*at as f64 / 1e6, sine(*t)))
        .collect();
    let sent = best_fit(&steady, |t| along(&arrived, t));
    // The end: the stream stops; the arm must come to rest at the last target.
    robot.run_for(1_500_000);
    drain(&mut robot);
    let end = robot.shaft_angles_deg();
    let end_deg = (0..6)
        .map(|j| (end[j] - last_target[j]).abs())
        .fold(0.0, f64::max);
    Following {
        lag_ms,
        rms_deg,
        worst_deg,
        sent,
        end_deg,
        moving: ask(&mut robot, Request::IsMoving) == Reply::Byte(1),
    }
}

/// The lag (ms, 0..400) of `reference` that fits `trace` best, and the residual after removing
/// it: RMS and worst, deg.
fn best_fit(trace: &[&(f64, [f64; 6])], reference: impl Fn(f64) -> [f64; 6]) -> (i64, f64, f64) {
    let fit = |lag_s: f64| -> (f64, f64) {
        let (mut sum, mut worst, mut n) = (0.0, 0.0f64, 0.0);
        for (t, q) in trace {
            let want = reference(t - lag_s);
            for j in 0..6 {
                let e = q[j] - want[j];
                sum += e * e;
                worst = worst.max(e.abs());
                n += 1.0;
            }
        }
        ((sum / n).sqrt(), worst)
    };
    let lag_ms = best_lag_ms(400, fit);
    let (rms, worst) = fit(f64::from(lag_ms) / 1e3);
    (i64::from(lag_ms), rms, worst)
}

/// The lag, whole ms up to `max_ms`, whose `fit` (RMS, worst) has the smallest RMS.
fn best_lag_ms(max_ms: u32, fit: impl Fn(f64) -> (f64, f64)) -> u32 {
    (0..=max_ms)
        .min_by(|&a, &b| {
            fit(f64::from(a) / 1e3)
                .0
                .total_cmp(&fit(f64::from(b) / 1e3).0)
        })
        .unwrap_or(0)
}

/// Where the straight lines through `points` (time in s, angles, in time order) are at `t`.
fn along(points: &[(f64, [f64; 6])], t: f64) -> [f64; 6] {
    let after = points.partition_point(|(at, _)| *at <= t);
    match (after.checked_sub(1).map(|i| &points[i]), points.get(after)) {
        (Some((ta, a)), Some((tb, b))) if tb > ta => {
            let f = (t - ta) / (tb - ta);
            std::array::from_fn(|j| a[j] + f * (b[j] - a[j]))
        }
        (Some((_, a)), _) => *a,
        (None, Some((_, b))) => *b,
        (None, None) => [0.0; 6],
    }
}

fn streams() {
    println!(
        "== streams, fresh mode, send_angles of a 0.4 Hz sine (target: lag <= 50 ms beyond one \
         period, residual <= 0.5 deg, clean end)"
    );
    for rate_hz in [20u64, 50, 100] {
        let period_us = 1_000_000 / rate_hz;
        let f = follow(&regular(period_us, 8_000_000));
        println!(
            "{rate_hz:>3} Hz: lag {} ms = period + {} ms, residual {:.3} deg RMS, worst {:.2} deg; \
             end {:.2} deg from the last target, {}",
            f.lag_ms,
            f.lag_ms - (period_us / 1000) as i64,
            f.rms_deg,
            f.worst_deg,
            f.end_deg,
            if f.moving { "still moving" } else { "at rest" }
        );
    }
}

/// A small deterministic random source (xorshift64*), so every run feeds the same streams.
struct Dice(u64);

impl Dice {
    /// A number in 0..1.
    fn roll(&mut self) -> f64 {
        self.0 ^= self.0 >> 12;
        self.0 ^= self.0 << 25;
        self.0 ^= self.0 >> 27;
        (self.0.wrapping_mul(0x2545_F491_4F6C_DD1D) >> 11) as f64 / (1u64 << 53) as f64
    }
}

/// Irregular 50 Hz streams, as a busy host sends them: each sample carries the sine at the time
/// it was due, but arrives late by up to the jitter, or never (dropped), or after a stall
/// together with the samples held up behind it (a burst); or the client samples late, and the
/// sample carries the sine at the time it was sent.
fn irregular_streams() {
    println!(
        "== irregular 50 Hz streams (residual against the sine the samples carry; each case's \
         target beside it, and a clean end)"
    );
    const PERIOD_US: u64 = 20_000;
    const DURATION_US: u64 = 8_000_000;
    let mut cases: Vec<(String, Schedule)> = Vec::new();
    for jitter_ms in [0u64, 5, 10, 20] {
        let mut dice = Dice(0x9E37_79B9_7F4A_7C15 ^ jitter_ms);
        let mut schedule: Schedule = regular(PERIOD_US, DURATION_US)
            .into_iter()
            .map(|(at, t)| (at + (dice.roll() * (jitter_ms * 1000) as f64) as u64, t))
            .collect();
        schedule.sort_by_key(|(at, _)| *at);
        cases.push((format!("jitter 0..{jitter_ms} ms late"), schedule));
    }
    for jitter_ms in [10u64, 20] {
        // A client that samples when it gets to send (pymycobot in a loop, a ROS node on a busy
        // PC): a late sample carries the sine at its late time, not at the time it was due.
        let mut dice = Dice(0x94D0_49BB_1331_11EB ^ jitter_ms);
        let mut schedule: Schedule = regular(PERIOD_US, DURATION_US)
            .into_iter()
            .map(|(at, _)| {
                let sent = at + (dice.roll() * (jitter_ms * 1000) as f64) as u64;
                (sent, sent as f64 / 1e6)
            })
            .collect();
        schedule.sort_by_key(|(at, _)| *at);
        cases.push((format!("sampled 0..{jitter_ms} ms late"), schedule));
    }
    for percent in [10u32, 30] {
        let mut dice = Dice(0xD1B5_4A32_D192_ED03 ^ u64::from(percent));
        let schedule = regular(PERIOD_US, DURATION_US)
            .into_iter()
            .filter(|_| dice.roll() * 100.0 >= f64::from(percent))
            .collect();
        cases.push((format!("{percent} % dropped"), schedule));
    }
    for stall_ms in [60u64, 100, 200] {
        // Every second the client stalls; the samples due meanwhile go out back to back when
        // it wakes (the line carries one every 1.3 ms).
        let schedule = regular(PERIOD_US, DURATION_US)
            .into_iter()
            .map(|(at, t)| {
                let into = at % 1_000_000;
                let stall_end = 500_000 + stall_ms * 1000;
                (
                    if (500_000..stall_end).contains(&into) {
                        at - into + stall_end
                    } else {
                        at
                    },
                    t,
                )
            })
            .collect();
        cases.push((
            format!("burst after a {stall_ms} ms stall, every 1 s"),
            schedule,
        ));
    }
    // The targets (RMS, worst; deg): issue 30's for jitter up to 10 ms, 10 ms of late sampling
    // and 10 % dropped (no worse than 10 ms of jitter); 0.5 and 2 for the rest, but for the
    // longer stalls, whose holes no follower can fill.
    let mut jitter_10 = (f64::MAX, f64::MAX);
    for (name, schedule) in &cases {
        let f = follow(schedule);
        let target = match name.as_str() {
            "10 % dropped" => Some(jitter_10),
            n if n.contains("0..20 ms") || n.contains("30 %") || n.contains("60 ms") => {
                Some((0.5, 2.0))
            }
            n if n.contains("stall") => None,
            _ => Some((0.10, 0.40)),
        };
        if name == "jitter 0..10 ms late" {
            jitter_10 = (f.rms_deg, f.worst_deg);
        }
        let verdict = match target {
            Some((rms, worst)) => format!(
                "target <= {rms:.3} RMS, <= {worst:.2} worst: {}",
                if f.rms_deg <= rms && f.worst_deg <= worst && !f.moving {
                    "met"
                } else {
                    "MISSED"
                }
            ),
            None => "no target (a hole)".to_string(),
        };
        println!(
            "{name:<40} lag {:>3} ms, residual {:.3} deg RMS, worst {:.2} deg [{verdict}]; \
             against what arrived: lag {:>3} ms, {:.3} deg RMS, worst {:.2} deg; end {:.2} deg, {}",
            f.lag_ms,
            f.rms_deg,
            f.worst_deg,
            f.sent.0,
            f.sent.1,
            f.sent.2,
            f.end_deg,
            if f.moving { "still moving" } else { "at rest" }
        );
    }
}

/// A send_coords stream: the flange drawing a 40 mm circle at 0.25 Hz, 50 samples a second.
fn coords_stream() {
    let mut robot = booted();
    move_to(&mut robot, [10.0, -30.0, -50.0, -10.0, 10.0, 20.0]);
    let Reply::Coords(centre) = ask(&mut robot, Request::GetCoords) else {
        panic!("get_coords")
    };
    let circle = |t: f64| -> [f64; 3] {
        let a = TAU * 0.25 * t;
        [
            f64::from(centre.x.0) / 10.0 + 40.0 * (a.cos() - 1.0),
            f64::from(centre.y.0) / 10.0 + 40.0 * a.sin(),
            f64::from(centre.z.0) / 10.0,
        ]
    };
    let period_us = 20_000;
    let start_us = robot.now_us();
    let mut next_sample_us = start_us;
    let mut trace: Vec<(f64, [f64; 3])> = Vec::new();
    while robot.now_us() < start_us + 6_000_000 {
        if robot.now_us() >= next_sample_us {
            let p = circle((robot.now_us() - start_us) as f64 / 1e6);
            let pose = Pose {
                x: DeciMm((p[0] * 10.0).round() as i16),
                y: DeciMm((p[1] * 10.0).round() as i16),
                z: DeciMm((p[2] * 10.0).round() as i16),
                ..centre
            };
            send(
                &mut robot,
                &Request::SendCoords {
                    pose,
                    speed: speed(100),
                    mode: Some(MoveMode::Joint),
                },
            );
            next_sample_us += period_us;
        }
        robot.run_for(SAMPLE_US);
        drain(&mut robot);
        let t = (robot.now_us() - start_us) as f64 / 1e6;
        trace.push((t, measure::flange(&robot.shaft_angles_deg()).position_mm));
    }
    let steady: Vec<&(f64, [f64; 3])> = trace.iter().filter(|(t, _)| *t >= 1.0).collect();
    let fit = |lag_s: f64| -> (f64, f64) {
        let (mut sum, mut worst) = (0.0, 0.0f64);
        for (t, p) in &steady {
            let e = measure::distance_to_segment_mm(p, &circle(t - lag_s), &circle(t - lag_s));
            sum += e * e;
            worst = worst.max(e);
        }
        ((sum / steady.len() as f64).sqrt(), worst)
    };
    let lag_ms = best_lag_ms(200, fit);
    let (rms, worst) = fit(f64::from(lag_ms) / 1e3);
    println!(
        " 50 Hz send_coords (40 mm circle at 0.25 Hz): lag {lag_ms} ms = period + {} ms, \
         residual {rms:.3} mm RMS, worst {worst:.2} mm",
        lag_ms as i64 - 20
    );
}

/// The flange's largest distance from the segment `a`..`b` and turn from `orientation` over
/// `trace`.
fn deviation(trace: &[FlangePose], a: &[f64; 3], b: &[f64; 3], start: &FlangePose) -> (f64, f64) {
    let distance = trace
        .iter()
        .map(|p| measure::distance_to_segment_mm(&p.position_mm, a, b))
        .fold(0.0, f64::max);
    let turn = trace
        .iter()
        .map(|p| measure::angle_between_deg(&p.rotation, &start.rotation))
        .fold(0.0, f64::max);
    (distance, turn)
}

fn lines() {
    println!("== straight lines at speed 50 (target: within 0.2 mm of the segment)");
    let start_angles = [10.0, -30.0, -50.0, -10.0, 10.0, 20.0];
    let offsets_mm = [
        [-60.0, 80.0, -40.0],
        [0.0, 0.0, -100.0],
        [-100.0, 0.0, 0.0],
        [-40.0, -40.0, 20.0],
    ];
    for d in offsets_mm {
        let mut robot = booted();
        move_to(&mut robot, start_angles);
        let start = measure::flange(&robot.shaft_angles_deg());
        let Reply::Coords(from) = ask(&mut robot, Request::GetCoords) else {
            panic!("get_coords")
        };
        let to = Pose {
            x: DeciMm(from.x.0 + (d[0] * 10.0) as i16),
            y: DeciMm(from.y.0 + (d[1] * 10.0) as i16),
            z: DeciMm(from.z.0 + (d[2] * 10.0) as i16),
            ..from
        };
        let target = [to.x.0, to.y.0, to.z.0].map(|v| f64::from(v) / 10.0);
        let reply = robot.ask(&Request::SendCoords {
            pose: to,
            speed: speed(50),
            mode: Some(MoveMode::Linear),
        });
        if reply != Ok(Reply::Ack) {
            println!("line to {to:?} refused: {reply:?}");
            continue;
        }
        let mut trace = Vec::new();
        for _ in 0..(10_000_000 / SAMPLE_US) {
            robot.run_for(SAMPLE_US);
            trace.push(measure::flange(&robot.shaft_angles_deg()));
            if !robot.atom().is_moving() {
                break;
            }
        }
        if std::env::var_os("MOTION_TRACE").is_some() {
            for (i, p) in trace.iter().enumerate().step_by(10) {
                let dd =
                    measure::distance_to_segment_mm(&p.position_mm, &start.position_mm, &target);
                println!(
                    "  t {:5.3} s  off {dd:.3} mm",
                    i as f64 * SAMPLE_US as f64 / 1e6
                );
            }
        }
        let (distance, turn) = deviation(&trace, &start.position_mm, &target, &start);
        let end = trace.last().map_or(start.position_mm, |p| p.position_mm);
        let miss = measure::distance_to_segment_mm(&end, &target, &target);
        println!(
            "line ({:>5.0}, {:>5.0}, {:>5.0}) mm: off the segment by at most {distance:.3} mm, \
             turned {turn:.3} deg, ends {miss:.2} mm from the target",
            d[0], d[1], d[2]
        );
    }
    for (axis, name) in [(Axis::X, "x"), (Axis::Z, "z")] {
        let mut robot = booted();
        move_to(&mut robot, start_angles);
        let start = measure::flange(&robot.shaft_angles_deg());
        ask(
            &mut robot,
            Request::JogCoord {
                axis,
                direction: Direction::Negative,
                speed: speed(50),
            },
        );
        let mut trace = Vec::new();
        for _ in 0..(1_000_000 / SAMPLE_US) {
            robot.run_for(SAMPLE_US);
            trace.push(measure::flange(&robot.shaft_angles_deg()));
        }
        ask(&mut robot, Request::Stop);
        wait_until_still(&mut robot);
        trace.push(measure::flange(&robot.shaft_angles_deg()));
        let i = if axis == Axis::X { 0 } else { 2 };
        let mut far = start.position_mm;
        far[i] -= 1_000.0;
        let (distance, turn) = deviation(&trace, &start.position_mm, &far, &start);
        let travelled = start.position_mm[i] - trace.last().map_or(0.0, |p| p.position_mm[i]);
        println!(
            "jog_coord -{name} 1 s: travelled {travelled:.1} mm, off the axis by at most \
             {distance:.3} mm, turned {turn:.3} deg"
        );
    }
}

/// Where the flange goes, sampled every [`SAMPLE_US`] until the arm stops (at most 10 s).
fn trace_until_still(robot: &mut VirtualRobot) -> Vec<FlangePose> {
    let mut trace = vec![measure::flange(&robot.shaft_angles_deg())];
    for _ in 0..(10_000_000 / SAMPLE_US) {
        robot.run_for(SAMPLE_US);
        trace.push(measure::flange(&robot.shaft_angles_deg()));
        if trace.len() > 40 && !robot.atom().is_moving() {
            break;
        }
    }
    trace
}

fn arcs() {
    println!(
        "== circular arcs, move_c_coords from here (target: within 0.15 mm of the circle, as lines)"
    );
    let start_angles = [10.0, -30.0, -50.0, -10.0, 10.0, 20.0];
    // (middle, end) as offsets from the start, mm.
    let arcs: [([f64; 3], [f64; 3]); 3] = [
        ([-40.0, 40.0, 10.0], [0.0, 80.0, 0.0]),
        ([-30.0, 0.0, 30.0], [-60.0, 0.0, 0.0]),
        ([-20.0, -20.0, 0.0], [-60.0, 10.0, 20.0]),
    ];
    let shifted = |p: &Pose, d: &[f64; 3]| Pose {
        x: DeciMm(p.x.0 + (d[0] * 10.0) as i16),
        y: DeciMm(p.y.0 + (d[1] * 10.0) as i16),
        z: DeciMm(p.z.0 + (d[2] * 10.0) as i16),
        ..*p
    };
    let mm = |p: &Pose| [p.x.0, p.y.0, p.z.0].map(|v| f64::from(v) / 10.0);
    for percent in [50, 100] {
        for (middle, end) in &arcs {
            let mut robot = booted();
            move_to(&mut robot, start_angles);
            let start = measure::flange(&robot.shaft_angles_deg());
            let Reply::Coords(from) = ask(&mut robot, Request::GetCoords) else {
                panic!("get_coords")
            };
            let (middle, end) = (shifted(&from, middle), shifted(&from, end));
            let Some(circle) = Circle::through(&start.position_mm, &mm(&middle), &mm(&end)) else {
                println!("no circle through {from:?} {middle:?} {end:?}");
                continue;
            };
            ask(
                &mut robot,
                Request::SetSpeed {
                    speed: speed(percent),
                },
            );
            let reply = robot.ask(&Request::MoveCCoordsFromHere { middle, end });
            if reply != Ok(Reply::Ack) {
                println!("arc through {middle:?} to {end:?} refused: {reply:?}");
                continue;
            }
            let trace = trace_until_still(&mut robot);
            let off = trace
                .iter()
                .map(|p| circle.distance_mm(&p.position_mm))
                .fold(0.0, f64::max);
            let passes = trace
                .iter()
                .map(|p| measure::distance_mm(&p.position_mm, &mm(&middle)))
                .fold(f64::MAX, f64::min);
            let ends = trace.last().map_or(f64::NAN, |p| {
                measure::distance_mm(&p.position_mm, &mm(&end))
            });
            println!(
                "arc r {:5.1} mm at {percent:>3} %: off the circle by at most {off:.3} mm, passes \
                 {passes:.3} mm from the middle, ends {ends:.3} mm from the end",
                circle.radius_mm
            );
        }
    }
}

fn main() {
    let only = std::env::args().nth(1).filter(|a| !a.starts_with('-'));
    let want = |name: &str| only.as_deref().is_none_or(|o| o == name);
    if want("stop") {
        stops();
    }
    if want("stream") {
        streams();
        coords_stream();
    }
    if want("stream") || only.as_deref() == Some("irregular") {
        irregular_streams();
    }
    if want("line") {
        lines();
    }
    if want("arc") {
        arcs();
    }
}
