//! A user works the end of the arm: the Atom's LEDs and pins, and the gripper.
#![allow(clippy::unwrap_used, clippy::expect_used, clippy::indexing_slicing)] // a test harness: a panic is a failed check

mod sim_support;

use firmware_atom::{AtomIo, Wiring};
use open_mycobot::sim::VirtualRobot;
use protocol_core::command::{
    AtomPin, GripperModel, GripperSpeed, GripperState, GripperType, GripperValue, PinMode, Reply,
    Request, Rgb,
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

fn gripper_value(robot: &mut VirtualRobot) -> u8 {
    match ask(robot, Request::GetGripperValue { gripper: None }) {
        Reply::Byte(v) => v,
        other => panic!("get_gripper_value answered {other:?}"),
    }
}

/// pymycobot's `gripper_stop()`: set gripper value 0 at speed 0, type 1, force control.
fn gripper_stop() -> Request {
    Request::SetGripperValue {
        value: GripperValue::new(0).expect("0"),
        speed: GripperSpeed::new(0).expect("0"),
        model: GripperModel::TypedTorque(GripperType::new(1).expect("type 1"), true),
    }
}

#[test]
fn gripper_stop_holds_the_gripper_where_it_is() {
    let mut robot = arm();
    gripper_to(&mut robot, 0);
    // Stopped on the way from 0 to 100.
    ack(
        &mut robot,
        Request::SetGripperValue {
            value: GripperValue::new(100).expect("100"),
            speed: GripperSpeed::new(30).expect("30"),
            model: GripperModel::Default,
        },
    );
    robot.run_for(400_000);
    ack(&mut robot, gripper_stop());
    robot.run_for(300_000);
    let stopped = gripper_value(&mut robot);
    assert!((10..90).contains(&stopped), "stopped at {stopped}");
    robot.run_for(2_500_000);
    assert_eq!(gripper_value(&mut robot), stopped, "it crept on");
    assert_eq!(ask(&mut robot, Request::IsGripperMoving), Reply::Byte(0));
    // Stopped at rest: it stays (it used to creep towards 0).
    gripper_to(&mut robot, 66);
    let before = robot.servo(7).expect("gripper").present_position();
    let value = gripper_value(&mut robot);
    ack(&mut robot, gripper_stop());
    robot.run_for(2_500_000);
    assert_eq!(gripper_value(&mut robot), value);
    let after = robot.servo(7).expect("gripper").present_position();
    assert!(after.abs_diff(before) <= 1, "{before} -> {after}");
}

fn release_gripper(robot: &mut VirtualRobot) {
    ack(
        robot,
        Request::SetGripperState {
            state: GripperState::Release,
            speed: GripperSpeed::new(50).expect("50"),
            model: GripperModel::Default,
        },
    );
    robot.run_for(200_000);
    assert!(!robot.servo(7).expect("gripper").torque_enabled());
}

#[test]
fn the_first_gripper_command_after_a_release_moves_it() {
    let mut robot = arm();
    gripper_to(&mut robot, 80);
    release_gripper(&mut robot);
    ack(
        &mut robot,
        Request::SetGripperValue {
            value: GripperValue::new(40).expect("40"),
            speed: GripperSpeed::new(80).expect("80"),
            model: GripperModel::Default,
        },
    );
    settle_gripper(&mut robot);
    assert!(robot.servo(7).expect("gripper").torque_enabled());
    let value = gripper_value(&mut robot);
    assert!(value.abs_diff(40) <= 1, "at {value}");
    // And set gripper state (1 = close) after a release.
    release_gripper(&mut robot);
    ack(
        &mut robot,
        Request::SetGripperState {
            state: GripperState::Close,
            speed: GripperSpeed::new(80).expect("80"),
            model: GripperModel::Default,
        },
    );
    settle_gripper(&mut robot);
    let value = gripper_value(&mut robot);
    assert!(value <= 1, "at {value}");
}

#[test]
fn atom_inputs_read_their_pull_up_and_what_is_wired_to_them() {
    let mut robot = arm();
    let pin = AtomPin::new(22).expect("pin 22");
    let read = |robot: &mut VirtualRobot| match ask(robot, Request::GetDigitalInput { pin }) {
        Reply::PinLevel { pin: 22, high } => high,
        other => panic!("get_digital_input(22) answered {other:?}"),
    };
    let set_mode = |robot: &mut VirtualRobot, mode| ack(robot, Request::SetPinMode { pin, mode });
    set_mode(&mut robot, PinMode::InputPullUp);
    assert!(
        read(&mut robot),
        "an open input with its pull-up reads high"
    );
    // A button to ground closes.
    assert!(robot.atom_io_mut().set_input(22, false));
    assert!(!read(&mut robot));
    assert!(robot.atom_io_mut().set_wiring(22, Wiring::Open));
    set_mode(&mut robot, PinMode::Input);
    assert!(!read(&mut robot), "floating, no pull: low");
    assert!(robot.atom_io_mut().set_wiring(22, Wiring::PullUp));
    assert!(read(&mut robot), "an external pull-up");
    assert!(robot.atom_io_mut().set_wiring(22, Wiring::PullDown));
    set_mode(&mut robot, PinMode::InputPullUp);
    assert!(
        !read(&mut robot),
        "an external pull-down beats the internal pull-up"
    );
}

#[test]
fn move_round_turns_the_dispenser_servo_once_and_four_pieces_zero_stops_it() {
    use firmware_atom::dispenser::{STOP_PULSE_US, TURN_PULSE_US, TURN_US};
    let mut robot = arm();
    let pulse = |robot: &VirtualRobot| robot.atom_io().accessory_servo_pulse_us;
    assert_eq!(pulse(&robot), None, "no pulses before the first command");
    ack(&mut robot, Request::MoveRound);
    let started = robot.now_us();
    assert_eq!(pulse(&robot), Some(TURN_PULSE_US), "turning clockwise");
    robot.run_until(started + TURN_US - 20_000);
    assert_eq!(pulse(&robot), Some(TURN_PULSE_US), "still turning");
    robot.run_until(started + TURN_US + 20_000);
    assert_eq!(
        pulse(&robot),
        Some(STOP_PULSE_US),
        "one revolution, then still"
    );
    // Zero ends a turn at once.
    ack(&mut robot, Request::MoveRound);
    robot.run_for(100_000);
    assert_eq!(pulse(&robot), Some(TURN_PULSE_US));
    assert_eq!(ask(&mut robot, Request::SetFourPiecesZero), Reply::Byte(1));
    assert_eq!(pulse(&robot), Some(STOP_PULSE_US));
    robot.run_for(TURN_US);
    assert_eq!(pulse(&robot), Some(STOP_PULSE_US));
}
