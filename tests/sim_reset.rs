//! A board restarts in the middle of a session (brown-out, reset button, firmware update): the
//! arm must not jump, and the host must be answered again once the board is back.
#![allow(clippy::unwrap_used, clippy::expect_used, clippy::indexing_slicing)] // a test harness: a panic is a failed check

mod sim_support;

use protocol_core::command::{Reply, Request};
use protocol_core::units::Centideg;
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

/// Runs until no shaft has moved for half a second (at most the motion timeout); returns the
/// angles there. Asks the host link nothing.
fn wait_for_shafts_to_settle(robot: &mut open_mycobot::sim::VirtualRobot) -> [Centideg; 6] {
    let deadline = robot.now_us() + MOTION_TIMEOUT_US;
    let mut last = robot.measured_angles();
    let mut still_since = robot.now_us();
    while robot.now_us() - still_since < 500_000 {
        assert!(robot.now_us() < deadline, "still moving after the timeout");
        robot.run_for(20_000);
        let now = robot.measured_angles();
        if now != last {
            last = now;
            still_since = robot.now_us();
        }
    }
    last
}

#[test]
fn the_basic_restarting_mid_move_neither_stops_nor_moves_the_arm() {
    for restart_after_us in [100_000, 400_000, 900_000] {
        let mut robot = arm();
        let target = degrees([90.0, -30.0, 40.0, 0.0, 20.0, 0.0]);
        ack(
            &mut robot,
            Request::SendAngles {
                angles: target,
                speed: speed(40),
            },
        );
        robot.run_for(restart_after_us);
        robot.reset_basic();
        // The host stays away while the Basic boots (it cannot be heard anyway).
        let settled = wait_for_shafts_to_settle(&mut robot);
        let context = format!("Basic restarted {restart_after_us} us into the move");
        assert_angles_near(settled, target, &context);
        robot.run_for(3_000_000);
        assert_eq!(robot.measured_angles(), settled, "{context}: moved unasked");
        assert_angles_near(get_angles(&mut robot), target, &context);
    }
}
