//! The shared bus misbehaves: boards that do or do not hear their own echo, noise on the wire,
//! transmissions that collide. Every request still gets exactly one correct reply.
#![allow(clippy::unwrap_used, clippy::expect_used, clippy::indexing_slicing)] // a test harness: a panic is a failed check

mod sim_support;

use open_mycobot::sim::{BusByte, HostLink, RobotConfig, StationId, VirtualRobot};
use protocol_core::command::{JointId, Reply, Request};
use protocol_core::timing::HOST_REPLY_DEADLINE_US;
use protocol_core::units::Centideg;
use protocol_core::{Frame, FrameDecoder};
use sim_support::*;

/// A small deterministic generator, so a failure can be replayed.
struct Lcg(u64);

impl Lcg {
    fn next(&mut self, below: u64) -> u64 {
        self.0 = self
            .0
            .wrapping_mul(6_364_136_223_846_793_005)
            .wrapping_add(1_442_695_040_888_963_407);
        (self.0 >> 33) % below
    }
}

fn user_session(robot: &mut VirtualRobot) {
    assert_eq!(ask(robot, Request::IsPowerOn), Reply::Byte(1));
    let target = degrees([12.0, -24.0, 36.0, -48.0, 60.0, -72.0]);
    ack(
        robot,
        Request::SendAngles {
            angles: target,
            speed: speed(100),
        },
    );
    wait_until_stopped(robot);
    assert_angles_near(robot.measured_angles(), target, "shafts");
    assert_angles_near(get_angles(robot), target, "get_angles");
    assert_silent_for(robot, HostLink::Basic, 100_000);
}

#[test]
fn works_whether_or_not_the_boards_hear_their_own_echo() {
    for (atom_hears_echo, basic_hears_echo) in
        [(true, true), (false, false), (true, false), (false, true)]
    {
        let mut robot = booted(RobotConfig {
            atom_hears_echo,
            basic_hears_echo,
            ..RobotConfig::default()
        });
        user_session(&mut robot);
        assert_eq!(
            robot.bus().collisions(),
            0,
            "echo atom {atom_hears_echo} basic {basic_hears_echo}: stations talked over each other"
        );
    }
}

/// Sends `request`, throws `noise` onto the bus `delay_us` later, and returns every frame the
/// host got: the first one (within pymycobot's reply deadline) and any within 30 ms after it.
fn exchange_with_noise(
    robot: &mut VirtualRobot,
    request: &Frame,
    delay_us: u64,
    noise: &[u8],
) -> Vec<Frame> {
    robot.host_write(&request.to_bytes());
    robot.run_for(delay_us);
    robot.inject_bus_noise(noise);
    let Some(first) = robot.await_frame(HostLink::Basic, HOST_REPLY_DEADLINE_US - delay_us) else {
        return Vec::new();
    };
    let mut frames = vec![first];
    robot.run_for(30_000);
    let mut bytes = Vec::new();
    robot.host_read(&mut bytes);
    FrameDecoder::new().feed(&bytes, |f| frames.push(f));
    frames
}

/// Waits until `station` is `bytes_in` bytes into a host frame on the bus, then puts three
/// bytes of noise over it. Returns the first frame the host gets within the reply deadline.
fn collide_with(
    robot: &mut VirtualRobot,
    station: StationId,
    bytes_in: usize,
    request: &Request,
) -> Option<Frame> {
    robot.bus_mut().set_tracing(true);
    robot.host_write(&request.to_frame().to_bytes());
    let deadline = robot.now_us() + HOST_REPLY_DEADLINE_US;
    let mut sent = Vec::new();
    while sent.len() < bytes_in {
        if robot.now_us() >= deadline {
            return None;
        }
        robot.run_for(5);
        let trace = robot.bus_mut().take_trace();
        for b in trace.iter().filter(|b| b.from == station) {
            // Count from the start of a host frame: FE FE ...
            if sent.len() >= 2 || b.byte == 0xFE {
                sent.push(b.byte);
            } else {
                sent.clear();
            }
        }
    }
    let collisions_before = robot.bus().collisions();
    robot.inject_bus_noise(&[0x00, 0xFE, 0x55]);
    robot.bus_mut().set_tracing(false);
    let found = robot.await_frame(HostLink::Basic, deadline.saturating_sub(robot.now_us()));
    assert!(
        robot.bus().collisions() > collisions_before,
        "the noise missed"
    );
    found
}

#[test]
fn bus_noise_loses_nothing() {
    for seed in [0x5eed, 3 * 7919, 0xC0FFEE] {
        noisy_session(seed);
    }
}

fn noisy_session(seed: u64) {
    let mut robot = arm();
    let mut rng = Lcg(seed);
    let requests = [
        Request::GetAngles,
        Request::IsPowerOn,
        Request::GetEncoders,
        Request::GetServoTemps,
        Request::SendAngles {
            angles: degrees([10.0, 10.0, 10.0, 10.0, 10.0, 10.0]),
            speed: speed(100),
        },
        Request::SendAngles {
            angles: degrees([-10.0, -10.0, -10.0, -10.0, -10.0, -10.0]),
            speed: speed(100),
        },
    ];
    for round in 0..36 {
        let request = &requests[round % requests.len()];
        let frame = request.to_frame();
        // Noise lands anywhere from while the request is still on the USB line to well after
        // the reply.
        let delay_us = rng.next(3_000);
        let noise: Vec<u8> = (0..1 + rng.next(24)).map(|_| rng.next(256) as u8).collect();
        let frames = exchange_with_noise(&mut robot, &frame, delay_us, &noise);
        assert_eq!(
            frames.len(),
            1,
            "seed {seed} round {round}: {request:?} with {noise:02x?} after {delay_us} us got \
             {frames:?}"
        );
        assert_eq!(frames[0].cmd(), frame.cmd(), "round {round}");
        assert!(
            Reply::parse(request.reply_kind(), &frames[0]).is_ok(),
            "round {round}: {:?}",
            frames[0]
        );
    }
    assert!(robot.bus().collisions() > 0, "the noise did hit traffic");
    // The last move was to -10 degrees everywhere, and the arm got there.
    wait_until_stopped(&mut robot);
    assert_angles_near(
        robot.measured_angles(),
        degrees([-10.0; 6]),
        "after the noisy session",
    );
}

#[test]
fn a_request_that_collides_on_the_bus_is_still_answered() {
    let mut robot = arm();
    let basic = robot.basic_station().expect("basic");
    for request in [Request::GetAngles, Request::IsPowerOn, Request::GetEncoders] {
        let reply = collide_with(&mut robot, basic, 2, &request)
            .unwrap_or_else(|| panic!("{request:?} lost after a collision"));
        assert_eq!(reply.cmd(), request.to_frame().cmd());
        assert!(Reply::parse(request.reply_kind(), &reply).is_ok());
        assert_silent_for(&mut robot, HostLink::Basic, 200_000);
    }
}

#[test]
fn a_reply_that_collides_on_the_bus_still_reaches_the_host() {
    let mut robot = arm();
    let atom = robot.atom_station();
    for request in [Request::GetAngles, Request::IsPowerOn, Request::GetEncoders] {
        let reply = collide_with(&mut robot, atom, 3, &request)
            .unwrap_or_else(|| panic!("the reply to {request:?} was lost after a collision"));
        assert_eq!(reply.cmd(), request.to_frame().cmd());
        assert!(Reply::parse(request.reply_kind(), &reply).is_ok());
        assert_silent_for(&mut robot, HostLink::Basic, 200_000);
    }
}

#[test]
fn an_incremental_jog_whose_reply_collides_moves_once_and_is_answered() {
    let mut robot = arm();
    let atom = robot.atom_station();
    let jog = Request::JogIncrementAngle {
        joint: JointId::new(1).expect("joint 1"),
        increment: Centideg(1_000),
        speed: speed(50),
    };
    // The Basic may not repeat an incremental jog, so only the Atom can save this reply.
    let reply = collide_with(&mut robot, atom, 3, &jog);
    // The arm moves 10 degrees, once, whatever happened to the reply.
    assert!(
        robot.run_until_true(MOTION_TIMEOUT_US, |r| r.measured_angles()[0].0
            >= 1_000 - ANGLE_TOLERANCE)
    );
    robot.run_for(2_000_000);
    assert_angles_near(
        robot.measured_angles(),
        degrees([10.0, 0.0, 0.0, 0.0, 0.0, 0.0]),
        "after one jog",
    );
    let reply = reply.expect("the jog's reply was lost: pymycobot would resend it and jog twice");
    assert_eq!(reply.cmd(), jog.to_frame().cmd());
}

/// Quiet time before each burst on the bus that `pick` selects (given the burst's first two
/// bytes), in us. A burst starts when a station starts sending after the wire was silent.
fn quiet_before(
    trace: &[BusByte],
    mut pick: impl FnMut(&BusByte, Option<&BusByte>) -> bool,
) -> Vec<u64> {
    let mut quiet = Vec::new();
    let mut prev_end = u64::MAX;
    for (i, b) in trace.iter().enumerate() {
        let follows_another = i > 0 && trace.get(i - 1).is_some_and(|p| p.from != b.from);
        let starts_burst = prev_end != u64::MAX
            && b.start_ns >= prev_end
            && (b.start_ns > prev_end || follows_another);
        if starts_burst && pick(b, trace.get(i + 1)) {
            quiet.push((b.start_ns - prev_end) / 1_000);
        }
        prev_end = if prev_end == u64::MAX {
            b.end_ns
        } else {
            prev_end.max(b.end_ns)
        };
    }
    quiet
}

#[test]
fn every_station_keeps_the_bus_timing_rules_during_a_busy_session() {
    use protocol_core::timing::{
        ATOM_TRANSACTION_GAP_US, BUS_QUIET_BEFORE_SEND_US, SERVO_TURNAROUND_MAX_US,
    };
    let mut robot = arm();
    robot.bus_mut().set_tracing(true);
    ack(
        &mut robot,
        Request::SendAngles {
            angles: degrees([60.0; 6]),
            speed: speed(15),
        },
    );
    let mut trace = Vec::new();
    for k in 0..40 {
        get_angles(&mut robot);
        robot.run_for(2_000 + k * 137);
        trace.extend(robot.bus_mut().take_trace());
    }
    let basic = robot.basic_station().expect("basic");
    let atom = robot.atom_station();
    // Firmware sees time in whole microseconds: allow 1 us of rounding.
    let atom_gaps = quiet_before(&trace, |b, next| {
        b.from == atom && b.byte == 0xFF && next.is_some_and(|n| n.byte == 0xFF)
    });
    assert!(atom_gaps.len() > 100, "the Atom polls the servos");
    let shortest = atom_gaps.iter().min().copied().unwrap_or(0);
    assert!(
        shortest + 1 >= ATOM_TRANSACTION_GAP_US,
        "Atom gap {shortest} us"
    );
    let basic_gaps = quiet_before(&trace, |b, _| b.from == basic);
    assert!(basic_gaps.len() >= 40, "the Basic forwards every request");
    let shortest = basic_gaps.iter().min().copied().unwrap_or(0);
    assert!(
        shortest + 1 >= BUS_QUIET_BEFORE_SEND_US,
        "Basic quiet {shortest} us"
    );
    let servo_turnarounds = quiet_before(&trace, |b, _| b.from != atom && b.from != basic);
    let longest = servo_turnarounds.iter().max().copied().unwrap_or(0);
    assert!(
        longest <= SERVO_TURNAROUND_MAX_US,
        "servo turnaround {longest} us"
    );
}
