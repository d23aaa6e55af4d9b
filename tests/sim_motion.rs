//! A user drives the virtual arm through the Basic's USB port, the way pymycobot does, and
//! checks that it moves exactly where told and reports what it does.
#![allow(clippy::unwrap_used, clippy::expect_used, clippy::indexing_slicing)] // a test harness: a panic is a failed check

mod sim_support;

use open_mycobot::sim::{HostLink, RobotConfig, VirtualRobot};
use protocol_core::Frame;
use protocol_core::command::{ErrorCode, JointId, Reply, Request, cmd};
use protocol_core::units::Centideg;
use sim_support::*;

#[test]
fn a_fresh_arm_is_powered_and_reports_zero_angles() {
    let mut robot = arm();
    assert_eq!(ask(&mut robot, Request::IsPowerOn), Reply::Byte(1));
    assert_eq!(get_angles(&mut robot), [Centideg(0); 6]);
    assert_eq!(ask(&mut robot, Request::IsMoving), Reply::Byte(0));
    assert_eq!(
        ask(&mut robot, Request::AreAllServosEnabled),
        Reply::Byte(1)
    );
    assert!(robot.servos().all(|s| s.torque_enabled()));
}

#[test]
fn send_angles_moves_every_joint_exactly_where_told() {
    let mut robot = arm();
    let target = degrees([30.0, -45.0, 60.0, -90.0, 45.0, 120.0]);
    ack(
        &mut robot,
        Request::SendAngles {
            angles: target,
            speed: speed(80),
        },
    );
    robot.run_for(100_000);
    assert_eq!(ask(&mut robot, Request::IsMoving), Reply::Byte(1));
    let halfway = get_angles(&mut robot);
    assert_ne!(halfway, target, "a move takes time");
    wait_until_stopped(&mut robot);
    assert_angles_near(robot.measured_angles(), target, "shafts");
    assert_angles_near(get_angles(&mut robot), target, "get_angles");
}

#[test]
fn send_angle_moves_one_joint_and_leaves_the_others() {
    let mut robot = arm();
    let joint = JointId::new(5).expect("joint 5");
    ack(
        &mut robot,
        Request::SendAngle {
            joint,
            angle: Centideg(-7_250),
            speed: speed(50),
        },
    );
    wait_until_stopped(&mut robot);
    let expected = degrees([0.0, 0.0, 0.0, 0.0, -72.5, 0.0]);
    assert_angles_near(robot.measured_angles(), expected, "shafts");
    assert_angles_near(get_angles(&mut robot), expected, "get_angles");
}

#[test]
fn a_slower_speed_takes_longer() {
    let duration_at = |percent: u8| {
        let mut robot = arm();
        let start = robot.now_us();
        ack(
            &mut robot,
            Request::SendAngles {
                angles: degrees([60.0, 0.0, 0.0, 0.0, 0.0, 0.0]),
                speed: speed(percent),
            },
        );
        let target = degrees([60.0, 0.0, 0.0, 0.0, 0.0, 0.0]);
        assert!(
            robot.run_until_true(MOTION_TIMEOUT_US, |r| {
                (r.measured_angles()[0].0 - target[0].0).abs() <= ANGLE_TOLERANCE
            }),
            "joint 1 never arrived at speed {percent}"
        );
        robot.now_us() - start
    };
    // A short move at full speed is limited by acceleration, so 5x the speed is not 5x faster.
    let fast = duration_at(100);
    let slow = duration_at(20);
    assert!(
        2 * slow > 3 * fast,
        "20 % took {slow} us, 100 % took {fast} us"
    );
}

#[test]
fn stop_halts_a_move_where_it_is() {
    let mut robot = arm();
    let target = degrees([90.0, 0.0, 0.0, 0.0, 0.0, 0.0]);
    ack(
        &mut robot,
        Request::SendAngles {
            angles: target,
            speed: speed(10),
        },
    );
    robot.run_for(500_000);
    ack(&mut robot, Request::Stop);
    robot.run_for(1_000_000);
    let stopped_at = robot.measured_angles();
    assert!(
        stopped_at[0].0 > 0 && stopped_at[0].0 < 9_000 - 500,
        "{stopped_at:?}"
    );
    assert_eq!(ask(&mut robot, Request::IsMoving), Reply::Byte(0));
    robot.run_for(1_000_000);
    assert_eq!(robot.measured_angles(), stopped_at, "stays stopped");
    assert_angles_near(get_angles(&mut robot), stopped_at, "get_angles after stop");
}

#[test]
fn power_off_releases_the_servos_and_power_on_holds_them_again() {
    let mut robot = arm();
    ack(&mut robot, Request::PowerOff);
    robot.run_for(20_000);
    assert!(robot.servos().take(6).all(|s| !s.torque_enabled()));
    assert_eq!(ask(&mut robot, Request::IsPowerOn), Reply::Byte(0));
    ack(&mut robot, Request::PowerOn);
    robot.run_for(20_000);
    assert!(robot.servos().take(6).all(|s| s.torque_enabled()));
    assert_eq!(ask(&mut robot, Request::IsPowerOn), Reply::Byte(1));
}

#[test]
fn a_released_arm_reports_where_a_hand_moved_it() {
    let mut robot = arm();
    ack(&mut robot, Request::ReleaseAllServos { undamped: None });
    robot.run_for(20_000);
    // About 40 degrees on joint 2, -20 on joint 4.
    robot
        .servo_mut(2)
        .expect("servo 2")
        .move_by_hand(2048 + 455);
    robot
        .servo_mut(4)
        .expect("servo 4")
        .move_by_hand(2048 - 228);
    robot.run_for(100_000);
    let reported = get_angles(&mut robot);
    assert_angles_near(reported, robot.measured_angles(), "get_angles in free mode");
    assert!((reported[1].0 - 4_000).abs() < 20, "{reported:?}");
    assert!((reported[3].0 + 2_000).abs() < 20, "{reported:?}");
}

#[test]
fn an_angle_beyond_the_joint_limit_is_refused_and_nothing_moves() {
    let mut robot = arm();
    // Joint 1 to 200 degrees at 50 %: pymycobot would refuse it; a raw client may not.
    let frame = Frame::new(cmd::SEND_ANGLE, &[1, 0x4E, 0x20, 50]).expect("frame");
    let replies = frames_within(&mut robot, &frame, 100_000);
    assert_eq!(replies.len(), 1, "exactly one reply: {replies:?}");
    assert_eq!(replies[0].cmd(), cmd::SEND_ANGLE);
    robot.run_for(1_000_000);
    assert_eq!(robot.measured_angles(), [Centideg(0); 6]);
    assert_eq!(
        ask(&mut robot, Request::GetErrorInfo),
        Reply::Byte(ErrorCode::JointLimit(JointId::new(1).expect("joint 1")).code())
    );
}

#[test]
fn encoders_go_where_told_and_read_back() {
    let mut robot = arm();
    let target = [1800, 2300, 2048, 1500, 2600, 3000].map(steps);
    ack(
        &mut robot,
        Request::SetEncoders {
            encoders: target,
            speed: speed(70),
        },
    );
    wait_until_stopped(&mut robot);
    let Reply::Encoders(read) = ask(&mut robot, Request::GetEncoders) else {
        panic!("get_encoders gave no encoders");
    };
    for (j, (r, t)) in read.iter().zip(target).enumerate() {
        assert!((r.0 - t.0).abs() <= 1, "joint {}: {r:?} vs {t:?}", j + 1);
        let servo = robot.servo(j as u8 + 1).expect("servo");
        assert!((i32::from(servo.present_position()) - i32::from(t.0)).abs() <= 1);
    }
}

#[test]
fn every_request_gets_exactly_one_reply_and_never_its_echo() {
    let mut robot = booted(RobotConfig::default());
    let requests = [
        Request::GetSystemVersion,
        Request::IsPowerOn,
        Request::GetAngles,
        Request::GetEncoders,
        Request::SendAngles {
            angles: degrees([5.0, 5.0, 5.0, 5.0, 5.0, 5.0]),
            speed: speed(50),
        },
        Request::IsMoving,
        Request::GetServoTemps,
        Request::GetServoVoltages,
        Request::GetErrorInfo,
        Request::GetBasicVersion,
        Request::GetCoords,
    ];
    for request in requests {
        let frame = request.to_frame();
        let replies = frames_within(&mut robot, &frame, 50_000);
        assert_eq!(replies.len(), 1, "{request:?} got {replies:?}");
        assert_eq!(replies[0].cmd(), frame.cmd(), "{request:?}");
        assert_ne!(replies[0], frame, "{request:?} was echoed");
        assert_silent_for(&mut robot, HostLink::Basic, 100_000);
    }
}

#[test]
fn requests_sent_back_to_back_are_answered_in_order() {
    let mut robot = arm();
    let mut bytes = Vec::new();
    for request in [Request::GetAngles, Request::IsPowerOn, Request::GetEncoders] {
        bytes.extend_from_slice(&request.to_frame().to_bytes());
    }
    robot.host_write(&bytes);
    robot.run_for(100_000);
    let mut answer = Vec::new();
    robot.host_read(&mut answer);
    let mut cmds = Vec::new();
    protocol_core::FrameDecoder::new().feed(&answer, |f| cmds.push(f.cmd()));
    assert_eq!(
        cmds,
        vec![cmd::GET_ANGLES, cmd::IS_POWER_ON, cmd::GET_ENCODERS]
    );
}

#[test]
fn powering_on_after_hand_posing_holds_the_new_pose() {
    use protocol_core::command::ServoSelect;
    for hold in [
        Request::PowerOn,
        Request::FocusServo {
            servo: ServoSelect::All,
        },
    ] {
        let mut robot = arm();
        ack(&mut robot, Request::ReleaseAllServos { undamped: None });
        robot.run_for(20_000);
        robot
            .servo_mut(3)
            .expect("servo 3")
            .move_by_hand(2048 - 341);
        robot.run_for(100_000);
        let posed = robot.measured_angles();
        ack(&mut robot, hold.clone());
        robot.run_for(1_000_000);
        assert!(
            robot.servos().take(6).all(|s| s.torque_enabled()),
            "{hold:?}"
        );
        assert_eq!(robot.measured_angles(), posed, "{hold:?} moved the arm");
    }
}

#[test]
fn a_jog_whose_client_vanished_stops_by_itself() {
    let mut robot = arm();
    jog_joint_1(&mut robot, 20);
    robot.run_for(500_000);
    let moving_at = robot.measured_angles()[0];
    assert!(moving_at.0 > 0, "the jog started");
    // The client crashed: no stop ever comes. The jog watchdog (2 s, about 60 degrees at this
    // speed) must end it long before the joint limit (168 degrees).
    robot.run_for(5_000_000);
    let stopped_at = robot.measured_angles()[0];
    assert!(
        stopped_at.0 < 12_000,
        "the jog ran on without its client: joint 1 at {stopped_at:?}"
    );
    robot.run_for(1_000_000);
    assert_eq!(robot.measured_angles()[0], stopped_at, "still jogging");
    assert_eq!(ask(&mut robot, Request::IsMoving), Reply::Byte(0));
}

/// Sends joint 1 of a 50 Hz stream ramping at 60 deg/s: its targets `from..to`, each on its
/// 20 ms beat after `start_us`.
fn stream_joint1(robot: &mut VirtualRobot, start_us: u64, from: u64, to: u64) {
    for k in from..to {
        robot.run_until(start_us + k * 20_000);
        ack(
            robot,
            Request::SendAngles {
                angles: degrees([1.2 * k as f64, 0.0, 0.0, 0.0, 0.0, 0.0]),
                speed: speed(100),
            },
        );
    }
}

#[test]
fn a_missing_stream_sample_is_bridged_along_the_stream_not_held() {
    // Target 25 of a 50 Hz stream ramping joint 1 at 60 deg/s never comes. The joint goes on
    // at the stream's speed through the hole (it heads for where the stream's motion puts the
    // missing target) instead of braking past target 24 and then hurrying after target 26.
    let mut robot = arm();
    let start_us = robot.now_us();
    stream_joint1(&mut robot, start_us, 0, 25);
    let mut speeds = Vec::new();
    let hole_us = start_us + 24 * 20_000;
    let mut probe = |robot: &mut VirtualRobot, until_us: u64| {
        let mut before = robot.shaft_angles_deg()[0];
        while robot.now_us() < until_us {
            robot.run_for(5_000);
            let now = robot.shaft_angles_deg()[0];
            if robot.now_us() > hole_us + 10_000 {
                speeds.push((now - before) / 0.005);
            }
            before = now;
        }
    };
    probe(&mut robot, start_us + 26 * 20_000);
    stream_joint1(&mut robot, start_us, 26, 30);
    probe(&mut robot, start_us + 32 * 20_000);
    let slowest = speeds.iter().copied().fold(f64::MAX, f64::min);
    let fastest = speeds.iter().copied().fold(f64::MIN, f64::max);
    assert!(
        slowest > 52.0 && fastest < 68.0,
        "joint 1 at {slowest:.1}..{fastest:.1} deg/s across the missing sample (the stream: 60)"
    );
    wait_until_stopped(&mut robot);
    assert_angles_near(
        robot.measured_angles(),
        degrees([1.2 * 29.0, 0.0, 0.0, 0.0, 0.0, 0.0]),
        "the stream's last target",
    );
}

#[test]
fn a_stream_sampled_late_is_followed_at_its_own_speed() {
    // A client that samples its motion when it gets to send (a loop on a busy PC): each
    // target of a 50 Hz stream ramping joint 1 at 60 deg/s goes out 0 to 10 ms late and
    // carries the ramp at that late time. Played on the stream's steady beats, a target 10 ms
    // late would be 10 ms of the ramp too far on for its beat, and the joint would lurch;
    // played on their arrivals, it keeps the ramp's speed.
    let mut robot = arm();
    let start_us = robot.now_us();
    let mut trace = Vec::new();
    for k in 0..60u64 {
        let late_us = (k.wrapping_mul(0x9E37_79B9_7F4A_7C15) >> 40) % 10_000;
        let sent_us = k * 20_000 + late_us;
        while robot.now_us() + 1_000 <= start_us + sent_us {
            robot.run_for(1_000);
            trace.push((robot.now_us(), robot.shaft_angles_deg()[0]));
        }
        robot.run_until(start_us + sent_us);
        ack(
            &mut robot,
            Request::SendAngles {
                angles: degrees([60.0 * sent_us as f64 / 1e6, 0.0, 0.0, 0.0, 0.0, 0.0]),
                speed: speed(100),
            },
        );
    }
    // The speed over each 10 ms once the joint is under way (the shaft reads in whole encoder
    // steps), until the last target.
    let under_way: Vec<_> = trace
        .iter()
        .filter(|(t, _)| *t >= start_us + 300_000)
        .collect();
    let speeds: Vec<f64> = under_way
        .iter()
        .filter_map(|(t0, a0)| {
            let (t1, a1) = under_way.iter().find(|(t, _)| *t >= t0 + 10_000)?;
            Some((a1 - a0) / ((t1 - t0) as f64 / 1e6))
        })
        .collect();
    let slowest = speeds.iter().copied().fold(f64::MAX, f64::min);
    let fastest = speeds.iter().copied().fold(f64::MIN, f64::max);
    assert!(
        slowest > 45.0 && fastest < 75.0,
        "joint 1 at {slowest:.1}..{fastest:.1} deg/s (the stream: 60)"
    );
}

#[test]
fn a_stream_sample_that_comes_late_is_not_taken_for_the_end_of_the_stream() {
    // A busy host holds its samples up for 120 ms (six periods), then sends the next ones on
    // time: while it waits, the arm goes on to a halt just past the last target instead of
    // turning back to it, and then follows the stream on to its end.
    let mut robot = arm();
    let start_us = robot.now_us();
    stream_joint1(&mut robot, start_us, 0, 30);
    let mut trace = Vec::new();
    while robot.now_us() < start_us + 36 * 20_000 {
        robot.run_for(1_000);
        trace.push(robot.measured_angles()[0].0);
    }
    let mut furthest = i16::MIN;
    for &angle in &trace {
        furthest = furthest.max(angle);
        assert!(
            furthest - angle <= ANGLE_TOLERANCE,
            "joint 1 turned back from {furthest} to {angle} centideg while the stream was late"
        );
    }
    assert!(
        furthest >= degrees([1.2 * 29.0; 6])[0].0,
        "joint 1 stopped short of the last target: {furthest}"
    );
    stream_joint1(&mut robot, start_us, 36, 50);
    wait_until_stopped(&mut robot);
    assert_angles_near(
        robot.measured_angles(),
        degrees([1.2 * 49.0, 0.0, 0.0, 0.0, 0.0, 0.0]),
        "the stream's last target",
    );
}
