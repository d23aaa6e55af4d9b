//! Servos fail while the user works: one stops answering mid-move, one stalls, one overheats,
//! one sends corrupt answers. The arm keeps answering the host, the healthy joints keep
//! moving, and the status commands say which servo is in trouble.
#![allow(clippy::unwrap_used, clippy::expect_used, clippy::indexing_slicing)] // a test harness: a panic is a failed check

mod sim_support;

use open_mycobot::sim::{AskError, Faults, VirtualRobot};
use protocol_core::command::{Reply, ReplyError, Request, ServoErrorCode};
use protocol_core::servo::fault;
use sim_support::*;

const TARGET_DEG: [f64; 6] = [20.0, -30.0, 40.0, -50.0, 60.0, -70.0];

fn inject(robot: &mut VirtualRobot, id: u8, faults: Faults) {
    robot.servo_mut(id).expect("servo").set_faults(faults);
}

fn servo_errors(robot: &mut VirtualRobot) -> [u8; 7] {
    match ask(robot, Request::ReadNextError) {
        Reply::ServoErrors(e) => e,
        other => panic!("read_next_error answered {other:?}"),
    }
}

fn servo_status(robot: &mut VirtualRobot) -> [u8; 6] {
    match ask(robot, Request::GetServoStatus) {
        Reply::Bytes6(s) => s,
        other => panic!("get_servo_status answered {other:?}"),
    }
}

fn joint_arrived(robot: &VirtualRobot, joint: usize) -> bool {
    let target = degrees(TARGET_DEG);
    (robot.measured_angles()[joint].0 - target[joint].0).abs() <= ANGLE_TOLERANCE
}

fn start_move(robot: &mut VirtualRobot) {
    ack(
        robot,
        Request::SendAngles {
            angles: degrees(TARGET_DEG),
            speed: speed(40),
        },
    );
}

/// A joint whose servo stops answering is nowhere the Atom knows of: the arm stops rather than
/// finish the move by guesswork, 0x07 names the joint, "is moving" does not claim it is still,
/// and the host keeps getting answers that say which servo is gone.
#[test]
fn a_servo_that_stops_answering_mid_move_stops_the_arm_and_is_reported() {
    let mut robot = arm();
    start_move(&mut robot);
    robot.run_for(300_000);
    inject(&mut robot, 3, Faults::NO_ANSWER);
    robot.run_for(500_000);
    let stopped = robot.measured_angles();
    robot.run_for(500_000);
    let healthy = [0, 1, 3, 4, 5];
    for j in healthy {
        assert_eq!(
            robot.measured_angles()[j],
            stopped[j],
            "joint {} still moving after the stop",
            j + 1
        );
        assert!(
            !joint_arrived(&robot, j),
            "joint {} finished the move",
            j + 1
        );
    }
    assert_eq!(ask(&mut robot, Request::GetErrorInfo), Reply::Byte(23));
    assert_eq!(
        ask(&mut robot, Request::IsMoving),
        Reply::Byte(1),
        "joint 3 is not known to be still"
    );
    // The host still gets answers, and they say which servo is gone.
    let reported = get_angles(&mut robot);
    for j in healthy {
        assert!((reported[j].0 - stopped[j].0).abs() <= ANGLE_TOLERANCE);
    }
    assert_eq!(
        ask(&mut robot, Request::IsServoEnabled { servo: servo(3) }),
        Reply::ServoEnabled {
            servo: servo(3),
            enabled: false
        }
    );
    assert_eq!(
        ask(&mut robot, Request::IsServoEnabled { servo: servo(2) }),
        Reply::ServoEnabled {
            servo: servo(2),
            enabled: true
        }
    );
    assert_eq!(
        ask(&mut robot, Request::AreAllServosEnabled),
        Reply::Byte(0)
    );
    let status = servo_status(&mut robot);
    assert_eq!(
        [status[0], status[1], status[3], status[4], status[5]],
        [0; 5]
    );
    assert_ne!(
        status[2], 0,
        "get_servo_status calls a silent servo healthy"
    );
    let errors = servo_errors(&mut robot);
    assert_eq!(errors[2], ServoErrorCode::NoAnswer.code(), "{errors:?}");
    assert_eq!(
        [errors[0], errors[1], errors[3], errors[4], errors[5]],
        [0; 5]
    );
    // No new motion while joint 3 is unknown: refused (00).
    let refused = robot.ask(&Request::SendAngles {
        angles: degrees([0.0; 6]),
        speed: speed(40),
    });
    assert_eq!(refused, Err(AskError::BadReply(ReplyError::BadValue(0))));

    // Plugged back in: the servo is seen again, the arm comes to rest and moves again.
    inject(&mut robot, 3, Faults::NONE);
    robot.run_for(200_000);
    assert_eq!(
        ask(&mut robot, Request::AreAllServosEnabled),
        Reply::Byte(1)
    );
    wait_until_stopped(&mut robot);
    start_move(&mut robot);
    wait_until_stopped(&mut robot);
    assert_angles_near(robot.measured_angles(), degrees(TARGET_DEG), "moved again");
}

#[test]
fn a_silent_gripper_does_not_stop_the_arm() {
    let mut robot = arm();
    inject(&mut robot, 7, Faults::NO_ANSWER);
    start_move(&mut robot);
    wait_until_stopped(&mut robot);
    assert_angles_near(robot.measured_angles(), degrees(TARGET_DEG), "arm");
    let errors = servo_errors(&mut robot);
    assert_eq!(errors[6], ServoErrorCode::NoAnswer.code(), "{errors:?}");
}

#[test]
fn a_stalled_joint_reports_overload_while_the_others_arrive() {
    let mut robot = arm();
    inject(&mut robot, 2, Faults::STALL);
    start_move(&mut robot);
    let others = [0, 2, 3, 4, 5];
    assert!(robot.run_until_true(MOTION_TIMEOUT_US, |r| {
        others.iter().all(|&j| joint_arrived(r, j))
    }));
    assert!(!joint_arrived(&robot, 1), "a stalled joint cannot arrive");
    let status = servo_status(&mut robot);
    assert_eq!(status[1] & fault::OVERLOAD, fault::OVERLOAD, "{status:?}");
    let errors = servo_errors(&mut robot);
    assert!(
        matches!(
            ServoErrorCode::from_code(errors[1]),
            Some(ServoErrorCode::Fault(bits)) if bits & fault::OVERLOAD != 0
        ),
        "{errors:?}"
    );
}

#[test]
fn an_overheating_servo_shows_its_temperature_and_fault_bit() {
    let mut robot = arm();
    inject(&mut robot, 5, Faults::OVERHEAT);
    robot.run_for(200_000);
    let Reply::Bytes6(temps) = ask(&mut robot, Request::GetServoTemps) else {
        panic!("no temperatures");
    };
    assert_eq!(temps[4], open_mycobot::sim::servo::OVERHEAT_C);
    assert!(temps.iter().enumerate().all(|(j, &t)| j == 4 || t < 50));
    let status = servo_status(&mut robot);
    assert_eq!(status[4] & fault::OVERHEAT, fault::OVERHEAT, "{status:?}");
    let errors = servo_errors(&mut robot);
    assert_eq!(
        ServoErrorCode::from_code(errors[4]),
        Some(ServoErrorCode::Fault(fault::OVERHEAT)),
        "{errors:?}"
    );
}

#[test]
fn corrupt_answers_are_reported_and_the_host_is_still_served() {
    let mut robot = arm();
    inject(&mut robot, 6, Faults::BAD_CHECKSUM);
    robot.run_for(200_000);
    for _ in 0..5 {
        get_angles(&mut robot);
    }
    let errors = servo_errors(&mut robot);
    assert_eq!(errors[5], ServoErrorCode::BadAnswer.code(), "{errors:?}");
}

#[test]
fn a_servo_that_browns_out_is_driven_again_by_the_next_move() {
    let mut robot = arm();
    start_move(&mut robot);
    wait_until_stopped(&mut robot);
    // Joint 2 loses power for a moment under load: it comes back with torque off.
    robot.servo_mut(2).expect("servo 2").power_cycle();
    robot.run_for(200_000);
    let target = degrees([0.0, 10.0, 0.0, 0.0, 0.0, 0.0]);
    ack(
        &mut robot,
        Request::SendAngles {
            angles: target,
            speed: speed(100),
        },
    );
    wait_until_stopped(&mut robot);
    assert_angles_near(robot.measured_angles(), target, "after a servo brown-out");
    assert!(robot.servo(2).is_some_and(|s| s.torque_enabled()));
}
