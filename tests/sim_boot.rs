//! Start-up: whatever the boards do while they boot, a move the host was told `01` for runs to
//! its end. A host may well speak in the Basic's first second: a script started with the arm,
//! or a client that reconnects to a Basic that has just restarted.
#![allow(clippy::unwrap_used, clippy::expect_used, clippy::indexing_slicing)] // a test harness: a panic is a failed check

mod sim_support;

use open_mycobot::sim::{RobotConfig, VirtualRobot};
use protocol_core::command::Request;
use protocol_core::units::Centideg;
use sim_support::*;

/// Starts the tester's move, joint 1 to 90 degrees at half speed (answered `01`); returns its
/// target.
fn start_move(robot: &mut VirtualRobot) -> [Centideg; 6] {
    let target = degrees([90.0, 0.0, 0.0, 0.0, 0.0, 0.0]);
    ack(
        robot,
        Request::SendAngles {
            angles: target,
            speed: speed(50),
        },
    );
    target
}

#[test]
fn a_move_sent_in_the_first_second_after_switch_on_runs_to_its_end() {
    for sent_at_us in [50_000, 300_000, 700_000, 950_000] {
        let mut robot = VirtualRobot::new(RobotConfig::default());
        robot.run_for(sent_at_us);
        let target = start_move(&mut robot);
        wait_until_stopped(&mut robot);
        assert_angles_near(
            robot.measured_angles(),
            target,
            &format!("sent {sent_at_us} us after switch-on"),
        );
    }
}

#[test]
fn an_arm_that_starts_powered_off_is_powered_on_by_the_basic() {
    let mut robot = booted(RobotConfig {
        atom: firmware_atom::AtomConfig {
            powered_at_boot: false,
            ..firmware_atom::AtomConfig::default()
        },
        ..RobotConfig::default()
    });
    assert_eq!(
        ask(&mut robot, Request::IsPowerOn),
        protocol_core::command::Reply::Byte(1)
    );
    assert!(robot.servos().all(|s| s.torque_enabled()));
}

/// The Atom's half of the rule. Power on (0x10) still reaches a running Atom: from an older
/// Basic firmware (the vendor's sends it at every boot) or from the user's button A. An Atom
/// that is already on lets the move go on.
#[test]
fn a_power_on_to_an_arm_that_is_on_does_not_cut_a_move_short() {
    let mut robot = arm();
    let target = start_move(&mut robot);
    robot.run_for(300_000);
    ack(&mut robot, Request::PowerOn);
    wait_until_stopped(&mut robot);
    assert_angles_near(robot.measured_angles(), target, "after a power on mid-move");
}
