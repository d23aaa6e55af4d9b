//! Choosing the dialect on the arm (`docs/protocol.md`, "Dialects"): the 0xC5 command both
//! dialects accept, button C, the flash that keeps the choice, and what a switch does to the
//! clients already connected (nothing moves; a frame begun is read whole in the dialect it
//! began in).
#![allow(clippy::unwrap_used, clippy::expect_used, clippy::indexing_slicing)] // a test harness: a panic is a failed check

mod sim_support;

use firmware_basic::dialect::SWITCH_HOLD_US;
use open_mycobot::sim::{HostLink, RobotConfig, VirtualRobot};
use protocol_core::Frame;
use protocol_core::dialect::Dialect;
use sim_support::*;

fn frame(cmd: u8, data: &[u8]) -> Frame {
    Frame::new(cmd, data).unwrap()
}

/// Sends `request` on `link` and returns the frame that comes back within 500 ms, if any.
fn send_on(robot: &mut VirtualRobot, link: HostLink, request: &Frame) -> Option<Frame> {
    robot.link_write(link, &request.to_bytes());
    robot.await_frame(link, 500_000)
}

fn dialect_now(robot: &VirtualRobot) -> Dialect {
    robot.basic().unwrap().status().dialect
}

#[test]
fn the_dialect_command_answers_in_both_and_switches_both_ways() {
    let mut robot = arm();
    let usb = HostLink::Basic;
    assert_eq!(
        send_on(&mut robot, usb, &frame(0xC5, &[])),
        Some(frame(0xC5, &[1]))
    );
    // pymycobot: power on answers.
    assert_eq!(
        send_on(&mut robot, usb, &frame(0x10, &[])),
        Some(frame(0x10, &[1]))
    );
    assert_eq!(
        send_on(&mut robot, usb, &frame(0xC5, &[2])),
        Some(frame(0xC5, &[2]))
    );
    assert_eq!(dialect_now(&robot), Dialect::Seed);
    // Seed: power on does not answer, a question does.
    assert_eq!(send_on(&mut robot, usb, &frame(0x10, &[])), None);
    assert_eq!(
        send_on(&mut robot, usb, &frame(0x12, &[])),
        Some(frame(0x12, &[1]))
    );
    assert_eq!(
        send_on(&mut robot, usb, &frame(0xC5, &[])),
        Some(frame(0xC5, &[2]))
    );
    // A dialect that does not exist changes nothing (and, a refusal, is not answered in seed).
    assert_eq!(send_on(&mut robot, usb, &frame(0xC5, &[3])), None);
    assert_eq!(dialect_now(&robot), Dialect::Seed);
    assert_eq!(
        send_on(&mut robot, usb, &frame(0xC5, &[1])),
        Some(frame(0xC5, &[1]))
    );
    assert_eq!(
        send_on(&mut robot, usb, &frame(0xC5, &[3])),
        Some(frame(0xC5, &[0]))
    );
    assert_eq!(
        send_on(&mut robot, usb, &frame(0x10, &[])),
        Some(frame(0x10, &[1]))
    );
}

#[test]
fn the_choice_survives_a_restart_of_the_basic() {
    let mut robot = arm();
    assert_eq!(
        send_on(&mut robot, HostLink::Basic, &frame(0xC5, &[2])),
        Some(frame(0xC5, &[2]))
    );
    // Written once the bus is quiet.
    robot.run_for(200_000);
    robot.reset_basic();
    robot.run_for(CLIENT_OPEN_DELAY_US);
    assert_eq!(dialect_now(&robot), Dialect::Seed);
    assert_eq!(
        send_on(&mut robot, HostLink::Basic, &frame(0x10, &[])),
        None
    );
    // The setting at start (the virtual robot's --dialect) wins over the stored one, and is
    // stored in its turn.
    let mut config = RobotConfig::default();
    config.basic.dialect = Some(Dialect::Pymycobot);
    let flash = robot.basic_flash_mut().unwrap().clone();
    let mut robot = VirtualRobot::new(config).with_basic_flash(flash);
    robot.run_for(CLIENT_OPEN_DELAY_US);
    assert_eq!(dialect_now(&robot), Dialect::Pymycobot);
    robot.reset_basic();
    robot.run_for(CLIENT_OPEN_DELAY_US);
    assert_eq!(dialect_now(&robot), Dialect::Pymycobot);
}

#[test]
fn holding_button_c_two_seconds_switches_once() {
    let mut robot = arm();
    robot.basic_io_mut().unwrap().buttons.c = true;
    robot.run_for(SWITCH_HOLD_US - 200_000);
    assert_eq!(dialect_now(&robot), Dialect::Pymycobot, "not yet");
    robot.run_for(400_000);
    assert_eq!(dialect_now(&robot), Dialect::Seed);
    robot.run_for(5 * SWITCH_HOLD_US);
    assert_eq!(dialect_now(&robot), Dialect::Seed, "once per press");
    robot.basic_io_mut().unwrap().buttons.c = false;
    robot.run_for(100_000);
    assert_eq!(
        send_on(&mut robot, HostLink::Basic, &frame(0x10, &[])),
        None
    );
}

#[test]
fn a_switch_never_moves_the_arm_and_a_frame_begun_ends_in_its_dialect() {
    let mut robot = arm();
    let usb = HostLink::Basic;
    let net = robot.connect().unwrap();
    robot.run_for(100_000);
    ack(
        &mut robot,
        protocol_core::command::Request::SendAngles {
            angles: degrees([10.0, -10.0, 0.0, 0.0, 0.0, 0.0]),
            speed: speed(80),
        },
    );
    wait_until_stopped(&mut robot);
    let still = robot.atom().present_angles();
    // The network client has sent half of pymycobot's send_angle(1, 30, 50)...
    let request = frame(0x21, &[1, 0x0B, 0xB8, 50]).to_bytes();
    robot.link_write(net, &request[..4]);
    robot.run_for(2_000);
    // ...when the USB client switches to seed (a few milliseconds, within the network link's
    // 20 ms frame gap).
    assert_eq!(
        send_on(&mut robot, usb, &frame(0xC5, &[2])),
        Some(frame(0xC5, &[2]))
    );
    assert_angles_near(
        robot.atom().present_angles(),
        still,
        "a switch moves nothing",
    );
    // The rest of the frame: read as it began, pymycobot's (joint 1, answered).
    robot.link_write(net, &request[4..]);
    assert_eq!(robot.await_frame(net, 500_000), Some(frame(0x21, &[1])));
    wait_until_stopped(&mut robot);
    let moved = robot.atom().present_angles();
    assert!((moved[0].0 - 3000).abs() <= ANGLE_TOLERANCE, "{moved:?}");
    assert!(
        (moved[1].0 - still[1].0).abs() <= ANGLE_TOLERANCE,
        "J2 kept"
    );
    // The next frame on that link is seed: joint byte 1 is the second joint, unanswered.
    assert_eq!(
        send_on(&mut robot, net, &frame(0x21, &[1, 0x0B, 0xB8, 50])),
        None
    );
    wait_until_stopped(&mut robot);
    let now = robot.atom().present_angles();
    assert!((now[1].0 - 3000).abs() <= ANGLE_TOLERANCE, "{now:?}");
}
