//! The seed dialect against the vendor manual itself: every example frame of its section 3.3
//! ("Basic development guide", `../shared/seeds/`), sent as printed (miscounted LENs
//! included) to the Basic's USB port with the seed dialect in force, does what the manual
//! says and answers what it says: a reply frame where it prints one, nothing where it says
//! 无返回值 ("no return value"). Where an example contradicts the manual's own text, the
//! text is followed; `docs/protocol.md` ("Dialects") lists those cases, and each is pinned
//! here too. What the arm does is read from the simulation, or asked in pymycobot's dialect
//! on the Atom's own port, never through the dialect under test.
#![allow(clippy::unwrap_used, clippy::expect_used, clippy::indexing_slicing)] // a test harness: a panic is a failed check

mod sim_support;

use open_mycobot::sim::{HostLink, RobotConfig, VirtualRobot};
use protocol_core::Frame;
use protocol_core::command::{Reply, Request};
use protocol_core::dialect::Dialect;
use protocol_core::units::Centideg;
use sim_support::*;

/// The manual's reply deadline (section 3.2): "within 500 ms".
const MANUAL_REPLY_US: u64 = 500_000;

/// A robot whose Basic speaks the seed dialect from boot, booted and powered on.
fn seed_arm() -> VirtualRobot {
    let mut config = RobotConfig::default();
    config.basic.dialect = Some(Dialect::Seed);
    booted(config)
}

/// Parses hex bytes as the manual prints them: `"FE FE 02 20 FA"`.
fn hex(text: &str) -> Vec<u8> {
    text.split_whitespace()
        .map(|b| u8::from_str_radix(b, 16).expect("hex byte"))
        .collect()
}

/// Sends an example as printed and returns the frame that comes back within the manual's
/// deadline, if any; afterwards the link is quiet (one answer at most).
fn send(robot: &mut VirtualRobot, example: &str) -> Option<Frame> {
    robot.link_write(HostLink::Basic, &hex(example));
    let reply = robot.await_frame(HostLink::Basic, MANUAL_REPLY_US);
    assert_silent_for(robot, HostLink::Basic, 50_000);
    reply
}

/// Sends an example the manual says has no return value: nothing comes back.
fn send_silent(robot: &mut VirtualRobot, example: &str) {
    assert_eq!(send(robot, example), None, "{example} answered");
}

/// Asks in pymycobot's dialect on the Atom's own port: the check, not the thing checked.
fn check(robot: &mut VirtualRobot, request: Request) -> Reply {
    ask_on(robot, HostLink::AtomUsb, request)
}

fn i16_at(data: &[u8], i: usize) -> i16 {
    i16::from_be_bytes([data[i], data[i + 1]])
}

#[test]
fn power_examples_open_and_close_the_arm_and_report_it() {
    let mut robot = seed_arm();
    send_silent(&mut robot, "FE FE 02 11 FA");
    robot.run_for(50_000);
    assert!(!robot.atom().is_powered());
    // "FE FE 02 12 00 FA": the manual prints LEN 02 for one data byte; the frame comes with
    // the LEN every other frame has, the byte where the manual puts it.
    let reply = send(&mut robot, "FE FE 02 12 FA").expect("0x12 answers");
    assert_eq!((reply.cmd(), reply.data()), (0x12, &[0][..]));
    send_silent(&mut robot, "FE FE 02 10 FA");
    robot.run_for(50_000);
    assert!(robot.atom().is_powered());
    assert_eq!(send(&mut robot, "FE FE 02 12 FA").unwrap().data(), [1]);
    // 0x13 releases every servo.
    send_silent(&mut robot, "FE FE 02 13 FA");
    robot.run_for(50_000);
    assert!(robot.servos().all(|s| !s.torque_enabled()));
}

#[test]
fn angle_examples_read_and_move_joint_1_numbered_from_0() {
    let mut robot = seed_arm();
    // Joint 2 out of the way, then the manual's "FE FE 06 21 00 00 00 20 FA": joint_no 0 (the
    // first joint) to 0.00 degrees at speed 0x20.
    move_on_atom(&mut robot, [20.0, -10.0, 0.0, 0.0, 0.0, 0.0]);
    send_silent(&mut robot, "FE FE 06 21 00 00 00 20 FA");
    wait_still(&mut robot);
    let angles = robot.atom().present_angles();
    assert!(angles[0].0.abs() <= ANGLE_TOLERANCE, "J1 {angles:?}");
    assert!(
        (angles[1].0 + 1000).abs() <= ANGLE_TOLERANCE,
        "J2 kept {angles:?}"
    );
    // "FE FE 02 20 FA" answers six int16 (LEN 0x0E).
    let reply = send(&mut robot, "FE FE 02 20 FA").expect("0x20 answers");
    assert_eq!((reply.cmd(), reply.data().len()), (0x20, 12));
    assert!((i16_at(reply.data(), 2) + 1000).abs() <= ANGLE_TOLERANCE);
}

/// "FE FE 0F 22 06 E6 ... 02 B6 FA" prints LEN 0x0F (angles and speed, as the table says) but
/// only the twelve angle bytes: following the text, it is a frame cut short, which the Basic
/// drops once the line is quiet; the next frame is read as usual. Its angles put joint 3 at
/// -152.31 degrees, past that joint's limit (150): the table's frame is refused, error 3.
#[test]
fn the_send_angles_example_without_its_speed_byte_is_a_cut_frame() {
    let mut robot = seed_arm();
    let before = robot.atom().present_angles();
    send_silent(
        &mut robot,
        "FE FE 0F 22 06 E6 EA 4E C4 81 0B BD EA C0 02 B6 FA",
    );
    robot.run_for(300_000);
    assert_angles_near(robot.atom().present_angles(), before, "nothing moved");
    assert_eq!(
        check(&mut robot, Request::GetErrorInfo),
        Reply::Byte(0),
        "not read"
    );
    // With the speed byte the table describes, the frame is read: J3 is past its limit.
    send_silent(
        &mut robot,
        "FE FE 0F 22 06 E6 EA 4E C4 81 0B BD EA C0 02 B6 32 FA",
    );
    robot.run_for(300_000);
    assert_eq!(check(&mut robot, Request::GetErrorInfo), Reply::Byte(3));
    assert_angles_near(robot.atom().present_angles(), before, "refused");
    // Within the limits, the same frame moves the arm.
    send_silent(
        &mut robot,
        "FE FE 0F 22 06 E6 EA 4E C6 78 0B BD EA C0 02 B6 32 FA",
    );
    wait_still(&mut robot);
    let want = [1766, -5554, -14728, 3005, -5440, 694].map(Centideg);
    assert_angles_near(robot.atom().present_angles(), want, "the table's frame");
}

#[test]
fn coordinate_examples_read_the_pose_move_x_and_reach_the_printed_pose() {
    let mut robot = seed_arm();
    move_on_atom(&mut robot, [0.0, -20.0, -60.0, -10.0, 0.0, 0.0]);
    let reply = send(&mut robot, "FE FE 02 23 FA").expect("0x23 answers");
    assert_eq!((reply.cmd(), reply.data().len()), (0x23, 12));
    let (x0, y0) = (i16_at(reply.data(), 0), i16_at(reply.data(), 2));
    // "FE FE 06 24 00 00 64 20 FA": axis 0 is x, 0x0064 x 1/10 = 10.0 mm (the text's rule;
    // its caption says 100).
    send_silent(&mut robot, "FE FE 06 24 00 00 64 20 FA");
    wait_still(&mut robot);
    let now = send(&mut robot, "FE FE 02 23 FA").unwrap();
    assert!(
        (i16_at(now.data(), 0) - 100).abs() <= 5,
        "x {x0} -> {:?}",
        now.data()
    );
    assert!((i16_at(now.data(), 2) - y0).abs() <= 5, "y kept");
    // "FE FE 10 25 ...": the pose (-14, -27.4, 275.3, -89.55, 0.72, -90.67), speed 50,
    // linear. From where the arm is, the line leaves the workspace: refused (34) as in any
    // dialect.
    send_silent(
        &mut robot,
        "FE FE 10 25 FF 74 FE EE 0A C1 DD 05 00 48 DC 95 32 01 FA",
    );
    wait_still(&mut robot);
    assert_eq!(
        check(&mut robot, Request::GetErrorInfo),
        Reply::Byte(34),
        "no straight line"
    );
    // From 20 mm beside it (a joint move, pymycobot's dialect on the Atom's port) the straight
    // line is in the workspace.
    check(&mut robot, Request::ClearErrorInfo);
    robot.link_write(
        HostLink::AtomUsb,
        &hex("FE FE 10 25 FF 74 FE 26 0A C1 DD 05 00 48 DC 95 32 00 FA"),
    );
    assert_eq!(
        robot
            .await_frame(HostLink::AtomUsb, MANUAL_REPLY_US)
            .unwrap()
            .data(),
        [1]
    );
    wait_still(&mut robot);
    send_silent(
        &mut robot,
        "FE FE 10 25 FF 74 FE EE 0A C1 DD 05 00 48 DC 95 32 01 FA",
    );
    wait_still(&mut robot);
    assert_eq!(check(&mut robot, Request::GetErrorInfo), Reply::Byte(0));
    let pose = send(&mut robot, "FE FE 02 23 FA").unwrap();
    let want = [-140, -274, 2753];
    for (axis, w) in want.iter().enumerate() {
        let got = i16_at(pose.data(), axis * 2);
        assert!((got - w).abs() <= 5, "axis {axis}: {:?}", pose.data());
    }
    // "FE FE 15 2A ... FA" (LEN printed as 0x15 for 15, no type byte): at that pose, 1.
    let reply = send(
        &mut robot,
        "FE FE 15 2A FF 74 FE EE 0A C1 DD 05 00 48 DC 95 FA",
    )
    .expect("0x2A answers");
    assert_eq!((reply.cmd(), reply.data()), (0x2A, &[1][..]));
    // "FE FE 02 2B FA": not running.
    assert_eq!(send(&mut robot, "FE FE 02 2B FA").unwrap().data(), [0]);
}

#[test]
fn jog_examples_turn_joint_1_and_move_along_x_until_jog_stop() {
    let mut robot = seed_arm();
    move_on_atom(&mut robot, [0.0, -20.0, -60.0, -10.0, 0.0, 0.0]);
    // "FE FE 05 30 01 01 32 FA": joint 1 (numbered from 1 here), direction 1, 50 %.
    let j1 = robot.atom().present_angles()[0];
    send_silent(&mut robot, "FE FE 05 30 01 01 32 FA");
    robot.run_for(500_000);
    assert!(robot.atom().is_moving());
    send_silent(&mut robot, "FE FE 02 34 FA");
    wait_still(&mut robot);
    let moved = robot.atom().present_angles()[0].0 - j1.0;
    assert!(moved > 300, "J1 turned {moved} cdeg");
    // "FE FE 05 32 01 00 32 FA": the x axis, direction 0 (negative), 50 %.
    let x0 = i16_at(send(&mut robot, "FE FE 02 23 FA").unwrap().data(), 0);
    send_silent(&mut robot, "FE FE 05 32 01 00 32 FA");
    robot.run_for(500_000);
    send_silent(&mut robot, "FE FE 02 34 FA");
    wait_still(&mut robot);
    let x1 = i16_at(send(&mut robot, "FE FE 02 23 FA").unwrap().data(), 0);
    assert!(x1 < x0 - 50, "x {x0} -> {x1}");
}

#[test]
fn encoder_examples_set_servo_2_and_read_servo_1_numbered_from_0() {
    let mut robot = seed_arm();
    // "FE FE 05 3A 01 08 C9 FA": the second joint to 2249, no speed (the default).
    send_silent(&mut robot, "FE FE 05 3A 01 08 C9 FA");
    wait_still(&mut robot);
    let s2 = robot.servo(2).unwrap().present_position();
    assert!(s2.abs_diff(2249) <= 2, "servo 2 at {s2}");
    // "FE FE 03 3B 00 FA": servo 1's encoder, "FE FE 04 3B hi lo FA".
    let reply = send(&mut robot, "FE FE 03 3B 00 FA").expect("0x3B answers");
    let s1 = robot.servo(1).unwrap().present_position();
    assert_eq!(reply.data().len(), 2);
    assert!((i16_at(reply.data(), 0) as u16).abs_diff(s1) <= 2);
    // "FE FE 15 3C 00 ... 00 20 FA" (LEN printed 0x15 for 15): every servo to encoder 0, which
    // is -180 degrees, past every joint's limit: refused as in any dialect, nothing moves.
    let before = robot.atom().present_angles();
    send_silent(
        &mut robot,
        "FE FE 15 3C 00 00 00 00 00 00 00 00 00 00 00 00 20 FA",
    );
    robot.run_for(300_000);
    assert_angles_near(robot.atom().present_angles(), before, "refused");
    assert_eq!(check(&mut robot, Request::GetErrorInfo), Reply::Byte(1));
}

#[test]
fn speed_examples_set_and_read_the_running_speed() {
    let mut robot = seed_arm();
    // "FE FE 02 41 32 FA": LEN printed 02 with the speed byte.
    send_silent(&mut robot, "FE FE 02 41 32 FA");
    let reply = send(&mut robot, "FE FE 02 40 FA").expect("0x40 answers");
    assert_eq!((reply.cmd(), reply.data()), (0x40, &[0x32][..]));
}

#[test]
fn joint_limit_examples_answer_the_value_alone_and_narrow_joint_1() {
    let mut robot = seed_arm();
    // "FE FE 03 4A 00 FA" -> "FE FE 04 4A hi lo FA": joint 1's minimum, degrees x 10.
    let min = send(&mut robot, "FE FE 03 4A 00 FA").expect("0x4A answers");
    assert_eq!(min.data().len(), 2, "{min:?}");
    let want = robot.atom().joint_limits()[0].min.0 / 10;
    assert_eq!(i16_at(min.data(), 0), want);
    // "FE FE 03 4B 01 FA": joint 2's maximum.
    let max = send(&mut robot, "FE FE 03 4B 01 FA").expect("0x4B answers");
    assert_eq!(
        i16_at(max.data(), 0),
        robot.atom().joint_limits()[1].max.0 / 10
    );
    // "FE FE 05 4D 00 01 44 FA": joint 1's maximum to 0x0144 / 10 = 32.4 degrees (the text's
    // rule; the caption says 90). Then "FE FE 05 4C 00 01 44 FA" raises its minimum there.
    send_silent(&mut robot, "FE FE 05 4D 00 01 44 FA");
    assert_eq!(robot.atom().joint_limits()[0].max, Centideg(3240));
    move_on_atom(&mut robot, [32.4, 0.0, 0.0, 0.0, 0.0, 0.0]);
    send_silent(&mut robot, "FE FE 05 4C 00 01 44 FA");
    assert_eq!(robot.atom().joint_limits()[0].min, Centideg(3240));
}

#[test]
fn servo_examples_check_the_connection_and_the_servos() {
    let mut robot = seed_arm();
    // "FE FE 03 50 FA" (LEN printed 03, no data): connected.
    let reply = send(&mut robot, "FE FE 03 50 FA").expect("0x50 answers");
    assert_eq!((reply.cmd(), reply.data()), (0x50, &[1][..]));
    // "FE FE 02 51 FA": every servo powered.
    assert_eq!(send(&mut robot, "FE FE 02 51 FA").unwrap().data(), [1]);
    // "FE FE 04 53 00 21 FA", "read servo 1's P": servo 00 is the first; register 0x21 is 33
    // (the table numbers P as 21 decimal), so it reads register 33 of servo 1.
    let reply = send(&mut robot, "FE FE 04 53 00 21 FA").expect("0x53 answers");
    assert_eq!(reply.data(), [robot.servo(1).unwrap().reg(33)]);
    // "FE FE 05 52 00 21 01 FA": a write of register 33 (the operating mode), refused as in
    // any dialect; the P gain stays.
    let p = robot.servo(1).unwrap().reg(21);
    send_silent(&mut robot, "FE FE 05 52 00 21 01 FA");
    robot.run_for(50_000);
    assert_eq!(robot.servo(1).unwrap().reg(21), p);
    assert_eq!(robot.servo(1).unwrap().reg(33), 0);
    // "FE FE 03 56 00 FA": brake servo 1: it holds, torque on.
    send_silent(&mut robot, "FE FE 03 56 00 FA");
    robot.run_for(50_000);
    assert!(robot.servo(1).unwrap().torque_enabled());
    // "FE FE 03 55 00 FA": servo 1's present position becomes its zero (2048).
    move_on_atom(&mut robot, [10.0, 0.0, 0.0, 0.0, 0.0, 0.0]);
    send_silent(&mut robot, "FE FE 03 55 00 FA");
    robot.run_for(200_000);
    let s1 = robot.servo(1).unwrap().present_position();
    assert!(s1.abs_diff(2048) <= 2, "servo 1 reads {s1}");
}

#[test]
fn pause_continue_and_stop_are_0x26_0x27_0x28() {
    let mut robot = seed_arm();
    move_on_atom(&mut robot, [0.0; 6]);
    let far = "FE FE 06 21 00 2E E0 0A FA"; // joint 1 to 120 degrees, slowly
    send_silent(&mut robot, far);
    robot.run_for(400_000);
    send_silent(&mut robot, "FE FE 02 26 FA");
    robot.run_for(400_000);
    let paused = robot.atom().present_angles()[0];
    robot.run_for(500_000);
    assert_eq!(robot.atom().present_angles()[0], paused, "paused");
    send_silent(&mut robot, "FE FE 02 27 FA");
    robot.run_for(500_000);
    let resumed = robot.atom().present_angles()[0];
    assert!(
        resumed.0 > paused.0 + 100,
        "continued: {paused:?} -> {resumed:?}"
    );
    send_silent(&mut robot, "FE FE 02 28 FA");
    wait_still(&mut robot);
    let stopped = robot.atom().present_angles()[0];
    assert!(stopped.0 < 11_000, "stopped short of 120: {stopped:?}");
    // A later continue does not restart a stopped move.
    send_silent(&mut robot, "FE FE 02 27 FA");
    robot.run_for(1_000_000);
    assert!(!robot.atom().is_moving());
    let after = robot.atom().present_angles()[0];
    assert!(
        (after.0 - stopped.0).abs() <= ANGLE_TOLERANCE,
        "{stopped:?} -> {after:?}"
    );
}

#[test]
fn io_examples_colour_the_leds_open_the_gripper_and_refuse_pin_25() {
    let mut robot = seed_arm();
    // "FE FE 05 6A 00 00 FF FA": blue.
    send_silent(&mut robot, "FE FE 05 6A 00 00 FF FA");
    robot.run_for(50_000);
    assert_eq!(robot.atom_io().rgb, (0, 0, 0xFF));
    // "FE FE 03 66 00 FA": the gripper open (state 0).
    send_silent(&mut robot, "FE FE 03 66 00 FA");
    robot.run_for(3_000_000);
    assert!(
        robot.atom().gripper_value() >= 90,
        "{}",
        robot.atom().gripper_value()
    );
    // "FE FE 04 60 19 00 FA", "pin 16 as output, mode 0": pin 0x19 (25) is not an Atom pin.
    send_silent(&mut robot, "FE FE 04 60 19 00 FA");
    robot.run_for(50_000);
    assert!(robot.atom_io().modes.iter().all(Option::is_none));
}

#[test]
fn frame_examples_set_and_read_the_tool_world_reference_and_end() {
    let mut robot = seed_arm();
    let pose = "FF 74 FE EE 0A C1 DD 05 00 48 DC 95";
    // LEN printed 0x14 for 14.
    send_silent(&mut robot, &format!("FE FE 14 81 {pose} FA"));
    send_silent(&mut robot, &format!("FE FE 14 83 {pose} FA"));
    for code in ["82", "84"] {
        let reply = send(&mut robot, &format!("FE FE 02 {code} FA")).expect("answers");
        assert_eq!(reply.data(), hex(pose), "0x{code}");
    }
    send_silent(&mut robot, "FE FE 03 85 01 FA");
    assert_eq!(send(&mut robot, "FE FE 02 86 FA").unwrap().data(), [1]);
    send_silent(&mut robot, "FE FE 03 85 00 FA");
    assert_eq!(send(&mut robot, "FE FE 02 86 FA").unwrap().data(), [0]);
    send_silent(&mut robot, "FE FE 03 89 01 FA");
    assert_eq!(send(&mut robot, "FE FE 02 8A FA").unwrap().data(), [1]);
    send_silent(&mut robot, "FE FE 03 89 00 FA");
    assert_eq!(send(&mut robot, "FE FE 02 8A FA").unwrap().data(), [0]);
}

/// Moves the joints to `angles` (degrees) in pymycobot's dialect on the Atom's own port, and
/// waits until the arm is still.
fn move_on_atom(robot: &mut VirtualRobot, angles: [f64; 6]) {
    ack_on_atom(
        robot,
        Request::SendAngles {
            angles: degrees(angles),
            speed: speed(80),
        },
    );
    wait_still(robot);
}

/// Asks in pymycobot's dialect on the Atom's own port and checks it is taken.
fn ack_on_atom(robot: &mut VirtualRobot, request: Request) {
    assert_eq!(check(robot, request.clone()), Reply::Ack, "{request:?}");
}
