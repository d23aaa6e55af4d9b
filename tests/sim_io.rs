//! A user works the end of the arm: the Atom's LEDs and pins, and the gripper.
#![allow(clippy::unwrap_used, clippy::expect_used, clippy::indexing_slicing)] // a test harness: a panic is a failed check

mod sim_support;

use firmware_atom::AtomIo;
use open_mycobot::sim::VirtualRobot;
use protocol_core::command::{
    AtomPin, GripperModel, GripperSpeed, GripperValue, PinMode, Reply, Request, Rgb,
};
use sim_support::*;

fn gripper_to(robot: &mut VirtualRobot, percent: u8) {
    ack(
        robot,
        Request::SetGripperValue {
            value: GripperValue::new(percent).expect("0..=100"),
            speed: GripperSpeed::new(80).expect("0..=100"),
            model: GripperModel::Default,
        },
    );
    let arrived = robot.run_until_true(MOTION_TIMEOUT_US, |r| {
        r.servo(7).is_some_and(|s| !s.is_moving())
    });
    assert!(arrived, "the gripper never stopped");
    robot.run_for(100_000);
}

#[test]
fn the_gripper_opens_and_closes_where_told() {
    let mut robot = arm();
    let range = robot.atom().config().gripper;
    gripper_to(&mut robot, 100);
    let open = robot.servo(7).expect("gripper").present_position();
    assert!(
        (i32::from(open) - i32::from(range.open.0)).abs() <= 2,
        "{open}"
    );
    assert!(matches!(
        ask(&mut robot, Request::GetGripperValue { gripper: None }),
        Reply::Byte(v) if v >= 98
    ));
    gripper_to(&mut robot, 0);
    let closed = robot.servo(7).expect("gripper").present_position();
    assert!(
        (i32::from(closed) - i32::from(range.closed.0)).abs() <= 2,
        "{closed}"
    );
    assert!(matches!(
        ask(&mut robot, Request::GetGripperValue { gripper: None }),
        Reply::Byte(v) if v <= 2
    ));
    assert_eq!(ask(&mut robot, Request::IsGripperMoving), Reply::Byte(0));
    // The arm did not move meanwhile.
    assert_eq!(robot.measured_angles(), degrees([0.0; 6]));
}

#[test]
fn the_atom_leds_and_pins_do_what_the_host_says() {
    let mut robot = arm();
    ack(
        &mut robot,
        Request::SetColor {
            rgb: Rgb {
                r: 255,
                g: 0,
                b: 40,
            },
        },
    );
    assert_eq!(robot.atom_io().rgb, (255, 0, 40));

    let pin = AtomPin::output(23).expect("pin 23");
    ack(
        &mut robot,
        Request::SetPinMode {
            pin,
            mode: PinMode::Output,
        },
    );
    ack(&mut robot, Request::SetDigitalOutput { pin, high: true });
    assert_eq!(robot.atom_io_mut().read_pin(23), Some(true));

    let input = AtomPin::new(19).expect("pin 19");
    ack(
        &mut robot,
        Request::SetPinMode {
            pin: input,
            mode: PinMode::Input,
        },
    );
    assert!(robot.atom_io_mut().set_input(19, true));
    assert_eq!(
        ask(&mut robot, Request::GetDigitalInput { pin: input }),
        Reply::PinLevel {
            pin: 19,
            high: true
        }
    );
}

#[test]
fn in_free_mode_the_atom_button_lets_a_hand_pose_the_arm() {
    let mut robot = arm();
    ack(&mut robot, Request::SetFreeMode { on: true });
    assert_eq!(ask(&mut robot, Request::IsFreeMode), Reply::Byte(1));
    robot.atom_io_mut().button = true;
    robot.run_for(50_000);
    assert!(
        robot.servos().take(6).all(|s| !s.torque_enabled()),
        "button held: limp"
    );
    // The user swings joint 1 to about 30 degrees and lets go of the button.
    robot
        .servo_mut(1)
        .expect("servo 1")
        .move_by_hand(2048 + 341);
    robot.run_for(50_000);
    robot.atom_io_mut().button = false;
    robot.run_for(200_000);
    assert!(
        robot.servos().take(6).all(|s| s.torque_enabled()),
        "released: holding"
    );
    let posed = robot.measured_angles();
    assert!((posed[0].0 - 3_000).abs() <= ANGLE_TOLERANCE, "{posed:?}");
    robot.run_for(1_000_000);
    assert_eq!(robot.measured_angles(), posed, "the arm holds the pose");
    assert_angles_near(get_angles(&mut robot), posed, "get_angles");
}
