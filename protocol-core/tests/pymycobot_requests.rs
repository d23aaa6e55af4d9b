//! Every request frame pymycobot 4.0.7's MyCobot280 sends (recorded by
//! `tools/record_pymycobot.py` into `tests/data/pymycobot_requests.txt`) is found by the frame
//! decoder, parses to the command the user called, and re-encodes byte for byte.

// Test code: a panic is a test failure with a message.
#![allow(clippy::unwrap_used, clippy::expect_used, clippy::indexing_slicing)]

use protocol_core::command::*;
use protocol_core::units::{Centideg, DeciMm, Decideg, SpeedPercent, Steps};
use protocol_core::{Frame, FrameDecoder};

const RECORDED: &str = include_str!("data/pymycobot_requests.txt");

/// (frame bytes, the pymycobot call that sent it)
fn recorded() -> Vec<(Vec<u8>, &'static str)> {
    RECORDED
        .lines()
        .filter(|l| !l.starts_with('#') && !l.trim().is_empty())
        .map(|l| {
            let (hex, call) = l.split_once(" | ").expect("line is `hex | call`");
            let bytes = hex
                .split_whitespace()
                .map(|h| u8::from_str_radix(h, 16).expect("hex byte"))
                .collect();
            (bytes, call.trim())
        })
        .collect()
}

fn j(n: u8) -> JointId {
    JointId::new(n).unwrap()
}
fn s(n: u8) -> ServoId {
    ServoId::new(n).unwrap()
}
fn sp(n: u8) -> SpeedPercent {
    SpeedPercent::new(n).unwrap()
}
fn deg6(v: [i16; 6]) -> [Centideg; 6] {
    v.map(Centideg)
}
fn pin(n: u8) -> AtomPin {
    AtomPin::new(n).unwrap()
}
fn gs(n: u8) -> GripperSpeed {
    GripperSpeed::new(n).unwrap()
}
fn gt(n: u8) -> GripperType {
    GripperType::new(n).unwrap()
}

const FE_FA: [i16; 6] = [-6, -2, 250, -130, 0, 0];
const A_MIN: [i16; 6] = [-16800, -14000, -15000, -15000, -15500, -18000];
const A_MAX: [i16; 6] = [16800, 14000, 15000, 15000, 16000, 18000];
const HOME: [i16; 6] = [1565, -634, 3042, -17560, -60, -8990];
const EDGE: [i16; 6] = [-2814, 2814, -700, -18000, 18000, -2];

/// What each recorded call must parse to (calls with several frames: the first one).
fn expected(call: &str) -> Option<Request> {
    use Request as R;
    Some(match call {
        "get_angles()" => R::GetAngles,
        "release_all_servos()" => R::ReleaseAllServos { undamped: None },
        "release_all_servos(1)" => R::ReleaseAllServos {
            undamped: Some(true),
        },
        "set_fresh_mode(1)" => R::SetFreshMode { fresh: true },
        "send_angle(1, -168, 1)" => R::SendAngle {
            joint: j(1),
            angle: Centideg(-16800),
            speed: sp(1),
        },
        "send_angle(2, -0.02, 50)" => R::SendAngle {
            joint: j(2),
            angle: Centideg(-2),
            speed: sp(50),
        },
        "send_angles([-168, -140, -150, -150, -155, -180], 100)" => R::SendAngles {
            angles: deg6(A_MIN),
            speed: sp(100),
        },
        "send_angles([-0.06, -0.02, 2.5, -1.3, 0, 0], 50)" => R::SendAngles {
            angles: deg6(FE_FA),
            speed: sp(50),
        },
        "get_coords()" => R::GetCoords,
        "send_coord(1, -0.6, 50)" => R::SendCoord {
            target: AxisValue::X(DeciMm(-6)),
            speed: sp(50),
        },
        "send_coord(4, -180, 100)" => R::SendCoord {
            target: AxisValue::Rx(Centideg(-18000)),
            speed: sp(100),
        },
        "send_coords([156.5, -63.4, 304.2, -175.6, -0.6, -89.9], 50)" => R::SendCoords {
            pose: Pose::from_array(HOME),
            speed: sp(50),
            mode: None,
        },
        "send_coords([-281.45, 281.45, -70, -180, 180, -0.02], 100, 0)" => R::SendCoords {
            pose: Pose::from_array(EDGE),
            speed: sp(100),
            mode: Some(MoveMode::Joint),
        },
        "send_coords([156.5, -63.4, 304.2, -175.6, -0.6, -89.9], 1, 1)" => R::SendCoords {
            pose: Pose::from_array(HOME),
            speed: sp(1),
            mode: Some(MoveMode::Linear),
        },
        "angles_to_coords([-0.06, -0.02, 2.5, -1.3, 0, 0])" => R::AnglesToCoords {
            angles: deg6(FE_FA),
        },
        "solve_inv_kinematics([156.5, -63.4, 304.2, -175.6, -0.6, -89.9], [-0.06, -0.02, 2.5, -1.3, 0, 0])" => {
            R::SolveIk {
                target: Pose::from_array(HOME),
                current: deg6(FE_FA),
            }
        }
        "is_in_position([-281.45, 281.45, -70, -180, 180, -0.02], 1)" => R::IsInPosition {
            target: PositionTarget::Coords(Pose::from_array(EDGE)),
        },
        "is_in_position([168, 140, 150, 150, 160, 180], 0)" => R::IsInPosition {
            target: PositionTarget::Angles(deg6(A_MAX)),
        },
        "jog_angle(6, 1, 100)" => R::JogAngle {
            joint: j(6),
            direction: Direction::Positive,
            speed: sp(100),
        },
        "jog_rpy(3, 0, 10)" => R::JogRpy {
            axis: RpyAxis::Yaw,
            direction: Direction::Negative,
            speed: sp(10),
        },
        "jog_coord(6, 1, 1)" => R::JogCoord {
            axis: Axis::Rz,
            direction: Direction::Positive,
            speed: sp(1),
        },
        "jog_increment_angle(1, -10.5, 50)" => R::JogIncrementAngle {
            joint: j(1),
            increment: Centideg(-1050),
            speed: sp(50),
        },
        "jog_increment_coord(1, -0.6, 50)" => R::JogIncrementCoord {
            increment: AxisValue::X(DeciMm(-6)),
            speed: sp(50),
        },
        "jog_increment_coord(4, 15, 20)" => R::JogIncrementCoord {
            increment: AxisValue::Rx(Centideg(1500)),
            speed: sp(20),
        },
        "set_encoder(7, 0, 1)" => R::SetEncoder {
            servo: s(7),
            encoder: Steps(0),
            speed: Some(sp(1)),
        },
        "set_encoder(6, 4096, 100)" => R::SetEncoder {
            servo: s(6),
            encoder: Steps(4096),
            speed: Some(sp(100)),
        },
        "get_encoder(7)" => R::GetEncoder { servo: s(7) },
        "set_encoders([0, 4096, 250, 1, 4094, 2048], 100)" => R::SetEncoders {
            encoders: [0, 4096, 250, 1, 4094, 2048].map(Steps),
            speed: sp(100),
        },
        "set_encoders_drag([2048, 0, 4096, 250, 254, 2000], [0, 6000, 250, 1, 100, 3000])" => {
            R::SetEncodersDrag {
                encoders: [2048, 0, 4096, 250, 254, 2000].map(Steps),
                speeds_steps_per_s: [0, 6000, 250, 1, 100, 3000],
            }
        }
        "get_joint_max_angle(6)" => R::GetJointMax { joint: j(6) },
        "set_joint_min(1, -168)" => R::SetJointMin {
            joint: j(1),
            limit: Decideg(-1680),
        },
        "set_joint_max(2, 140)" => R::SetJointMax {
            joint: j(2),
            limit: Decideg(1400),
        },
        "is_servo_enable(6)" => R::IsServoEnabled { servo: s(6) },
        "set_servo_data(1, 21, 10)" => R::SetServoData {
            servo: s(1),
            address: 21,
            value: ServoValue::Byte(10),
        },
        "set_servo_data(7, 42, 2048, 1)" => R::SetServoData {
            servo: s(7),
            address: 42,
            value: ServoValue::Word(2048),
        },
        "set_servo_data(2, 254, 250)" => R::SetServoData {
            servo: s(2),
            address: 254,
            value: ServoValue::Byte(250),
        },
        "get_servo_data(1, 56)" => R::GetServoData {
            servo: s(1),
            address: 56,
            width: None,
        },
        "get_servo_data(1, 56, 1)" => R::GetServoData {
            servo: s(1),
            address: 56,
            width: Some(DataWidth::Word),
        },
        "get_servo_data(2, 21, 0)" => R::GetServoData {
            servo: s(2),
            address: 21,
            width: Some(DataWidth::Byte),
        },
        "release_servo(1, 1)" => R::ReleaseServo {
            servo: s(1),
            undamped: Some(true),
        },
        "focus_all_servos()" => R::FocusServo {
            servo: ServoSelect::All,
        },
        "focus_servo(1)" => R::FocusServo {
            servo: ServoSelect::One(s(1)),
        },
        "backup_servo_params(254)" => R::BackupServoParams {
            servo: ServoSelect::All,
        },
        "restore_servo_params(6)" => R::RestoreServoParams {
            servo: ServoSelect::One(s(6)),
        },
        "set_pin_mode(39, 0)" => R::SetPinMode {
            pin: pin(39),
            mode: PinMode::Input,
        },
        "set_pin_mode(22, 2)" => R::SetPinMode {
            pin: pin(22),
            mode: PinMode::InputPullUp,
        },
        "set_digital_output(23, 1)" => R::SetDigitalOutput {
            pin: pin(23),
            high: true,
        },
        "get_digital_input(39)" => R::GetDigitalInput { pin: pin(39) },
        "set_pwm_output(33, 250, 255)" => R::SetPwmOutput {
            pin: pin(33),
            frequency_hz: 250,
            duty: 255,
        },
        "get_gripper_value(1)" => R::GetGripperValue {
            gripper: Some(gt(1)),
        },
        "set_gripper_state(0, 50)" => R::SetGripperState {
            state: GripperState::Open,
            speed: gs(50),
            model: GripperModel::Default,
        },
        "set_gripper_state(254, 0, 3, 1)" => R::SetGripperState {
            state: GripperState::Release,
            speed: gs(0),
            model: GripperModel::TypedTorque(gt(3), true),
        },
        "set_gripper_value(50, 80, 4)" => R::SetGripperValue {
            value: GripperValue::new(50).unwrap(),
            speed: gs(80),
            model: GripperModel::Typed(gt(4)),
        },
        "gripper_stop()" => R::SetGripperValue {
            value: GripperValue::new(0).unwrap(),
            speed: gs(0),
            model: GripperModel::TypedTorque(gt(1), true),
        },
        "set_color(255, 0, 254)" => R::SetColor {
            rgb: Rgb {
                r: 255,
                g: 0,
                b: 254,
            },
        },
        "set_HTS_gripper_torque(980)" => R::SetHtsGripperTorque { torque: 980 },
        "set_gripper_protect_current(500)" => R::SetGripperProtectCurrent { current: 500 },
        "set_tool_reference([0, 0, 100.5, 0, 0, -0.02])" => R::SetToolReference {
            pose: Pose::from_array([0, 0, 1005, 0, 0, -2]),
        },
        "set_world_reference([-281.45, 281.45, -70, -180, 180, -0.02])" => R::SetWorldReference {
            pose: Pose::from_array(EDGE),
        },
        "set_reference_frame(1)" => R::SetReferenceFrame {
            frame: ReferenceFrame::World,
        },
        "set_movement_type(1)" => R::SetMovementType {
            mode: MoveMode::Linear,
        },
        "set_end_type(1)" => R::SetEndType { end: EndType::Tool },
        "set_basic_output(5, 0)" => R::SetBasicOutput {
            pin: BasicOutputPin::new(5).unwrap(),
            high: false,
        },
        "get_basic_input(36)" => R::GetBasicInput {
            pin: BasicInputPin::new(36).unwrap(),
        },
        "set_transponder_mode(1)" => R::SetTransponderMode {
            mode: TransponderMode::Transparent,
        },
        "set_server_port(5001)" => R::SetServerPort { port: 5001 },
        "get_tof_distance()" => R::GetTofDistance,
        "drag_clear_record_data()" => R::DragClearRecordData,
        _ => return None,
    })
}

#[test]
fn every_recorded_request_parses_and_reencodes_identically() {
    let lines = recorded();
    assert!(lines.len() > 150, "recording has {} frames", lines.len());
    for (bytes, call) in &lines {
        let mut decoder = FrameDecoder::new();
        let mut frames: Vec<Frame> = Vec::new();
        decoder.feed(bytes, |f| frames.push(f));
        assert_eq!(frames.len(), 1, "{call}: decoder found {frames:?}");
        let frame = &frames[0];
        let request = Request::parse(frame).unwrap_or_else(|e| panic!("{call}: {e}"));
        assert_eq!(request.cmd(), frame.cmd(), "{call}");
        assert_eq!(
            request.to_frame().to_bytes().as_slice(),
            bytes.as_slice(),
            "{call}: re-encoded differently from {request:?}"
        );
    }
}

#[test]
fn recorded_calls_mean_what_the_user_asked() {
    let lines = recorded();
    let mut checked = 0;
    let mut seen = std::collections::HashSet::new();
    for (bytes, call) in &lines {
        if !seen.insert(*call) {
            continue; // the first frame of a call is the command itself
        }
        let Some(want) = expected(call) else { continue };
        let frame = Frame::new(bytes[3], &bytes[4..bytes.len() - 1]).unwrap();
        assert_eq!(Request::parse(&frame), Ok(want), "{call}");
        checked += 1;
    }
    assert!(
        checked >= 60,
        "only {checked} calls checked against expectations"
    );
}

#[test]
fn recorded_file_covers_every_command_pymycobot_uses() {
    let codes: std::collections::BTreeSet<u8> = recorded().iter().map(|(b, _)| b[3]).collect();
    // Every modelled command except the ones MyCobot280 4.0.7 has no method for (the older
    // speed commands, MyCobotBasic's PID and arc commands, and the collision settings of
    // pymycobot's closed-loop arms), and this firmware's own dialect command.
    let not_in_mycobot280 = [
        cmd::GET_SPEED,
        cmd::SET_SPEED,
        cmd::GET_SERVO_CURRENTS,
        cmd::SET_PID,
        cmd::GET_PID,
        cmd::MOVE_C_COORDS,
        cmd::MOVE_C_COORDS_FROM_HERE,
        cmd::SET_COLLISION_MODE,
        cmd::GET_COLLISION_MODE,
        cmd::SET_COLLISION_THRESHOLD,
        cmd::GET_COLLISION_THRESHOLDS,
        cmd::DIALECT,
    ];
    for code in cmd::ALL {
        if not_in_mycobot280.contains(&code) {
            continue;
        }
        assert!(codes.contains(&code), "no recorded request for {code:#04x}");
    }
}
