//! The arm against an obstacle or a push (`--obstacle J:DEG`, `VirtualRobot::push_joint`): the
//! simulated servos react as STS servos do, and the firmware sees it only on the bus.
#![allow(clippy::unwrap_used, clippy::expect_used, clippy::indexing_slicing)] // a test harness: a panic is a failed check

mod sim_support;

use open_mycobot::sim::VirtualRobot;
use open_mycobot::sim::contact::Obstacle;
use protocol_core::Frame;
use protocol_core::command::{JointId, MoveMode, Reply, Request};
use protocol_core::units::Centideg;
use sim_support::*;

/// Switches collision protection on or off (0x74) and checks it was taken.
fn protection(robot: &mut VirtualRobot, on: bool) {
    let set = Frame::new(0x74, &[u8::from(on)]).unwrap();
    let answer = robot.transact(&set).expect("an answer");
    assert_eq!(answer.data(), &[1]);
}

/// Joint 2 to `centideg` at speed 50.
fn joint_2_to(centideg: i16) -> Request {
    Request::SendAngle {
        joint: JointId::new(2).unwrap(),
        angle: Centideg(centideg),
        speed: speed(50),
    }
}

/// The arm with an obstacle in joint 2's way at 30 degrees.
fn blocked_at_30() -> VirtualRobot {
    let mut robot = arm();
    assert!(robot.add_obstacle("2:30".parse::<Obstacle>().unwrap()));
    robot
}

#[test]
fn a_move_into_an_obstacle_is_stopped_as_a_collision_until_cleared() {
    let mut robot = blocked_at_30();
    let to_60 = joint_2_to(6_000);
    ack(&mut robot, to_60.clone());
    assert!(robot.run_until_true(3_000_000, |r| r.atom().collision().is_some()));
    let collision = robot.atom().collision().unwrap();
    assert_eq!((collision.joint, collision.code()), (1, 16));
    wait_until_stopped(&mut robot);
    assert_eq!(ask(&mut robot, Request::GetErrorInfo), Reply::Byte(16));
    // Stopped at the obstacle, pressing no more.
    let at = get_angles(&mut robot)[1].0;
    assert!((at - 3_000).abs() <= 20, "{at}");
    let servo = robot.servo(2).unwrap();
    eprintln!(
        "goal {} present {} setpoint {} collision {:?}",
        servo.goal_position(),
        servo.present_position(),
        servo.setpoint_steps(),
        robot.atom().collision()
    );
    assert!(!servo.blocked(), "the servo let go: it presses no more");
    // Further motion is refused with the code until cleared.
    let refused = robot.transact(&to_60.to_frame()).expect("an answer");
    assert_eq!(refused.data(), &[0], "refused");
    assert_eq!(ask(&mut robot, Request::GetErrorInfo), Reply::Byte(16));
    ack(&mut robot, Request::ClearErrorInfo);
    assert_eq!(ask(&mut robot, Request::GetErrorInfo), Reply::Byte(0));
    ack(&mut robot, joint_2_to(-1_000));
    wait_until_stopped(&mut robot);
    assert!((get_angles(&mut robot)[1].0 + 1_000).abs() <= ANGLE_TOLERANCE);
    assert_eq!(robot.atom().collision(), None);
}

#[test]
fn a_push_on_a_holding_arm_is_a_collision_too() {
    let mut robot = arm();
    robot.run_for(500_000);
    assert!(robot.push_joint(3, 800));
    assert!(robot.run_until_true(1_000_000, |r| r.atom().collision().is_some()));
    assert_eq!(robot.atom().collision().unwrap().code(), 18);
    assert_eq!(ask(&mut robot, Request::GetErrorInfo), Reply::Byte(18));
}

#[test]
fn with_protection_off_the_arm_presses_on_as_before() {
    let mut robot = blocked_at_30();
    protection(&mut robot, false);
    ack(&mut robot, joint_2_to(6_000));
    robot.run_for(1_000_000);
    assert_eq!(robot.atom().collision(), None);
    assert!(robot.servo(2).unwrap().blocked(), "still pressing");
    assert_eq!(ask(&mut robot, Request::GetErrorInfo), Reply::Byte(0));
}

#[test]
fn a_joint_stops_at_an_obstacle_and_the_firmware_reads_where_it_stands() {
    let mut robot = blocked_at_30();
    protection(&mut robot, false);
    ack(&mut robot, joint_2_to(6_000));
    robot.run_for(3_000_000);
    let measured = robot.measured_angles()[1];
    assert!(
        (measured.0 - 3_000).abs() <= 10,
        "held at the obstacle: {measured:?}"
    );
    assert!(
        (get_angles(&mut robot)[1].0 - 3_000).abs() <= 10,
        "get_angles reports where it stands"
    );
    // Away from the obstacle it moves as before.
    ack(&mut robot, joint_2_to(-1_000));
    wait_until_stopped(&mut robot);
    assert!((get_angles(&mut robot)[1].0 + 1_000).abs() <= ANGLE_TOLERANCE);
}

#[test]
fn a_push_on_a_held_joint_gives_way_a_little_and_a_strong_one_moves_it() {
    let mut robot = arm();
    protection(&mut robot, false);
    assert!(robot.push_joint(3, 300));
    robot.run_for(200_000);
    let gave = robot.measured_angles()[2].0;
    assert!((30..=200).contains(&gave), "gives way a little: {gave}");
    assert!(robot.push_joint(3, 1_500));
    robot.run_for(200_000);
    assert!(robot.measured_angles()[2].0 > 1_000, "driven by the push");
    assert!(robot.push_joint(3, 0));
    wait_until_stopped(&mut robot);
    let back = robot.measured_angles()[2].0;
    assert!(
        back.abs() <= ANGLE_TOLERANCE,
        "let go, it returns to its goal: {back}"
    );
    assert!(!robot.push_joint(7, 100), "no joint 7");
}

/// The data of the Atom's answer to `cmd` with `data`.
fn answer(robot: &mut VirtualRobot, cmd: u8, data: &[u8]) -> Vec<u8> {
    let frame = Frame::new(cmd, data).unwrap();
    robot.transact(&frame).expect("an answer").data().to_vec()
}

#[test]
fn settings_are_taken_in_range_refused_outside_and_survive_a_restart() {
    let mut robot = arm();
    assert_eq!(answer(&mut robot, 0xFD, &[]), [1], "on by default");
    assert_eq!(answer(&mut robot, 0x76, &[]), [100; 6]);
    for bad in [&[0u8, 100][..], &[7, 100], &[1, 49], &[1, 251]] {
        assert_eq!(answer(&mut robot, 0x75, bad), [0], "{bad:?}");
    }
    assert_eq!(answer(&mut robot, 0x74, &[2]), [0]);
    assert_eq!(answer(&mut robot, 0x76, &[]), [100; 6], "nothing changed");
    assert_eq!(answer(&mut robot, 0x75, &[3, 250]), [1]);
    assert_eq!(answer(&mut robot, 0x75, &[6, 50]), [1]);
    assert_eq!(answer(&mut robot, 0x74, &[0]), [1]);
    // Written to flash once the arm has been quiet for 20 ms (docs/protocol.md).
    robot.run_for(50_000);
    robot.reset_atom();
    robot.run_for(1_000_000);
    assert_eq!(answer(&mut robot, 0xFD, &[]), [0]);
    assert_eq!(answer(&mut robot, 0x76, &[]), [100, 100, 250, 100, 100, 50]);
}

/// Runs until the Atom reports a collision, at most `timeout_us`; its error code.
fn collision_code_within(robot: &mut VirtualRobot, timeout_us: u64) -> Option<u8> {
    robot.run_until_true(timeout_us, |r| r.atom().collision().is_some());
    robot.atom().collision().map(|c| c.code())
}

#[test]
fn a_line_into_an_obstacle_is_a_cartesian_collision() {
    let mut robot = arm();
    let start = [0, -2_000, -3_000, -1_000, 0, 0].map(Centideg);
    ack(
        &mut robot,
        Request::SendAngles {
            angles: start,
            speed: speed(100),
        },
    );
    wait_until_stopped(&mut robot);
    assert!(robot.add_obstacle("3:-40".parse::<Obstacle>().unwrap()));
    let through = [0, 8_000, -3_000, -1_000, 0, 0].map(Centideg);
    let Reply::Coords(pose) = ask(&mut robot, Request::AnglesToCoords { angles: through }) else {
        panic!("angles to coords")
    };
    let line = Request::SendCoords {
        pose,
        speed: speed(50),
        mode: Some(MoveMode::Linear),
    };
    ack(&mut robot, line);
    assert_eq!(collision_code_within(&mut robot, 5_000_000), Some(17));
    assert_eq!(robot.atom().collision().unwrap().joint, 2, "joint 3");
    wait_until_stopped(&mut robot);
    assert_eq!(ask(&mut robot, Request::GetErrorInfo), Reply::Byte(17));
}

#[test]
fn a_stream_into_an_obstacle_is_stopped_while_it_streams() {
    let mut robot = blocked_at_30();
    // A ROS-like 50 Hz stream ramping joint 2 to 60 deg over 2 s.
    for k in 1..=100i16 {
        let angles = [0, k * 60, 0, 0, 0, 0].map(Centideg);
        let sample = Request::SendAngles {
            angles,
            speed: speed(100),
        };
        robot.stream_sample(&sample, 20_000);
        if robot.atom().collision().is_some() {
            break;
        }
    }
    let collision = robot.atom().collision().expect("felt during the stream");
    assert_eq!((collision.joint, collision.code()), (1, 16));
    let at = robot.collisions()[0].0;
    assert!(
        at < 1_500_000_000 + 2_000_000_000,
        "before the stream ended: {at} ns"
    );
}

#[test]
fn a_firm_push_against_a_moving_joint_is_felt_before_the_move_ends() {
    let mut robot = arm();
    let to_60 = Request::SendAngle {
        joint: JointId::new(1).unwrap(),
        angle: Centideg(6_000),
        speed: speed(30),
    };
    ack(&mut robot, to_60);
    robot.run_for(200_000);
    assert!(robot.atom().is_moving());
    assert!(robot.push_joint(1, -700));
    assert_eq!(collision_code_within(&mut robot, 100_000), Some(16));
    assert!(
        robot.measured_angles()[0].0 < 5_000,
        "long before it arrived"
    );
}

#[test]
fn power_on_ends_a_collision_and_its_error() {
    let mut robot = blocked_at_30();
    ack(&mut robot, joint_2_to(6_000));
    assert_eq!(collision_code_within(&mut robot, 3_000_000), Some(16));
    wait_until_stopped(&mut robot);
    ack(&mut robot, Request::PowerOn);
    assert_eq!(ask(&mut robot, Request::GetErrorInfo), Reply::Byte(0));
    ack(&mut robot, joint_2_to(0));
}
