//! Jogging a joint that already stands outside a limit the user just tightened: the jog towards
//! that limit must not drag the joint backwards to it (the user pressed "+" and saw it go "-").
#![allow(clippy::unwrap_used, clippy::expect_used, clippy::indexing_slicing)] // a test harness: a panic is a failed check

mod sim_support;

use open_mycobot::sim::{HostLink, VirtualRobot};
use protocol_core::command::{Direction, JointId, Reply, Request};
use protocol_core::units::{Centideg, Decideg};
use sim_support::*;

fn joint1() -> JointId {
    JointId::new(1).expect("joint 1")
}

/// Joint 1 at 30 deg with its maximum then tightened to 20 deg.
fn beyond_max() -> VirtualRobot {
    let mut robot = arm();
    ack(
        &mut robot,
        Request::SendAngles {
            angles: degrees([30.0, 0.0, 0.0, 0.0, 0.0, 0.0]),
            speed: speed(100),
        },
    );
    wait_until_stopped(&mut robot);
    ack(
        &mut robot,
        Request::SetJointMax {
            joint: joint1(),
            limit: Decideg(200),
        },
    );
    robot
}

fn jog(robot: &mut VirtualRobot, direction: Direction) {
    // Refused (a 0 byte) or acknowledged: what matters here is how the joint moves.
    let _answer = robot.ask_on(
        HostLink::Basic,
        &Request::JogAngle {
            joint: joint1(),
            direction,
            speed: speed(50),
        },
    );
    robot.run_for(500_000);
    ack(robot, Request::Stop);
    wait_until_stopped(robot);
}

#[test]
fn jog_outwards_beyond_a_tightened_limit_does_not_move_back() {
    let mut robot = beyond_max();
    let before = robot.measured_angles()[0];
    jog(&mut robot, Direction::Positive);
    let after = robot.measured_angles()[0];
    assert!(
        after.0 >= before.0 - ANGLE_TOLERANCE,
        "a positive jog moved joint 1 negatively: {before:?} -> {after:?}"
    );
    assert_ne!(
        ask(&mut robot, Request::GetErrorInfo),
        Reply::Byte(0),
        "the refused jog reports the joint limit"
    );
}

#[test]
fn jog_back_inside_a_tightened_limit_still_works() {
    let mut robot = beyond_max();
    jog(&mut robot, Direction::Negative);
    assert!(
        robot.measured_angles()[0] < Centideg(2_000),
        "the jog back inside did not move joint 1: {:?}",
        robot.measured_angles()[0]
    );
}
