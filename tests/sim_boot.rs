//! Start-up: whatever the boards do while they boot, a move the host was told `01` for runs to
//! its end. A host may well speak in the Basic's first second: a script started with the arm,
//! or a client that reconnects to a Basic that has just restarted.

mod sim_support;

use open_mycobot::sim::{RobotConfig, VirtualRobot};
use protocol_core::command::Request;
use sim_support::*;

/// The tester's move: joint 1 to 90 degrees at half speed.
const TARGET_DEG: [f64; 6] = [90.0, 0.0, 0.0, 0.0, 0.0, 0.0];

#[test]
fn a_move_sent_in_the_first_second_after_switch_on_runs_to_its_end() {
    for sent_at_us in [50_000, 300_000, 700_000, 950_000] {
        let mut robot = VirtualRobot::new(RobotConfig::default());
        robot.run_for(sent_at_us);
        let target = degrees(TARGET_DEG);
        ack(
            &mut robot,
            Request::SendAngles {
                angles: target,
                speed: speed(50),
            },
        );
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
/// Basic firmware (the vendor's sends it at every boot) or from the user's button A. The Atom
/// answers it by holding the arm where it is, so the move stops halfway.
#[test]
#[ignore = "needs the Atom change: power on (0x10) while powered keeps a running motion"]
fn a_power_on_to_an_arm_that_is_on_does_not_cut_a_move_short() {
    let mut robot = arm();
    let target = degrees(TARGET_DEG);
    ack(
        &mut robot,
        Request::SendAngles {
            angles: target,
            speed: speed(50),
        },
    );
    robot.run_for(300_000);
    ack(&mut robot, Request::PowerOn);
    wait_until_stopped(&mut robot);
    assert_angles_near(robot.measured_angles(), target, "after a power on mid-move");
}
