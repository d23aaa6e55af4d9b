//! Every call of the `mycobot-api` crate (the manual's section 2) against the virtual robot, in
//! both dialects: each does what the manual says it does, seen in what the arm does and in
//! what it reads back. The crate speaks to the Basic's USB serial through a port that runs the
//! robot under virtual time while a call waits, so the test is exact and quick.
#![allow(clippy::unwrap_used, clippy::expect_used, clippy::indexing_slicing)] // a test harness: a panic is a failed check

mod sim_support;

use std::cell::RefCell;
use std::collections::VecDeque;
use std::rc::Rc;

use mycobot_api::convert::{angles, deg, limit_deg, mm, pose_to_mm_deg, to_deg};
use mycobot_api::{Error, MyCobot};
use open_mycobot::sim::{RobotConfig, VirtualRobot};
use protocol_core::BytePort;
use protocol_core::command::{
    AtomPin, Axis, AxisValue, Direction, EndType, ErrorCode, GripperSpeed, GripperState,
    GripperValue, JointId, MoveMode, PinMode, PositionTarget, ReferenceFrame, Rgb, ServoId,
    ServoValue,
};
use protocol_core::dialect::Dialect;
use protocol_core::units::{Decideg, SpeedPercent, Steps};
use sim_support::booted;

type Shared = Rc<RefCell<VirtualRobot>>;

/// The Basic's USB serial as the crate sees it: reading when nothing has come runs the robot
/// 100 us on.
struct UsbSerial {
    robot: Shared,
    inbox: VecDeque<u8>,
}

impl BytePort for UsbSerial {
    fn read_byte(&mut self) -> Option<u8> {
        if self.inbox.is_empty() {
            let mut robot = self.robot.borrow_mut();
            robot.run_for(100);
            let mut out = Vec::new();
            robot.host_read(&mut out);
            self.inbox.extend(out);
        }
        self.inbox.pop_front()
    }

    fn write(&mut self, bytes: &[u8]) {
        self.robot.borrow_mut().host_write(bytes);
    }

    fn tx_idle(&self) -> bool {
        true
    }
}

type Arm = MyCobot<UsbSerial, Box<dyn FnMut() -> u64>>;

fn arm(dialect: Dialect) -> (Arm, Shared) {
    let mut config = RobotConfig::default();
    config.basic.dialect = Some(dialect);
    let robot = Rc::new(RefCell::new(booted(config)));
    let clock_robot = Rc::clone(&robot);
    let clock: Box<dyn FnMut() -> u64> = Box::new(move || clock_robot.borrow().now_us());
    let port = UsbSerial {
        robot: Rc::clone(&robot),
        inbox: VecDeque::new(),
    };
    (MyCobot::new(port, clock, dialect), robot)
}

fn run(robot: &Shared, us: u64) {
    robot.borrow_mut().run_for(us);
}

fn j(n: u8) -> JointId {
    JointId::new(n).unwrap()
}

fn s(n: u8) -> ServoId {
    ServoId::new(n).unwrap()
}

fn speed(percent: u8) -> SpeedPercent {
    SpeedPercent::new(percent).unwrap()
}

/// Polls check running (is moving) every 50 ms until the arm is still, as a manual client
/// would; at most 20 s.
fn until_still(arm: &mut Arm, robot: &Shared) {
    for _ in 0..400 {
        if !arm.check_running().unwrap() {
            return;
        }
        run(robot, 50_000);
    }
    panic!("still moving after 20 s");
}

fn angles_deg(arm: &mut Arm) -> [f32; 6] {
    arm.get_angles().unwrap().map(to_deg)
}

fn assert_near(got: &[f32], want: &[f32], within: f32, what: &str) {
    let off = got
        .iter()
        .zip(want)
        .map(|(g, w)| (g - w).abs())
        .fold(0.0, f32::max);
    assert!(off <= within, "{what}: {got:?} against {want:?}");
}

/// The same script in either dialect; `seed` skips the calls the seed dialect has no frame
/// for, and checks that they say so.
fn every_call(dialect: Dialect) {
    let (mut arm, robot) = arm(dialect);
    let what = |s: &str| format!("{s} ({})", dialect.name());

    // 2.2 overall status.
    assert!(arm.is_powered_on().unwrap());
    arm.power_off().unwrap();
    assert!(!arm.is_powered_on().unwrap(), "{}", what("power off"));
    arm.power_on().unwrap();
    assert!(arm.is_powered_on().unwrap(), "{}", what("power on"));
    assert!(arm.is_all_servo_enabled().unwrap());
    assert!(arm.is_servo_enabled(s(1)).unwrap());
    arm.set_free_move().unwrap();
    run(&robot, 100_000);
    assert!(
        !arm.is_all_servo_enabled().unwrap(),
        "{}",
        what("free move")
    );
    arm.power_on().unwrap();
    run(&robot, 100_000);
    assert!(arm.is_all_servo_enabled().unwrap());

    // 2.3 MDI: angles, coordinates, in position.
    assert_near(&angles_deg(&mut arm), &[0.0; 6], 0.1, &what("at zero"));
    let target = [10.0, 20.0, -30.0, 15.0, -25.0, 40.0];
    arm.write_angles(angles(target), speed(80)).unwrap();
    run(&robot, 200_000);
    assert!(arm.check_running().unwrap(), "{}", what("moving"));
    until_still(&mut arm, &robot);
    assert_near(&angles_deg(&mut arm), &target, 0.2, &what("write angles"));
    let here = arm.get_coords().unwrap();
    assert!(arm.is_in_position(PositionTarget::Coords(here)).unwrap());
    match dialect {
        Dialect::Pymycobot => assert!(
            arm.is_in_position(PositionTarget::Angles(angles(target)))
                .unwrap()
        ),
        Dialect::Seed => assert_eq!(
            arm.is_in_position(PositionTarget::Angles(angles(target))),
            Err(Error::NotInDialect { cmd: 0x2A })
        ),
    }
    arm.write_angle(j(1), deg(30.0), speed(50)).unwrap();
    until_still(&mut arm, &robot);
    let mut expected = target;
    expected[0] = 30.0;
    assert_near(
        &angles_deg(&mut arm),
        &expected,
        0.2,
        &what("write angle, joint 1"),
    );
    arm.write_angle(j(6), deg(-10.0), speed(50)).unwrap();
    until_still(&mut arm, &robot);
    expected[5] = -10.0;
    assert_near(
        &angles_deg(&mut arm),
        &expected,
        0.2,
        &what("write angle, joint 6"),
    );

    let start = pose_to_mm_deg(&arm.get_coords().unwrap());
    arm.write_coord(AxisValue::Z(mm(start[2] - 20.0)), speed(50))
        .unwrap();
    until_still(&mut arm, &robot);
    let lower = pose_to_mm_deg(&arm.get_coords().unwrap());
    let mut want = start;
    want[2] -= 20.0;
    assert_near(&lower[..3], &want[..3], 1.0, &what("write coord z"));
    arm.write_coord(AxisValue::Rz(deg(start[5] + 5.0)), speed(50))
        .unwrap();
    until_still(&mut arm, &robot);
    let turned = pose_to_mm_deg(&arm.get_coords().unwrap());
    assert!(
        (turned[5] - (start[5] + 5.0)).abs() < 0.5,
        "{}",
        what("write coord rz")
    );
    assert!((turned[2] - want[2]).abs() < 1.0, "{}", what("rz leaves z"));
    arm.write_coords(
        mycobot_api::convert::pose(start),
        speed(50),
        MoveMode::Linear,
    )
    .unwrap();
    until_still(&mut arm, &robot);
    assert_near(
        &pose_to_mm_deg(&arm.get_coords().unwrap())[..3],
        &start[..3],
        1.0,
        &what("write coords, a line"),
    );

    // 2.4 jog along a base axis, where the arm has room.
    let z = pose_to_mm_deg(&arm.get_coords().unwrap())[2];
    arm.jog_coord(Axis::Z, Direction::Negative, speed(30))
        .unwrap();
    run(&robot, 600_000);
    arm.jog_stop().unwrap();
    run(&robot, 400_000);
    let jogged_z = pose_to_mm_deg(&arm.get_coords().unwrap())[2];
    assert!(
        jogged_z < z - 2.0,
        "{}: {z} -> {jogged_z}",
        what("jog coord z")
    );

    // Encoders.
    arm.set_encoders([Steps(2048); 6], speed(50)).unwrap();
    until_still(&mut arm, &robot);
    assert_near(&angles_deg(&mut arm), &[0.0; 6], 0.2, &what("set encoders"));
    arm.set_encoder(s(2), Steps(2048 + 200)).unwrap();
    until_still(&mut arm, &robot);
    let encoder = arm.get_encoder(s(2)).unwrap();
    assert!(
        (encoder.0 - 2248).abs() <= 2,
        "{}: {encoder:?}",
        what("set encoder")
    );

    // 2.4 jog, pause, resume, stop.
    let before = angles_deg(&mut arm)[0];
    arm.jog_angle(j(1), Direction::Positive, speed(30)).unwrap();
    run(&robot, 600_000);
    assert!(arm.check_running().unwrap());
    arm.jog_stop().unwrap();
    run(&robot, 400_000);
    let jogged = angles_deg(&mut arm)[0];
    assert!(
        jogged > before + 2.0,
        "{}: {before} -> {jogged}",
        what("jog angle")
    );
    run(&robot, 500_000);
    assert!(
        (angles_deg(&mut arm)[0] - jogged).abs() < 0.3,
        "{}",
        what("jog stop")
    );
    arm.write_angles(angles([60.0, 0.0, 0.0, 0.0, 0.0, 0.0]), speed(20))
        .unwrap();
    run(&robot, 500_000);
    arm.pause().unwrap();
    run(&robot, 300_000);
    let paused = angles_deg(&mut arm)[0];
    run(&robot, 700_000);
    assert!(
        (angles_deg(&mut arm)[0] - paused).abs() < 0.3,
        "{}",
        what("pause holds")
    );
    arm.resume().unwrap();
    until_still(&mut arm, &robot);
    assert!(
        (angles_deg(&mut arm)[0] - 60.0).abs() < 0.2,
        "{}",
        what("resume goes on")
    );
    arm.write_angles(angles([0.0; 6]), speed(20)).unwrap();
    run(&robot, 700_000);
    arm.stop().unwrap();
    run(&robot, 500_000);
    let stopped = angles_deg(&mut arm)[0];
    run(&robot, 1_000_000);
    assert!(
        (angles_deg(&mut arm)[0] - stopped).abs() < 0.3,
        "{}",
        what("stop holds")
    );
    assert!(
        stopped > 5.0,
        "{}: stopped at {stopped}",
        what("stop is half way")
    );

    // 2.5 speed and joint limits.
    arm.set_speed(speed(50)).unwrap();
    assert_eq!(arm.get_speed().unwrap(), speed(50));
    assert_eq!(arm.get_joint_min(j(1)).unwrap(), limit_deg(-168.0));
    let max2 = arm.get_joint_max(j(2)).unwrap();
    arm.set_joint_max(j(2), limit_deg(90.0)).unwrap();
    assert_eq!(arm.get_joint_max(j(2)).unwrap(), limit_deg(90.0));
    let past = arm.write_angle(j(2), deg(100.0), speed(50));
    match dialect {
        Dialect::Pymycobot => assert_eq!(
            past,
            Err(Error::Refused {
                cmd: 0x21,
                code: Some(ErrorCode::JointLimit(j(2)))
            }),
            "{}",
            what("past a limit set")
        ),
        // A set command is not answered in the seed dialect: refused or not, the call ends
        // once it is written; the arm does not move and the error is there to read.
        Dialect::Seed => assert_eq!(past, Ok(())),
    }
    let joint_2 = angles_deg(&mut arm)[1];
    run(&robot, 500_000);
    assert!(
        (angles_deg(&mut arm)[1] - joint_2).abs() < 0.2,
        "{}",
        what("refused, still")
    );
    assert_eq!(
        arm.get_error_information().unwrap(),
        Some(ErrorCode::JointLimit(j(2)))
    );
    arm.set_joint_max(j(2), max2).unwrap();
    arm.set_joint_min(j(3), Decideg(-500)).unwrap();
    assert_eq!(arm.get_joint_min(j(3)).unwrap(), Decideg(-500));

    // 2.6 servos: registers, calibration, brake.
    let p_gain = arm.get_servo_data(s(1), 21).unwrap();
    arm.set_servo_data(s(1), 21, ServoValue::Byte(p_gain + 1))
        .unwrap();
    assert_eq!(arm.get_servo_data(s(1), 21).unwrap(), p_gain + 1);
    arm.set_servo_data(s(1), 21, ServoValue::Byte(p_gain))
        .unwrap();
    let position = arm.get_servo_data_word(s(1), 56).unwrap();
    let encoder = arm.get_encoder(s(1)).unwrap();
    assert!(
        (i32::from(position) - i32::from(encoder.0)).abs() <= 2,
        "{}",
        what("present position register")
    );
    arm.write_angle(j(4), deg(10.0), speed(50)).unwrap();
    until_still(&mut arm, &robot);
    arm.set_servo_calibration(s(4)).unwrap();
    run(&robot, 200_000);
    assert!(
        (arm.get_encoder(s(4)).unwrap().0 - 2048).abs() <= 2,
        "{}",
        what("calibration: here is zero")
    );
    assert!(angles_deg(&mut arm)[3].abs() < 0.3);
    arm.jog_angle(j(5), Direction::Positive, speed(20)).unwrap();
    run(&robot, 500_000);
    arm.joint_brake(s(5)).unwrap();
    run(&robot, 300_000);
    let braked = angles_deg(&mut arm)[4];
    run(&robot, 700_000);
    assert!(
        (angles_deg(&mut arm)[4] - braked).abs() < 0.3,
        "{}",
        what("joint brake")
    );
    arm.jog_stop().unwrap();

    // 2.7 Atom IO.
    arm.set_pin_mode(AtomPin::new(23).unwrap(), PinMode::Output)
        .unwrap();
    run(&robot, 20_000);
    assert_eq!(
        robot.borrow().atom_io().modes[2],
        Some(firmware_atom::io::PinMode::Output)
    );
    arm.set_led_rgb(Rgb { r: 0, g: 250, b: 7 }).unwrap();
    run(&robot, 10_000);
    assert_eq!(robot.borrow().atom_io().rgb, (0, 250, 7));

    // 2.8 gripper.
    arm.set_gripper_state(GripperState::Open, GripperSpeed::new(70).unwrap())
        .unwrap();
    run(&robot, 200_000);
    assert!(
        arm.is_gripper_moving().unwrap(),
        "{}",
        what("gripper moving")
    );
    run(&robot, 3_000_000);
    let open = arm.get_gripper_value().unwrap();
    arm.set_gripper(GripperState::Close).unwrap();
    run(&robot, 3_000_000);
    let closed = arm.get_gripper_value().unwrap();
    assert!(
        open.get() > closed.get() + 30,
        "{}: {open:?} {closed:?}",
        what("open, close")
    );
    arm.set_gripper_value(
        GripperValue::new(50).unwrap(),
        GripperSpeed::new(80).unwrap(),
    )
    .unwrap();
    run(&robot, 3_000_000);
    let half = arm.get_gripper_value().unwrap().get();
    assert!(
        (45..=55).contains(&half),
        "{}: {half}",
        what("gripper value")
    );
    assert!(!arm.is_gripper_moving().unwrap());
    arm.set_gripper_ini().unwrap();
    run(&robot, 200_000);
    // The present position becomes "closed" (docs/protocol.md, 0x68).
    let calibrated = arm.get_gripper_value().unwrap().get();
    assert!(
        calibrated <= 2,
        "{}: {calibrated}",
        what("gripper calibration")
    );

    // 2.9 frames.
    let tool = mycobot_api::convert::pose([0.0, 0.0, 50.0, 0.0, 0.0, 0.0]);
    arm.set_tool_reference(tool).unwrap();
    assert_eq!(arm.get_tool_reference().unwrap(), tool);
    let world = mycobot_api::convert::pose([10.0, -20.0, 30.0, 0.0, 0.0, 90.0]);
    arm.set_world_reference(world).unwrap();
    assert_eq!(arm.get_world_reference().unwrap(), world);
    let flange = pose_to_mm_deg(&arm.get_coords().unwrap());
    arm.set_end_type(EndType::Tool).unwrap();
    assert_eq!(arm.get_end_type().unwrap(), EndType::Tool);
    let tip = pose_to_mm_deg(&arm.get_coords().unwrap());
    assert!(
        (tip[..3].iter().zip(&flange[..3]))
            .map(|(a, b)| (a - b).powi(2))
            .sum::<f32>()
            .sqrt()
            > 45.0,
        "{}: the tool's tip is 50 mm from the flange",
        what("end type tool")
    );
    arm.set_reference_frame(ReferenceFrame::World).unwrap();
    assert_eq!(arm.get_reference_frame().unwrap(), ReferenceFrame::World);
    arm.set_reference_frame(ReferenceFrame::Base).unwrap();
    arm.set_end_type(EndType::Flange).unwrap();
    assert_eq!(arm.get_end_type().unwrap(), EndType::Flange);
}

#[test]
fn every_call_does_what_the_manual_says_in_pymycobots_dialect() {
    every_call(Dialect::Pymycobot);
}

#[test]
fn every_call_does_what_the_manual_says_in_the_seed_dialect() {
    every_call(Dialect::Seed);
}
