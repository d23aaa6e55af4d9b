//! The arm against an obstacle or a push (`--obstacle J:DEG`, `VirtualRobot::push_joint`): the
//! simulated servos react as STS servos do, and the firmware sees it only on the bus.
#![allow(clippy::unwrap_used, clippy::expect_used, clippy::indexing_slicing)] // a test harness: a panic is a failed check

mod sim_support;

use open_mycobot::sim::contact::Obstacle;
use protocol_core::command::{JointId, Request};
use protocol_core::units::Centideg;
use sim_support::*;

#[test]
fn a_joint_stops_at_an_obstacle_and_the_firmware_reads_where_it_stands() {
    let mut robot = arm();
    assert!(robot.add_obstacle("2:30".parse::<Obstacle>().unwrap()));
    ack(
        &mut robot,
        Request::SendAngle {
            joint: JointId::new(2).unwrap(),
            angle: Centideg(6_000),
            speed: speed(50),
        },
    );
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
    ack(
        &mut robot,
        Request::SendAngle {
            joint: JointId::new(2).unwrap(),
            angle: Centideg(-1_000),
            speed: speed(50),
        },
    );
    wait_until_stopped(&mut robot);
    assert!((get_angles(&mut robot)[1].0 + 1_000).abs() <= ANGLE_TOLERANCE);
}

#[test]
fn a_push_on_a_held_joint_gives_way_a_little_and_a_strong_one_moves_it() {
    let mut robot = arm();
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
