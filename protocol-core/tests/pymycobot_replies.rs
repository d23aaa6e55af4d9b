//! Replies encoded by [`Reply::to_frame`] are read back by pymycobot 4.0.7 (its own parsing
//! code, through `tools/pymycobot_replies.py`) as the values the user expects.
//!
//! Needs the workspace's Python venv with pymycobot 4.0.7 (`<workspace>/.venv`, or the
//! interpreter in env `MYCOBOT_PYTHON`), set up on first use by the end-to-end tests' helper
//! (`tests/e2e/venv.rs`).

// Test code: a panic is a test failure with a message.
#![allow(clippy::unwrap_used, clippy::expect_used, clippy::indexing_slicing)]

use std::io::Write;
use std::process::{Command, Stdio};

use protocol_core::command::*;
use protocol_core::units::{Centideg, Decideg, Steps};

#[path = "../../tests/e2e/venv.rs"]
mod venv;
use venv::{python, workspace};

struct Case {
    method: &'static str,
    args: &'static str,
    cmd: u8,
    reply: Reply,
    /// What the pymycobot call must return, as JSON.
    want: String,
}

fn case(method: &'static str, args: &'static str, cmd: u8, reply: Reply, want: String) -> Case {
    Case {
        method,
        args,
        cmd,
        reply,
        want,
    }
}

fn list<T: std::fmt::Display>(v: impl IntoIterator<Item = T>) -> String {
    let items: Vec<String> = v.into_iter().map(|x| x.to_string()).collect();
    format!("[{}]", items.join(", "))
}

fn degrees(a: &[Centideg]) -> String {
    list(a.iter().map(|c| f64::from(c.0) / 100.0))
}

fn pose_json(p: &Pose) -> String {
    let v = p.to_array();
    let (lin, ang) = v.split_at(3);
    list(
        lin.iter()
            .map(|&x| f64::from(x) / 10.0)
            .chain(ang.iter().map(|&x| f64::from(x) / 100.0)),
    )
}

fn j(n: u8) -> JointId {
    JointId::new(n).unwrap()
}

fn cases() -> Vec<Case> {
    let angles = [-16800, -2, 250, 0, 12345, 18000].map(Centideg);
    let pose = Pose::from_array([1565, -634, 3042, -17560, -6, -8990]);
    let edge = Pose::from_array([-2814, 2814, -700, -18000, 18000, -2]);
    let encoders = [0, 4096, 2048, 250, 1, 4095].map(Steps);
    let voltages = [74, 75, 120, 0, 250, 81];
    let speeds = [0, -120, 6000, 250, -6, 32767];
    let errors = [
        ServoErrorCode::Ok,
        ServoErrorCode::NoAnswer,
        ServoErrorCode::BadAnswer,
        ServoErrorCode::PositionError,
        ServoErrorCode::Fault(8),
        ServoErrorCode::Ok,
        ServoErrorCode::Fault(1),
    ];
    vec![
        case(
            "get_angles",
            "[]",
            cmd::GET_ANGLES,
            Reply::Angles(angles),
            degrees(&angles),
        ),
        case(
            "get_angles_plan",
            "[]",
            cmd::GET_PLANNED_ANGLES,
            Reply::Angles(angles),
            degrees(&angles),
        ),
        case(
            "solve_inv_kinematics",
            "[[156.5, -63.4, 304.2, -175.6, -0.6, -89.9], [0, 0, 0, 0, 0, 0]]",
            cmd::SOLVE_INV_KINEMATICS,
            Reply::Angles(angles),
            degrees(&angles),
        ),
        case(
            "get_coords",
            "[]",
            cmd::GET_COORDS,
            Reply::Coords(pose),
            pose_json(&pose),
        ),
        case(
            "get_coords",
            "[]",
            cmd::GET_COORDS,
            Reply::Coords(edge),
            pose_json(&edge),
        ),
        case(
            "get_coords_plan",
            "[]",
            cmd::GET_PLANNED_COORDS,
            Reply::Coords(pose),
            pose_json(&pose),
        ),
        case(
            "angles_to_coords",
            "[[0, 0, 0, 0, 0, 0]]",
            cmd::GET_COORDS,
            Reply::Coords(edge),
            pose_json(&edge),
        ),
        case(
            "get_tool_reference",
            "[]",
            cmd::GET_TOOL_REFERENCE,
            Reply::Coords(edge),
            pose_json(&edge),
        ),
        case(
            "get_world_reference",
            "[]",
            cmd::GET_WORLD_REFERENCE,
            Reply::Coords(pose),
            pose_json(&pose),
        ),
        case(
            "get_angles_coords",
            "[]",
            cmd::GET_ANGLES_COORDS,
            Reply::AnglesAndCoords {
                angles,
                coords: pose,
            },
            list(
                degrees(&angles)
                    .trim_matches(['[', ']'])
                    .split(", ")
                    .chain(pose_json(&pose).trim_matches(['[', ']']).split(", ")),
            ),
        ),
        case(
            "get_encoders",
            "[]",
            cmd::GET_ENCODERS,
            Reply::Encoders(encoders),
            list(encoders.map(|e| e.0)),
        ),
        case(
            "get_encoder",
            "[7]",
            cmd::GET_ENCODER,
            Reply::Int16(2048),
            "2048".into(),
        ),
        case(
            "get_servo_speeds",
            "[]",
            cmd::GET_SERVO_SPEEDS,
            Reply::Int16x6(speeds),
            list(speeds),
        ),
        case(
            "get_servo_voltages",
            "[]",
            cmd::GET_SERVO_VOLTAGES,
            Reply::Bytes6(voltages),
            list(voltages.map(|v| f64::from(v) / 10.0)),
        ),
        case(
            "get_servo_temps",
            "[]",
            cmd::GET_SERVO_TEMPS,
            Reply::Bytes6(voltages),
            list(voltages),
        ),
        case(
            "get_servo_status",
            "[]",
            cmd::GET_SERVO_STATUS,
            Reply::Bytes6([0; 6]),
            list([0; 6]),
        ),
        case(
            "get_servo_status",
            "[]",
            cmd::GET_SERVO_STATUS,
            Reply::Bytes6([0, 0, 32, 0, 5, 0]),
            "[0, 0, [5], 0, [0, 2], 0]".into(),
        ),
        // pymycobot maps 16..22 -> 1 (communication), 23..28 -> 2 (unstable), 32..111 -> 3
        // (servo fault), then lists the set bits of that number.
        case(
            "read_next_error",
            "[]",
            cmd::READ_NEXT_ERROR,
            Reply::ServoErrors(errors.map(ServoErrorCode::code)),
            "[0, [0], [0], [1], [0, 1], 0, [0, 1]]".into(),
        ),
        case(
            "get_joint_min_angle",
            "[1]",
            cmd::GET_JOINT_MIN,
            Reply::JointLimit {
                joint: j(1),
                limit: Decideg(-1680),
            },
            "-168.0".into(),
        ),
        case(
            "get_joint_max_angle",
            "[5]",
            cmd::GET_JOINT_MAX,
            Reply::JointLimit {
                joint: j(5),
                limit: Decideg(1605),
            },
            "160.5".into(),
        ),
        case(
            "get_digital_input",
            "[39]",
            cmd::GET_DIGITAL_INPUT,
            Reply::PinLevel {
                pin: 39,
                high: true,
            },
            "1".into(),
        ),
        case(
            "get_basic_input",
            "[35]",
            cmd::GET_BASIC_INPUT,
            Reply::PinLevel {
                pin: 35,
                high: false,
            },
            "0".into(),
        ),
        case(
            "is_servo_enable",
            "[3]",
            cmd::IS_SERVO_ENABLED,
            Reply::ServoEnabled {
                servo: ServoId::new(3).unwrap(),
                enabled: true,
            },
            "1".into(),
        ),
        case(
            "is_power_on",
            "[]",
            cmd::IS_POWER_ON,
            Reply::Byte(1),
            "1".into(),
        ),
        case(
            "is_power_on",
            "[]",
            cmd::IS_POWER_ON,
            Reply::Byte(0),
            "0".into(),
        ),
        case(
            "is_moving",
            "[]",
            cmd::IS_MOVING,
            Reply::Byte(1),
            "1".into(),
        ),
        case(
            "is_paused",
            "[]",
            cmd::IS_PAUSED,
            Reply::Byte(0),
            "0".into(),
        ),
        case(
            "is_in_position",
            "[[0, 0, 0, 0, 0, 0], 0]",
            cmd::IS_IN_POSITION,
            Reply::Byte(1),
            "1".into(),
        ),
        case(
            "get_error_information",
            "[]",
            cmd::GET_ERROR_INFO,
            Reply::Byte(ErrorCode::IkNoSolution.code()),
            "32".into(),
        ),
        case(
            "get_error_information",
            "[]",
            cmd::GET_ERROR_INFO,
            Reply::Byte(ErrorCode::JointLimit(j(4)).code()),
            "4".into(),
        ),
        case(
            "get_system_version",
            "[]",
            cmd::GET_SYSTEM_VERSION,
            Reply::Byte(70),
            "7.0".into(),
        ),
        case(
            "get_basic_version",
            "[]",
            cmd::GET_BASIC_VERSION,
            Reply::Byte(12),
            "1.2".into(),
        ),
        case(
            "get_modify_version",
            "[]",
            cmd::GET_MODIFY_VERSION,
            Reply::Byte(3),
            "3".into(),
        ),
        case(
            "get_reboot_count",
            "[]",
            cmd::GET_REBOOT_COUNT,
            Reply::Int16(300),
            "300".into(),
        ),
        case(
            "get_tof_distance",
            "[]",
            cmd::GET_TOF_DISTANCE,
            Reply::Int16(250),
            "250".into(),
        ),
        case(
            "get_gripper_value",
            "[]",
            cmd::GET_GRIPPER_VALUE,
            Reply::Byte(55),
            "55".into(),
        ),
        case(
            "is_gripper_moving",
            "[]",
            cmd::IS_GRIPPER_MOVING,
            Reply::Byte(0),
            "0".into(),
        ),
        case(
            "get_fresh_mode",
            "[]",
            cmd::GET_FRESH_MODE,
            Reply::Byte(1),
            "1".into(),
        ),
        case(
            "get_end_type",
            "[]",
            cmd::GET_END_TYPE,
            Reply::Byte(1),
            "1".into(),
        ),
        case(
            "get_transponder_mode",
            "[]",
            cmd::GET_TRANSPONDER_MODE,
            Reply::Byte(0),
            "0".into(),
        ),
        case(
            "get_servo_data",
            "[1, 56, 1]",
            cmd::GET_SERVO_DATA,
            Reply::Int16(2048),
            "2048".into(),
        ),
        case(
            "get_servo_data",
            "[1, 21]",
            cmd::GET_SERVO_DATA,
            Reply::Byte(32),
            "32".into(),
        ),
        case(
            "get_HTS_gripper_torque",
            "[]",
            cmd::GET_HTS_GRIPPER_TORQUE,
            Reply::Int16(300),
            "300".into(),
        ),
        case(
            "send_angle",
            "[1, -168, 1]",
            cmd::SEND_ANGLE,
            Reply::Ack,
            "1".into(),
        ),
        case(
            "send_angles",
            "[[0, 0, 0, 0, 0, 0], 50]",
            cmd::SEND_ANGLES,
            Reply::Ack,
            "1".into(),
        ),
        case("power_on", "[]", cmd::POWER_ON, Reply::Ack, "1".into()),
        case(
            "set_color",
            "[255, 0, 0]",
            cmd::SET_COLOR,
            Reply::Ack,
            "1".into(),
        ),
        case(
            "set_basic_output",
            "[5, 1]",
            cmd::SET_BASIC_OUTPUT,
            Reply::Ack,
            "1".into(),
        ),
        case(
            "set_gripper_value",
            "[50, 80]",
            cmd::SET_GRIPPER_VALUE,
            Reply::Ack,
            "1".into(),
        ),
    ]
}

#[test]
fn pymycobot_reads_our_replies_as_the_values_we_meant() {
    let cases = cases();
    let mut input = String::new();
    for c in &cases {
        let frame = c.reply.to_frame(c.cmd);
        assert!(frame.data().len() <= 28, "{}: reply too long", c.method);
        let hex: Vec<String> = frame
            .to_bytes()
            .iter()
            .map(|b| format!("{b:02X}"))
            .collect();
        input += &format!(
            "{} | {} | {} | {}\n",
            c.method,
            c.args,
            hex.join(" "),
            c.want
        );
    }
    let script = workspace().join("tools/pymycobot_replies.py");
    let mut child = Command::new(python())
        .arg(&script)
        .stdin(Stdio::piped())
        .stdout(Stdio::piped())
        .stderr(Stdio::inherit())
        .spawn()
        .expect("start python");
    child
        .stdin
        .take()
        .unwrap()
        .write_all(input.as_bytes())
        .unwrap();
    let out = child.wait_with_output().expect("python ran");
    let stdout = String::from_utf8_lossy(&out.stdout);
    assert!(out.status.success(), "python failed:\n{stdout}");
    let failures: Vec<&str> = stdout.lines().filter(|l| l.starts_with("FAIL")).collect();
    assert!(failures.is_empty(), "{}", failures.join("\n"));
    assert!(
        stdout.contains(&format!("done {}", cases.len())),
        "python did not check every case:\n{stdout}"
    );
}

#[test]
fn replies_parse_back_to_themselves() {
    for c in cases() {
        let frame = c.reply.to_frame(c.cmd);
        assert_eq!(frame.cmd(), c.cmd);
        assert_eq!(
            Reply::parse(c.reply.kind(), &frame),
            Ok(c.reply.clone()),
            "{}",
            c.method
        );
    }
}
