//! A board restarts in the middle of a session (brown-out, reset button, firmware update): the
//! arm must not jump, and the host must be answered again once the board is back.
#![allow(clippy::unwrap_used, clippy::expect_used, clippy::indexing_slicing)] // a test harness: a panic is a failed check

mod sim_support;

use protocol_core::command::{Reply, Request};
use sim_support::*;

const POSE_DEG: [f64; 6] = [25.0, -35.0, 45.0, -20.0, 30.0, -60.0];

fn arm_at_pose() -> open_mycobot::sim::VirtualRobot {
    let mut robot = arm();
    ack(
        &mut robot,
        Request::SendAngles {
            angles: degrees(POSE_DEG),
            speed: speed(100),
        },
    );
    wait_until_stopped(&mut robot);
    robot
}

#[test]
fn the_atom_restarts_without_moving_the_arm_and_answers_again() {
    let mut robot = arm_at_pose();
    let before = robot.measured_angles();
    robot.reset_atom();
    robot.run_for(CLIENT_OPEN_DELAY_US);
    assert_eq!(
        robot.measured_angles(),
        before,
        "the arm moved while the Atom restarted"
    );
    assert_angles_near(
        get_angles(&mut robot),
        before,
        "get_angles after the restart",
    );
    assert_eq!(ask(&mut robot, Request::IsPowerOn), Reply::Byte(1));
    let target = degrees([0.0; 6]);
    ack(
        &mut robot,
        Request::SendAngles {
            angles: target,
            speed: speed(100),
        },
    );
    wait_until_stopped(&mut robot);
    assert_angles_near(robot.measured_angles(), target, "moves after the restart");
}

#[test]
fn the_basic_restarts_and_the_host_gets_answers_again() {
    let mut robot = arm_at_pose();
    let before = robot.measured_angles();
    robot.reset_basic();
    robot.run_for(CLIENT_OPEN_DELAY_US);
    assert_eq!(
        robot.measured_angles(),
        before,
        "the arm moved while the Basic restarted"
    );
    assert_angles_near(
        get_angles(&mut robot),
        before,
        "get_angles after the restart",
    );
    assert_eq!(ask(&mut robot, Request::IsPowerOn), Reply::Byte(1));
}
