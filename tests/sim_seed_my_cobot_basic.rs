//! The vendor's Arduino library MyCobotBasic (elephantrobotics/MyCobotBasic, `MyCobotBasic.cpp`)
//! against a Basic that speaks the seed dialect (`BasicConfig::dialect`): every call of the
//! library that sends a request frame, its frame written here byte by byte on the Basic's USB
//! port as the library writes it (its LEN constants, high byte first), and for each what it
//! does to the arm and what comes back: the reply, with the LEN and layout the library's
//! `readData` parses, where the library reads one; nothing where it does not.
//!
//! **70 calls**, every function of `MyCobotBasic.cpp` that writes a frame (the six under
//! `#ifdef MyCobot_Pro_350` included; the `MyPalletizerBasic` class is not the 280's), in 72
//! layouts (`releaseServo` and `releaseAllServos` with and without their mode byte), and
//! `writeCoord` sent on all six axes:
//!
//! * power and status (9): `powerOn` 0x10, `powerOff` 0x11, `isPoweredOn` 0x12,
//!   `getAtomVersion` 0x02, `asynOrSync` 0x06, `isAllServoEnabled` 0x51, `releaseAllServos`
//!   0x13 (LEN 2, LEN 3), `isServoEnabled` 0x50, `focusServo` 0x57;
//! * angles (4): `getAngles` 0x20, `writeAngle` 0x21, `writeAngles` 0x22, `checkRunning` 0x2B;
//! * coordinates (5): `getCoords` 0x23, `writeCoord` 0x24 (axes 0..5), `writeCoords` 0x25,
//!   `moveCCoords` 0x8B and 0x8C;
//! * jog (2): `jogAngle` 0x30, `jogCoord` 0x32;
//! * pause and stop (4): `ProgramPause` 0x26, `ProgramResume` 0x28, `TaskStop` 0x29,
//!   `clearServoQueue` 0x05;
//! * encoders (6): `setEncoder` 0x3A, `getEncoder` 0x3B, `setEncoders` 0x3C, `getEncoders` 0x3D,
//!   `setEncodersDrag` 0x3E, `getServoSpeeds` 0xE1;
//! * servo data, PID, health (9): `setServoData` 0x52, `getServoData` 0x53, `setPid` 0x2C,
//!   `getPid` 0x2D, `getServoVoltages` 0xE3, `getServoStatus` 0xE4, `getServoTemps` 0xE5,
//!   `getServoCurrents` 0xE2, `getServoLastPDI` 0xE6;
//! * calibration and release (2): `setServoCalibration` 0x54, `releaseServo` 0x56 (LEN 3, 4);
//! * Atom IO and LED (5): `setLEDRGB` 0x6A, `setPinMode` 0x60, `setDigitalOutput` 0x61,
//!   `getDigitalInput` 0x62, `setPWMOutput` 0x64;
//! * gripper (13): `setGripperState` 0x66 (LEN 4, 5, 6: three calls), `setGripperValue` 0x67
//!   (LEN 4, 5, 6: three calls), `setGripperIni` 0x68, `getGripperValue` 0x65,
//!   `isGripperMoving` 0x69, `setEletricGripper` 0x6B, `InitEletricGripper` 0x6C,
//!   `setGripperMode` 0x6D, `getGripperMode` 0x6E;
//! * modes and coordinate frames (11): `setFreeMoveMode` 0x1A, `isFreeMoveMode` 0x1B,
//!   `setMovementType` 0x87, `getMovementType` 0x88, `setToolReference` 0x81,
//!   `getToolReference` 0x82, `setWorldReference` 0x83, `getWorldReference` 0x84,
//!   `setReferenceFrame` 0x85, `setEndType` 0x89, `getEndType` 0x8A.
//!
//! Beyond the 70: `getJointMin`/`getJointMax` (declared in `MyCobotBasic.h`, their bodies
//! commented out in the `.cpp`) and `setJointMin`/`setJointMax` (commented out in both), the
//! seed manual's 0x4A..0x4D, are checked too.
//!
//! Numbering: the library sends joint, servo and axis numbers as given. Where the seed dialect
//! numbers from 0 (0x21, 0x24, 0x3A, 0x3B, 0x4A..0x4D, 0x52, 0x53, 0x56) the calls get the
//! library's `Joint`/`Axis` enum values (`J1` = 0, `Axis::RZ` = 5); where the command keeps
//! pymycobot's numbering (0x30, 0x50 with a servo, 0x54, 0x57, 0xE6) they get 1..7, as the
//! library's own 280 examples pass them (`MiniRobot`: `isServoEnabled(7)` is the gripper,
//! `setServoCalibration(1..6)`, `focusServo(1..6)`); `J1` (0) there is refused, silently
//! (0x57 takes it as every servo). The same examples also pass 1..6 to `setEncoder`,
//! `getServoData` and `setServoData`, which the seed dialect reads as the next servo up: they
//! were written for pymycobot's numbering.
//!
//! What the seed dialect cannot get right by construction, asserted as it is:
//! * `ProgramResume` sends 0x28, the manual's stop: a paused move is forgotten, nothing moves;
//! * `releaseServo` sends 0x56, the manual's brake: the servo stops and keeps its torque; with
//!   the mode byte (LEN 4) it is no brake frame at all and does nothing;
//! * `setEletricGripper`, `InitEletricGripper`, `setGripperMode`, `getGripperMode` (0x6B..0x6E)
//!   and `getServoLastPDI` (0xE6), Pro-350-only calls, are commands this firmware does not
//!   have: nothing happens and nothing comes back (`getGripperMode` and `getServoLastPDI`
//!   time out in the library).
#![allow(clippy::unwrap_used, clippy::expect_used, clippy::indexing_slicing)] // a test harness: a panic is a failed check

mod sim_support;

use firmware_atom::AtomIo;
use firmware_atom::io::OUTPUT_PINS;
use firmware_basic::BasicConfig;
use open_mycobot::sim::{HostLink, RobotConfig, VirtualRobot, measure};
use protocol_core::command::{EndType, MoveMode, ReferenceFrame};
use protocol_core::dialect::Dialect;
use protocol_core::servo::reg;
use protocol_core::units::Centideg;
use sim_support::*;

const LINK: HostLink = HostLink::Basic;

/// How long the library waits for a reply, in us: `readSerial` sleeps 5 ms, then reads for
/// `IO_TimeOut` (70 ms).
const LIBRARY_READ_US: u64 = 75_000;

/// How long a call without a reply is watched for one, in us: the Atom answers any command in
/// a few milliseconds, so a reply the Basic should have dropped would be here.
const QUIET_US: u64 = 100_000;

/// The arm, its Basic speaking the seed dialect from boot.
fn seed_arm() -> VirtualRobot {
    booted(RobotConfig {
        basic: BasicConfig {
            dialect: Some(Dialect::Seed),
            ..BasicConfig::default()
        },
        ..RobotConfig::default()
    })
}

/// The calls of MyCobotBasic, one function each, named after the library's: each writes the
/// frame the library writes (its LEN constant from `CommunicateDefine.h`, values high byte
/// first) byte by byte, then either checks that nothing comes back (the library reads
/// nothing) or returns the data of the reply, checked to have the CMD and the LEN the
/// library's `readData` parses.
mod my_cobot_basic {
    use super::*;

    /// `FE FE LEN CMD DATA FA`, one byte at a time.
    pub fn write_frame(robot: &mut VirtualRobot, len: u8, cmd: u8, data: &[u8]) {
        assert_eq!(usize::from(len), data.len() + 2, "LEN of {cmd:#04x}");
        let mut bytes = vec![0xFE, 0xFE, len, cmd];
        bytes.extend_from_slice(data);
        bytes.push(0xFA);
        for byte in bytes {
            robot.link_write(LINK, &[byte]);
        }
    }

    /// A call the library reads no reply to: nothing comes back.
    fn unanswered(robot: &mut VirtualRobot, len: u8, cmd: u8, data: &[u8]) {
        write_frame(robot, len, cmd, data);
        assert_silent_for(robot, LINK, QUIET_US);
    }

    /// A call the library reads a reply to: the reply's data, its CMD and LEN as parsed.
    fn answered(robot: &mut VirtualRobot, len: u8, cmd: u8, data: &[u8], reply_len: u8) -> Vec<u8> {
        write_frame(robot, len, cmd, data);
        let reply = robot
            .await_frame(LINK, LIBRARY_READ_US)
            .unwrap_or_else(|| panic!("{cmd:#04x}: no reply within the library's wait"));
        let bytes = reply.to_bytes();
        assert_eq!(
            (bytes[2], bytes[3]),
            (reply_len, cmd),
            "{cmd:#04x}: reply {bytes:02x?}"
        );
        reply.data().to_vec()
    }

    fn be(v: i32) -> [u8; 2] {
        (v as i16).to_be_bytes()
    }

    /// An int16 as the library decodes one (`lo + hi * 256`, negative above 33000).
    pub fn int16(hi: u8, lo: u8) -> i32 {
        let t = i32::from(lo) + i32::from(hi) * 256;
        if t > 33000 { t - 65536 } else { t }
    }

    fn int16s(data: &[u8]) -> Vec<i32> {
        data.chunks(2).map(|c| int16(c[0], c[1])).collect()
    }

    /// A pose as the library writes it: x, y, z x 10, rx, ry, rz x 100.
    fn coords_bytes(c: [f64; 6]) -> Vec<u8> {
        c.iter()
            .enumerate()
            .flat_map(|(i, v)| be((v * if i < 3 { 10.0 } else { 100.0 }) as i32))
            .collect()
    }

    /// A pose as the library reads one (`getCoords`, `getToolReference`, ...).
    fn coords_of(data: &[u8]) -> [f64; 6] {
        let v = int16s(data);
        std::array::from_fn(|i| f64::from(v[i]) / if i < 3 { 10.0 } else { 100.0 })
    }

    fn six(data: &[u8]) -> [i32; 6] {
        let v = int16s(data);
        std::array::from_fn(|i| v[i])
    }

    // --- power and status ---

    pub fn power_on(r: &mut VirtualRobot) {
        unanswered(r, 2, 0x10, &[]);
    }
    pub fn power_off(r: &mut VirtualRobot) {
        unanswered(r, 2, 0x11, &[]);
    }
    pub fn is_powered_on(r: &mut VirtualRobot) -> bool {
        answered(r, 2, 0x12, &[], 3)[0] != 0
    }
    pub fn get_atom_version(r: &mut VirtualRobot) -> u8 {
        answered(r, 2, 0x02, &[], 3)[0]
    }
    pub fn asyn_or_sync(r: &mut VirtualRobot) -> bool {
        answered(r, 2, 0x06, &[], 3)[0] != 0
    }
    pub fn is_all_servo_enabled(r: &mut VirtualRobot) -> bool {
        answered(r, 2, 0x51, &[], 3)[0] != 0
    }
    /// `releaseAllServos(mode)`: LEN 2, or LEN 3 with the mode byte when `mode` is true.
    pub fn release_all_servos(r: &mut VirtualRobot, mode: bool) {
        if mode {
            unanswered(r, 3, 0x13, &[1]);
        } else {
            unanswered(r, 2, 0x13, &[]);
        }
    }
    /// `isServoEnabled(joint)`: the reply is `50 servo state` (LEN 4), the library takes the
    /// state.
    pub fn is_servo_enabled(r: &mut VirtualRobot, joint: u8) -> bool {
        let data = answered(r, 3, 0x50, &[joint], 4);
        assert_eq!(data[0], joint, "the servo asked");
        data[1] != 0
    }
    pub fn focus_servo(r: &mut VirtualRobot, servo_no: u8) {
        unanswered(r, 3, 0x57, &[servo_no]);
    }

    // --- angles ---

    pub fn get_angles(r: &mut VirtualRobot) -> [f64; 6] {
        six(&answered(r, 2, 0x20, &[], 14)).map(|v| f64::from(v) / 100.0)
    }
    pub fn write_angle(r: &mut VirtualRobot, joint: u8, value: f64, speed: u8) {
        let [hi, lo] = be((value * 100.0) as i32);
        unanswered(r, 6, 0x21, &[joint, hi, lo, speed]);
    }
    pub fn write_angles(r: &mut VirtualRobot, angles: [f64; 6], speed: u8) {
        let mut data: Vec<u8> = angles.iter().flat_map(|a| be((a * 100.0) as i32)).collect();
        data.push(speed);
        unanswered(r, 15, 0x22, &data);
    }
    pub fn check_running(r: &mut VirtualRobot) -> bool {
        answered(r, 2, 0x2B, &[], 3)[0] != 0
    }

    // --- coordinates ---

    pub fn get_coords(r: &mut VirtualRobot) -> [f64; 6] {
        coords_of(&answered(r, 2, 0x23, &[], 14))
    }
    /// `writeCoord(axis, value, speed)`: x, y, z x 10, rotations x 100.
    pub fn write_coord(r: &mut VirtualRobot, axis: u8, value: f64, speed: u8) {
        let scale = if axis < 3 { 10.0 } else { 100.0 };
        let [hi, lo] = be((value * scale) as i32);
        unanswered(r, 6, 0x24, &[axis, hi, lo, speed]);
    }
    pub fn write_coords(r: &mut VirtualRobot, coords: [f64; 6], speed: u8, mode: u8) {
        let mut data = coords_bytes(coords);
        data.extend([speed, mode]);
        unanswered(r, 16, 0x25, &data);
    }
    pub fn move_c_coords3(r: &mut VirtualRobot, begin: [f64; 6], middle: [f64; 6], end: [f64; 6]) {
        let data = [begin, middle, end].into_iter().flat_map(coords_bytes);
        unanswered(r, 38, 0x8B, &data.collect::<Vec<u8>>());
    }
    pub fn move_c_coords2(r: &mut VirtualRobot, middle: [f64; 6], end: [f64; 6]) {
        let data = [middle, end].into_iter().flat_map(coords_bytes);
        unanswered(r, 26, 0x8C, &data.collect::<Vec<u8>>());
    }

    // --- jog ---

    pub fn jog_angle(r: &mut VirtualRobot, joint: u8, direction: u8, speed: u8) {
        unanswered(r, 5, 0x30, &[joint, direction, speed]);
    }
    /// `jogCoord(axis, ...)` sends `axis + 1`.
    pub fn jog_coord(r: &mut VirtualRobot, axis: u8, direction: u8, speed: u8) {
        unanswered(r, 5, 0x32, &[axis + 1, direction, speed]);
    }

    // --- pause and stop ---

    pub fn program_pause(r: &mut VirtualRobot) {
        unanswered(r, 2, 0x26, &[]);
    }
    pub fn program_resume(r: &mut VirtualRobot) {
        unanswered(r, 2, 0x28, &[]);
    }
    pub fn task_stop(r: &mut VirtualRobot) {
        unanswered(r, 2, 0x29, &[]);
    }
    pub fn clear_servo_queue(r: &mut VirtualRobot) {
        unanswered(r, 2, 0x05, &[]);
    }

    // --- encoders ---

    pub fn set_encoder(r: &mut VirtualRobot, joint: u8, encoder: i32, speed: u8) {
        let [hi, lo] = be(encoder);
        unanswered(r, 6, 0x3A, &[joint, hi, lo, speed]);
    }
    pub fn get_encoder(r: &mut VirtualRobot, joint: u8) -> i32 {
        let data = answered(r, 3, 0x3B, &[joint], 4);
        int16(data[0], data[1])
    }
    pub fn set_encoders(r: &mut VirtualRobot, encoders: [i32; 6], speed: u8) {
        let mut data: Vec<u8> = encoders.into_iter().flat_map(be).collect();
        data.push(speed);
        unanswered(r, 15, 0x3C, &data);
    }
    pub fn get_encoders(r: &mut VirtualRobot) -> [i32; 6] {
        six(&answered(r, 2, 0x3D, &[], 14))
    }
    pub fn set_encoders_drag(r: &mut VirtualRobot, encoders: [i32; 6], speeds: [i32; 6]) {
        let data: Vec<u8> = encoders.into_iter().chain(speeds).flat_map(be).collect();
        unanswered(r, 26, 0x3E, &data);
    }
    /// `getServoSpeeds()`: the library reads these unsigned (`lo + hi * 256`, no sign), so a
    /// servo turning backwards at s steps/s reads 65536 - s.
    pub fn get_servo_speeds(r: &mut VirtualRobot) -> [i32; 6] {
        let data = answered(r, 2, 0xE1, &[], 14);
        std::array::from_fn(|i| i32::from(data[2 * i + 1]) + i32::from(data[2 * i]) * 256)
    }

    // --- servo data, PID, health ---

    pub fn set_servo_data(r: &mut VirtualRobot, servo_no: u8, servo_state: u8, servo_data: u8) {
        unanswered(r, 5, 0x52, &[servo_no, servo_state, servo_data]);
    }
    pub fn get_servo_data(r: &mut VirtualRobot, joint: u8, data_id: u8) -> u8 {
        answered(r, 4, 0x53, &[joint, data_id], 3)[0]
    }
    pub fn set_pid(r: &mut VirtualRobot, pids: [u8; 6]) {
        unanswered(r, 8, 0x2C, &pids);
    }
    pub fn get_pid(r: &mut VirtualRobot) -> Vec<u8> {
        answered(r, 2, 0x2D, &[], 8)
    }
    pub fn get_servo_voltages(r: &mut VirtualRobot) -> Vec<u8> {
        answered(r, 2, 0xE3, &[], 8)
    }
    pub fn get_servo_status(r: &mut VirtualRobot) -> Vec<u8> {
        answered(r, 2, 0xE4, &[], 8)
    }
    pub fn get_servo_temps(r: &mut VirtualRobot) -> Vec<u8> {
        answered(r, 2, 0xE5, &[], 8)
    }
    pub fn get_servo_currents(r: &mut VirtualRobot) -> [i32; 6] {
        six(&answered(r, 2, 0xE2, &[], 14))
    }
    /// `getServoLastPDI(joint)` (Pro 350): the library would read `E6 servo p d i` (LEN 6).
    pub fn get_servo_last_pdi_frame(r: &mut VirtualRobot, joint: u8) {
        write_frame(r, 3, 0xE6, &[joint]);
    }

    // --- calibration and release ---

    pub fn set_servo_calibration(r: &mut VirtualRobot, joint: u8) {
        unanswered(r, 3, 0x54, &[joint]);
    }
    /// `releaseServo(servo_no, mode)`: LEN 3, or LEN 4 with the mode byte when `mode` is true.
    pub fn release_servo(r: &mut VirtualRobot, servo_no: u8, mode: bool) {
        if mode {
            unanswered(r, 4, 0x56, &[servo_no, 1]);
        } else {
            unanswered(r, 3, 0x56, &[servo_no]);
        }
    }

    // --- Atom IO and LED ---

    pub fn set_led_rgb(r: &mut VirtualRobot, red: u8, green: u8, blue: u8) {
        unanswered(r, 5, 0x6A, &[red, green, blue]);
    }
    pub fn set_pin_mode(r: &mut VirtualRobot, pin_no: u8, pin_mode: u8) {
        unanswered(r, 4, 0x60, &[pin_no, pin_mode]);
    }
    pub fn set_digital_output(r: &mut VirtualRobot, pin_no: u8, pin_state: u8) {
        unanswered(r, 4, 0x61, &[pin_no, pin_state]);
    }
    /// `getDigitalInput(pin_no)`: the whole reply frame, whatever its LEN.
    pub fn get_digital_input_reply(r: &mut VirtualRobot, pin_no: u8) -> Vec<u8> {
        write_frame(r, 3, 0x62, &[pin_no]);
        r.await_frame(LINK, LIBRARY_READ_US)
            .expect("0x62: no reply")
            .to_bytes()
            .to_vec()
    }
    pub fn set_pwm_output(r: &mut VirtualRobot, pin_no: u8, freq: i32, pin_write: u8) {
        let [hi, lo] = be(freq);
        unanswered(r, 6, 0x64, &[pin_no, hi, lo, pin_write]);
    }

    // --- gripper ---

    /// `setGripperState(mode, sp)`: LEN 4.
    pub fn set_gripper_state(r: &mut VirtualRobot, mode: u8, sp: u8) {
        unanswered(r, 4, 0x66, &[mode, sp]);
    }
    /// `setGripperState(state, sp, type)`: LEN 5.
    pub fn set_gripper_state_typed(r: &mut VirtualRobot, state: u8, sp: u8, kind: u8) {
        unanswered(r, 5, 0x66, &[state, sp, kind]);
    }
    /// `setGripperState(state, sp, type, is_torque)`: LEN 6.
    pub fn set_gripper_state_torque(r: &mut VirtualRobot, state: u8, sp: u8, kind: u8, t: u8) {
        unanswered(r, 6, 0x66, &[state, sp, kind, t]);
    }
    /// `setGripperValue(data, sp)`: LEN 4.
    pub fn set_gripper_value(r: &mut VirtualRobot, data: u8, sp: u8) {
        unanswered(r, 4, 0x67, &[data, sp]);
    }
    /// `setGripperValue(value, sp, type)`: LEN 5.
    pub fn set_gripper_value_typed(r: &mut VirtualRobot, value: u8, sp: u8, kind: u8) {
        unanswered(r, 5, 0x67, &[value, sp, kind]);
    }
    /// `setGripperValue(value, sp, type, is_torque)`: LEN 6.
    pub fn set_gripper_value_torque(r: &mut VirtualRobot, value: u8, sp: u8, kind: u8, t: u8) {
        unanswered(r, 6, 0x67, &[value, sp, kind, t]);
    }
    pub fn set_gripper_ini(r: &mut VirtualRobot) {
        unanswered(r, 2, 0x68, &[]);
    }
    pub fn get_gripper_value(r: &mut VirtualRobot) -> u8 {
        answered(r, 2, 0x65, &[], 3)[0]
    }
    pub fn is_gripper_moving(r: &mut VirtualRobot) -> bool {
        answered(r, 2, 0x69, &[], 3)[0] != 0
    }
    pub fn set_eletric_gripper(r: &mut VirtualRobot, mode: u8) {
        unanswered(r, 3, 0x6B, &[mode]);
    }
    pub fn init_eletric_gripper(r: &mut VirtualRobot) {
        unanswered(r, 2, 0x6C, &[]);
    }
    pub fn set_gripper_mode(r: &mut VirtualRobot, mode: u8) {
        unanswered(r, 3, 0x6D, &[mode]);
    }
    /// `getGripperMode()` (Pro 350): the library would read `6E mode` (LEN 3).
    pub fn get_gripper_mode_frame(r: &mut VirtualRobot) {
        write_frame(r, 2, 0x6E, &[]);
    }

    // --- modes and coordinate frames ---

    pub fn set_free_move_mode(r: &mut VirtualRobot, mode: u8) {
        unanswered(r, 3, 0x1A, &[mode]);
    }
    pub fn is_free_move_mode(r: &mut VirtualRobot) -> bool {
        answered(r, 2, 0x1B, &[], 3)[0] != 0
    }
    pub fn set_movement_type(r: &mut VirtualRobot, movement_type: u8) {
        unanswered(r, 3, 0x87, &[movement_type]);
    }
    pub fn get_movement_type(r: &mut VirtualRobot) -> u8 {
        answered(r, 2, 0x88, &[], 3)[0]
    }
    pub fn set_tool_reference(r: &mut VirtualRobot, coords: [f64; 6]) {
        unanswered(r, 14, 0x81, &coords_bytes(coords));
    }
    pub fn get_tool_reference(r: &mut VirtualRobot) -> [f64; 6] {
        coords_of(&answered(r, 2, 0x82, &[], 14))
    }
    pub fn set_world_reference(r: &mut VirtualRobot, coords: [f64; 6]) {
        unanswered(r, 14, 0x83, &coords_bytes(coords));
    }
    pub fn get_world_reference(r: &mut VirtualRobot) -> [f64; 6] {
        coords_of(&answered(r, 2, 0x84, &[], 14))
    }
    pub fn set_reference_frame(r: &mut VirtualRobot, rftype: u8) {
        unanswered(r, 3, 0x85, &[rftype]);
    }
    pub fn set_end_type(r: &mut VirtualRobot, end_type: u8) {
        unanswered(r, 3, 0x89, &[end_type]);
    }
    pub fn get_end_type(r: &mut VirtualRobot) -> u8 {
        answered(r, 2, 0x8A, &[], 3)[0]
    }

    // --- beyond the 70: commented out in MyCobotBasic.cpp ---

    /// `getJointMin(joint)`: the reply is the int16 alone (LEN 4), in tenths of a degree.
    pub fn get_joint_min(r: &mut VirtualRobot, joint: u8) -> f64 {
        let data = answered(r, 3, 0x4A, &[joint], 4);
        f64::from(int16(data[0], data[1])) / 10.0
    }
    pub fn get_joint_max(r: &mut VirtualRobot, joint: u8) -> f64 {
        let data = answered(r, 3, 0x4B, &[joint], 4);
        f64::from(int16(data[0], data[1])) / 10.0
    }
    pub fn set_joint_min(r: &mut VirtualRobot, joint: u8, angle: f64) {
        let [hi, lo] = be((angle * 10.0) as i32);
        unanswered(r, 5, 0x4C, &[joint, hi, lo]);
    }
    pub fn set_joint_max(r: &mut VirtualRobot, joint: u8, angle: f64) {
        let [hi, lo] = be((angle * 10.0) as i32);
        unanswered(r, 5, 0x4D, &[joint, hi, lo]);
    }
}

use my_cobot_basic as lib;

/// The library's `enum Joint`.
const J1: u8 = 0;
const J2: u8 = 1;
const J3: u8 = 2;
/// The library's `enum Axis`.
const AXIS_Z: u8 = 2;

/// The joints' angles as the servos' shafts are, in degrees.
fn shafts(robot: &VirtualRobot) -> [f64; 6] {
    robot.shaft_angles_deg()
}

fn assert_near(actual: &[f64], expected: &[f64], tolerance: f64, what: &str) {
    for (i, (a, e)) in actual.iter().zip(expected).enumerate() {
        assert!(
            (a - e).abs() <= tolerance,
            "{what}: [{i}] is {a:.2}, expected {e:.2} (all: {actual:.2?})"
        );
    }
}

/// A rotation difference in degrees, in -180..180.
fn turn(a: f64, b: f64) -> f64 {
    (a - b + 540.0).rem_euclid(360.0) - 180.0
}

/// The arm with its joints at angles away from singularities (writeAngles).
fn posed() -> VirtualRobot {
    let mut robot = seed_arm();
    lib::write_angles(&mut robot, [10.0, -30.0, -50.0, -10.0, 10.0, 20.0], 100);
    wait_still(&mut robot);
    robot
}

#[test]
fn power_and_status_calls_answer_where_the_library_reads() {
    let mut robot = seed_arm();
    assert_eq!(lib::get_atom_version(&mut robot), 70);
    assert!(lib::asyn_or_sync(&mut robot), "1: asynchronous");
    assert!(lib::is_powered_on(&mut robot));
    assert!(lib::is_all_servo_enabled(&mut robot));

    lib::power_off(&mut robot);
    assert!(!robot.atom().is_powered());
    assert!(robot.servos().all(|s| !s.torque_enabled()), "all limp");
    assert!(!lib::is_powered_on(&mut robot));
    assert!(!lib::is_all_servo_enabled(&mut robot));
    lib::power_on(&mut robot);
    assert!(robot.servos().all(|s| s.torque_enabled()), "all holding");
    assert!(lib::is_powered_on(&mut robot));

    // isServoEnabled numbers servos as pymycobot does (1..7, 7 the gripper), as the library's
    // own examples do: the seed manual's 0x50 has no servo byte.
    lib::release_all_servos(&mut robot, false);
    assert!(robot.servos().all(|s| !s.torque_enabled()));
    assert!(!lib::is_servo_enabled(&mut robot, 1));
    assert!(!lib::is_all_servo_enabled(&mut robot));
    lib::focus_servo(&mut robot, 1);
    assert!(robot.servo(1).unwrap().torque_enabled());
    assert!(!robot.servo(2).unwrap().torque_enabled());
    assert!(lib::is_servo_enabled(&mut robot, 1));
    assert!(!lib::is_servo_enabled(&mut robot, 7));
    // 0 is no servo in that numbering: refused, and the seed dialect says nothing.
    lib::write_frame(&mut robot, 3, 0x50, &[0]);
    assert_silent_for(&mut robot, LINK, QUIET_US);

    lib::focus_servo(&mut robot, 7);
    lib::release_all_servos(&mut robot, true);
    assert!(robot.servos().all(|s| !s.torque_enabled()), "undamped");
    lib::power_on(&mut robot);
    assert!(lib::is_all_servo_enabled(&mut robot));
}

#[test]
fn write_angle_moves_the_joint_numbered_from_0_and_check_running_follows() {
    let mut robot = seed_arm();
    let targets = [20.0, -20.0, 25.0, -25.0, 30.0, -30.0];
    let mut expected = [0.0; 6];
    for (joint, target) in targets.into_iter().enumerate() {
        lib::write_angle(&mut robot, joint as u8, target, 60);
        assert!(lib::check_running(&mut robot), "J{} moving", joint + 1);
        wait_still(&mut robot);
        assert!(!lib::check_running(&mut robot));
        expected[joint] = target;
        assert_near(&shafts(&robot), &expected, 0.2, "writeAngle");
        assert_near(&lib::get_angles(&mut robot), &expected, 0.2, "getAngles");
    }
    let angles = [10.0, -30.0, -50.0, -10.0, 10.0, 20.0];
    lib::write_angles(&mut robot, angles, 80);
    assert!(lib::check_running(&mut robot));
    wait_still(&mut robot);
    assert_near(&lib::get_angles(&mut robot), &angles, 0.2, "writeAngles");
}

#[test]
fn write_coord_moves_the_axis_named_on_every_axis() {
    let mut robot = posed();
    let start = lib::get_coords(&mut robot);
    let flange = measure::flange(&shafts(&robot)).position_mm;
    assert_near(
        &start[..3],
        &flange,
        0.2,
        "getCoords is where the flange is",
    );
    // Axis::X .. Axis::RZ: 20 mm along x, y, z, then 5 degrees about rx, ry, rz, toward 0 so
    // that no rotation wraps.
    for axis in 0..6u8 {
        let i = usize::from(axis);
        let before = lib::get_coords(&mut robot);
        let step: f64 = if i < 3 { 20.0 } else { 5.0 };
        let target = before[i] - step.copysign(before[i]);
        lib::write_coord(&mut robot, axis, target, 30);
        wait_still(&mut robot);
        let after = lib::get_coords(&mut robot);
        for k in 0..6 {
            let (moved, tolerance) = if k < 3 {
                (after[k] - before[k], 0.5)
            } else {
                (turn(after[k], before[k]), 0.5)
            };
            let want = if k == i { target - before[k] } else { 0.0 };
            assert!(
                (moved - want).abs() <= tolerance,
                "writeCoord(axis {axis}): coordinate {k} moved {moved:.2}, expected {want:.2} \
                 ({before:.2?} -> {after:.2?})"
            );
        }
    }
}

#[test]
fn write_coords_and_both_arcs_reach_their_poses() {
    let mut robot = posed();
    let c = lib::get_coords(&mut robot);
    let offset = |dx: f64, dy: f64, dz: f64| [c[0] + dx, c[1] + dy, c[2] + dz, c[3], c[4], c[5]];
    let close = |p: &[f64; 3], q: &[f64; 6]| measure::distance_mm(p, &[q[0], q[1], q[2]]);
    let flange = |robot: &VirtualRobot| measure::flange(&robot.shaft_angles_deg()).position_mm;

    // writeCoords(coords, speed) with the library's default mode 1 (a line), then mode 0.
    let target = offset(-15.0, 15.0, 10.0);
    lib::write_coords(&mut robot, target, 50, 1);
    wait_still(&mut robot);
    assert!(close(&flange(&robot), &target) < 0.5, "writeCoords, linear");
    lib::write_coords(&mut robot, c, 50, 0);
    wait_still(&mut robot);
    assert!(close(&flange(&robot), &c) < 0.5, "writeCoords, joint");

    // moveCCoords(begin, middle, end) passes through all three.
    let (begin, middle, end) = (
        offset(-20.0, -20.0, 0.0),
        offset(-40.0, 20.0, 20.0),
        offset(-10.0, 50.0, 0.0),
    );
    lib::move_c_coords3(&mut robot, begin, middle, end);
    let mut passed = (f64::MAX, f64::MAX);
    while robot.atom().is_moving() {
        robot.run_for(1_000);
        let p = flange(&robot);
        passed = (
            passed.0.min(close(&p, &begin)),
            passed.1.min(close(&p, &middle)),
        );
    }
    robot.run_for(200_000);
    assert!(passed.0 < 0.5 && passed.1 < 0.5, "passed {passed:?} mm");
    assert!(close(&flange(&robot), &end) < 0.5);

    // moveCCoords(middle, end) from where the arm is.
    let (middle, end) = (offset(-25.0, 25.0, 10.0), c);
    lib::move_c_coords2(&mut robot, middle, end);
    let mut passed_middle = f64::MAX;
    while robot.atom().is_moving() {
        robot.run_for(1_000);
        passed_middle = passed_middle.min(close(&flange(&robot), &middle));
    }
    robot.run_for(200_000);
    assert!(passed_middle < 0.5, "{passed_middle} mm from the middle");
    assert!(close(&flange(&robot), &end) < 0.5);
}

#[test]
fn jog_angle_and_jog_coord_run_until_task_stop() {
    let mut robot = posed();
    // jogAngle(1, 1, 50): 0x30 numbers joints from 1 in the seed dialect too.
    let before = shafts(&robot);
    lib::jog_angle(&mut robot, 1, 1, 50);
    robot.run_for(400_000);
    lib::task_stop(&mut robot);
    wait_still(&mut robot);
    let after = shafts(&robot);
    assert!(
        after[0] - before[0] > 2.0,
        "J1 went up: {before:.2?} -> {after:.2?}"
    );
    assert_near(&after[1..], &before[1..], 0.2, "the other joints");
    robot.run_for(500_000);
    assert_near(&shafts(&robot), &after, 0.05, "stopped for good");

    // jogCoord(Axis::Z, 1, 50) sends axis 3: z goes up, x and y stay.
    let before = lib::get_coords(&mut robot);
    lib::jog_coord(&mut robot, AXIS_Z, 1, 50);
    robot.run_for(400_000);
    lib::task_stop(&mut robot);
    wait_still(&mut robot);
    let after = lib::get_coords(&mut robot);
    assert!(
        after[2] - before[2] > 2.0,
        "z went up: {before:.2?} -> {after:.2?}"
    );
    assert_near(&after[..2], &before[..2], 1.0, "x and y");
}

#[test]
fn program_pause_holds_program_resume_stops_and_task_stop_stops() {
    let mut robot = seed_arm();
    lib::write_angle(&mut robot, J1, 60.0, 20);
    robot.run_for(300_000);
    lib::program_pause(&mut robot);
    robot.run_for(300_000);
    let paused = shafts(&robot);
    assert!(
        paused[0] > 1.0 && paused[0] < 55.0,
        "paused on the way: {paused:.2?}"
    );
    robot.run_for(500_000);
    assert_near(&shafts(&robot), &paused, 0.05, "paused");

    // ProgramResume sends 0x28, the seed manual's stop: the paused move is forgotten.
    lib::program_resume(&mut robot);
    robot.run_for(1_000_000);
    assert_near(
        &shafts(&robot),
        &paused,
        0.05,
        "0x28 stops, it does not resume",
    );
    assert!(!lib::check_running(&mut robot));
    // Nothing is left to continue (0x27, the manual's continue, which the library never sends).
    lib::write_frame(&mut robot, 2, 0x27, &[]);
    assert_silent_for(&mut robot, LINK, 1_000_000);
    assert_near(
        &shafts(&robot),
        &paused,
        0.05,
        "nothing moves after the stop",
    );

    // TaskStop (0x29) stops a move on its way.
    lib::write_angle(&mut robot, J1, -40.0, 20);
    robot.run_for(400_000);
    lib::task_stop(&mut robot);
    wait_still(&mut robot);
    let stopped = shafts(&robot);
    assert!(
        stopped[0] < paused[0] - 1.0 && stopped[0] > -35.0,
        "stopped on the way: {stopped:.2?}"
    );
    assert!(!lib::check_running(&mut robot));
    robot.run_for(1_000_000);
    assert_near(&shafts(&robot), &stopped, 0.05, "stopped for good");

    // clearServoQueue (0x05) forgets the moves queued (queue mode: pymycobot's 0x16 0, which
    // the library does not send), the one running ends.
    lib::write_frame(&mut robot, 3, 0x16, &[0]);
    lib::write_frame(&mut robot, 6, 0x21, &[J2, 0x03, 0xE8, 30]); // writeAngle(J2, 10, 30)
    lib::write_frame(&mut robot, 6, 0x21, &[J2, 0x0B, 0xB8, 30]); // writeAngle(J2, 30, 30)
    lib::clear_servo_queue(&mut robot);
    wait_still(&mut robot);
    assert!(
        (shafts(&robot)[1] - 10.0).abs() < 0.2,
        "the queued 30 degrees never ran: {:.2?}",
        shafts(&robot)
    );
}

#[test]
fn encoders_are_set_and_read_per_servo_numbered_from_0() {
    let mut robot = seed_arm();
    // setEncoder(J3, 1948, 50): servo 3.
    lib::set_encoder(&mut robot, J3, 1948, 50);
    wait_still(&mut robot);
    let present: Vec<i32> = (1..=7)
        .map(|id| i32::from(robot.servo(id).unwrap().present_position()))
        .collect();
    assert_near(
        &present.iter().map(|&p| f64::from(p)).collect::<Vec<_>>(),
        &[2048.0, 2048.0, 1948.0, 2048.0, 2048.0, 2048.0, 2048.0],
        2.0,
        "setEncoder moved servo 3 alone",
    );
    assert_eq!(lib::get_encoder(&mut robot, J3), present[2]);
    assert_eq!(lib::get_encoder(&mut robot, J1), present[0]);
    // 6 is the gripper.
    assert_eq!(lib::get_encoder(&mut robot, 6), present[6]);

    let goal = [2148, 1948, 2148, 1948, 2148, 1948];
    lib::set_encoders(&mut robot, goal, 50);
    wait_still(&mut robot);
    let read = lib::get_encoders(&mut robot);
    for (r, g) in read.iter().zip(goal) {
        assert!((r - g).abs() <= 2, "getEncoders {read:?}, goal {goal:?}");
    }
    assert_eq!(read, robot.atom().present_steps().map(|s| i32::from(s.0)));

    // setEncodersDrag: each servo at its own speed; getServoSpeeds sees them move.
    let back = [2048; 6];
    lib::set_encoders_drag(&mut robot, back, [600; 6]);
    robot.run_for(50_000);
    let speeds = lib::get_servo_speeds(&mut robot);
    assert!(speeds.iter().all(|&s| s != 0), "moving: {speeds:?}");
    wait_still(&mut robot);
    assert_eq!(lib::get_servo_speeds(&mut robot), [0; 6]);
    for (r, g) in lib::get_encoders(&mut robot).iter().zip(back) {
        assert!((r - g).abs() <= 2, "setEncodersDrag");
    }
}

#[test]
fn servo_data_pid_and_health_reads_have_the_library_lengths() {
    let mut robot = seed_arm();
    // setServoData(0, 21, 25): servo 1's P gain (register 21); servo 2's is unchanged.
    let p2 = robot.servo(2).unwrap().reg(reg::P_COEFFICIENT);
    lib::set_servo_data(&mut robot, J1, reg::P_COEFFICIENT, 25);
    robot.run_for(100_000);
    assert_eq!(robot.servo(1).unwrap().reg(reg::P_COEFFICIENT), 25);
    assert_eq!(robot.servo(2).unwrap().reg(reg::P_COEFFICIENT), p2);
    assert_eq!(lib::get_servo_data(&mut robot, J1, reg::P_COEFFICIENT), 25);
    assert_eq!(lib::get_servo_data(&mut robot, J2, reg::P_COEFFICIENT), p2);
    // 6 is the gripper.
    let gripper_p = robot.servo(7).unwrap().reg(reg::P_COEFFICIENT);
    assert_eq!(
        lib::get_servo_data(&mut robot, 6, reg::P_COEFFICIENT),
        gripper_p
    );

    // setPid / getPid: P, I, D of joints 1..3, then of joints 4..6.
    let pids = [20, 0, 3, 30, 2, 10];
    lib::set_pid(&mut robot, pids);
    robot.run_for(100_000);
    for id in 1..=6u8 {
        let servo = robot.servo(id).unwrap();
        let want = if id <= 3 { [20, 3, 0] } else { [30, 10, 2] };
        let got = [
            servo.reg(reg::P_COEFFICIENT),
            servo.reg(reg::D_COEFFICIENT),
            servo.reg(reg::I_COEFFICIENT),
        ];
        assert_eq!(got, want, "servo {id}: P, D, I");
    }
    assert_eq!(lib::get_pid(&mut robot), pids);

    let volts = lib::get_servo_voltages(&mut robot);
    assert!(
        volts.iter().all(|&v| v > 50),
        "{volts:?} (tenths of a volt)"
    );
    assert_eq!(lib::get_servo_status(&mut robot), [0; 6]);
    let temps = lib::get_servo_temps(&mut robot);
    assert!(temps.iter().all(|&t| (10..=80).contains(&t)), "{temps:?}");
    let currents = lib::get_servo_currents(&mut robot);
    assert!(currents.iter().all(|&c| c >= 0), "{currents:?}");

    // getServoLastPDI (Pro 350, 0xE6) is no command of this firmware: nothing comes back.
    lib::get_servo_last_pdi_frame(&mut robot, 1);
    assert_silent_for(&mut robot, LINK, LIBRARY_READ_US);
}

#[test]
fn set_servo_calibration_zeroes_the_servo_and_release_servo_brakes() {
    let mut robot = seed_arm();
    lib::write_angle(&mut robot, J1, 10.0, 50);
    wait_still(&mut robot);
    let turned = robot.servo(1).unwrap().present_position();
    assert!(turned > 2048 + 100, "{turned}");
    // setServoCalibration sends 0x54, pymycobot's calibration (the manual's zero is 0x55), so
    // servos are numbered from 1, as the library's own Calibration example does: J1 (0) is
    // refused, silently, and 1 is servo 1.
    lib::set_servo_calibration(&mut robot, J1);
    robot.run_for(100_000);
    assert_eq!(robot.servo(1).unwrap().present_position(), turned);
    lib::set_servo_calibration(&mut robot, 1);
    robot.run_for(100_000);
    let zeroed = robot.servo(1).unwrap().present_position();
    assert!(zeroed.abs_diff(2048) <= 1, "{zeroed}");
    assert!(lib::get_angles(&mut robot)[0].abs() < 0.2);

    // releaseServo sends 0x56, the seed manual's brake (servo numbered from 0): joint 1 stops
    // on its way and keeps its torque.
    lib::write_angle(&mut robot, J1, 40.0, 20);
    robot.run_for(300_000);
    lib::release_servo(&mut robot, J1, false);
    wait_still(&mut robot);
    let braked = shafts(&robot)[0];
    assert!(
        braked > 1.0 && braked < 35.0,
        "braked on the way: {braked:.2}"
    );
    assert!(
        robot.servo(1).unwrap().torque_enabled(),
        "braked, not released"
    );
    robot.run_for(500_000);
    assert!((shafts(&robot)[0] - braked).abs() < 0.05, "held");
    // With the mode byte (LEN 4) it is no brake frame: refused, nothing happens.
    lib::release_servo(&mut robot, J1, true);
    assert!(robot.servos().all(|s| s.torque_enabled()));
}

#[test]
fn atom_led_and_pins_do_what_the_library_says() {
    let mut robot = seed_arm();
    lib::set_led_rgb(&mut robot, 0, 0, 255);
    assert_eq!(robot.atom_io().rgb, (0, 0, 255));

    lib::set_pin_mode(&mut robot, 23, 1);
    lib::set_digital_output(&mut robot, 23, 1);
    assert_eq!(robot.atom_io_mut().read_pin(23), Some(true));
    lib::set_digital_output(&mut robot, 23, 0);
    assert_eq!(robot.atom_io_mut().read_pin(23), Some(false));

    lib::set_pwm_output(&mut robot, 22, 1000, 128);
    let slot = OUTPUT_PINS.iter().position(|&p| p == 22).unwrap();
    assert_eq!(robot.atom_io().pwm[slot], Some((1000, 128)));

    // getDigitalInput (0x62, not in the seed manual): the level alone (LEN 3), as the library
    // parses it.
    lib::set_pin_mode(&mut robot, 19, 0);
    assert!(robot.atom_io_mut().set_input(19, true));
    assert_eq!(
        lib::get_digital_input_reply(&mut robot, 19),
        [0xFE, 0xFE, 0x03, 0x62, 1, 0xFA]
    );
}

#[test]
fn gripper_calls_move_the_gripper_and_read_it_back() {
    let mut robot = seed_arm();
    // setGripperValue(data, sp): LEN 4.
    lib::set_gripper_value(&mut robot, 100, 30);
    robot.run_for(20_000);
    assert!(lib::is_gripper_moving(&mut robot));
    settle_gripper(&mut robot);
    assert!(!lib::is_gripper_moving(&mut robot));
    assert!(lib::get_gripper_value(&mut robot) >= 98);
    let value = |robot: &VirtualRobot| robot.atom().gripper_value();

    // setGripperState(mode, sp): 1 closes, 0 opens.
    lib::set_gripper_state(&mut robot, 1, 80);
    settle_gripper(&mut robot);
    assert!(value(&robot) <= 2, "closed: {}", value(&robot));
    assert!(lib::get_gripper_value(&mut robot) <= 2);
    // setGripperState(state, sp, type) and (state, sp, type, is_torque).
    lib::set_gripper_state_typed(&mut robot, 0, 80, 1);
    settle_gripper(&mut robot);
    assert!(value(&robot) >= 98, "open: {}", value(&robot));
    lib::set_gripper_state_torque(&mut robot, 1, 80, 1, 0);
    settle_gripper(&mut robot);
    assert!(value(&robot) <= 2, "closed: {}", value(&robot));
    // setGripperValue(value, sp, type) and (value, sp, type, is_torque).
    lib::set_gripper_value_typed(&mut robot, 50, 80, 1);
    settle_gripper(&mut robot);
    assert!(value(&robot).abs_diff(50) <= 2, "{}", value(&robot));
    lib::set_gripper_value_torque(&mut robot, 30, 80, 1, 1);
    settle_gripper(&mut robot);
    assert!(value(&robot).abs_diff(30) <= 2, "{}", value(&robot));
    assert!(lib::get_gripper_value(&mut robot).abs_diff(30) <= 2);

    // setGripperIni (0x68): where the gripper is becomes its zero (2048).
    assert!(robot.servo(7).unwrap().present_position().abs_diff(2048) > 20);
    lib::set_gripper_ini(&mut robot);
    robot.run_for(100_000);
    let zeroed = robot.servo(7).unwrap().present_position();
    assert!(zeroed.abs_diff(2048) <= 1, "{zeroed}");

    // The Pro 350's electric gripper and gripper mode (0x6B..0x6E) are no commands of this
    // firmware: nothing moves and nothing comes back, getGripperMode's reply included.
    let goal = robot.servo(7).unwrap().goal_position();
    lib::set_eletric_gripper(&mut robot, 1);
    lib::init_eletric_gripper(&mut robot);
    lib::set_gripper_mode(&mut robot, 1);
    lib::get_gripper_mode_frame(&mut robot);
    assert_silent_for(&mut robot, LINK, LIBRARY_READ_US);
    robot.run_for(300_000);
    assert_eq!(robot.servo(7).unwrap().goal_position(), goal);
    assert!(!robot.servo(7).unwrap().is_moving());
}

#[test]
fn modes_and_coordinate_frames_are_set_and_read_back() {
    let mut robot = posed();
    lib::set_free_move_mode(&mut robot, 1);
    assert!(lib::is_free_move_mode(&mut robot));
    lib::set_free_move_mode(&mut robot, 0);
    assert!(!lib::is_free_move_mode(&mut robot));

    // MovementType: MOVEJ = 0, MOVEL = 1.
    lib::set_movement_type(&mut robot, 1);
    assert_eq!(lib::get_movement_type(&mut robot), 1);
    assert_eq!(robot.atom().cartesian().movement(), MoveMode::Linear);
    lib::set_movement_type(&mut robot, 0);
    assert_eq!(lib::get_movement_type(&mut robot), 0);

    let flange = lib::get_coords(&mut robot);
    // A tool 100 mm out along the flange's z; EndType::TOOL = 1 reports its tip.
    let tool = [0.0, 0.0, 100.0, 0.0, 0.0, 0.0];
    lib::set_tool_reference(&mut robot, tool);
    assert_eq!(lib::get_tool_reference(&mut robot), tool);
    lib::set_end_type(&mut robot, 1);
    assert_eq!(lib::get_end_type(&mut robot), 1);
    assert_eq!(robot.atom().cartesian().end(), EndType::Tool);
    let tip = lib::get_coords(&mut robot);
    let reach = measure::distance_mm(
        &[tip[0], tip[1], tip[2]],
        &[flange[0], flange[1], flange[2]],
    );
    assert!((reach - 100.0).abs() < 0.3, "the tip is {reach:.2} mm out");
    lib::set_end_type(&mut robot, 0);
    assert_eq!(lib::get_end_type(&mut robot), 0);
    assert_near(
        &lib::get_coords(&mut robot),
        &flange,
        0.1,
        "the flange again",
    );

    // The base 100 mm along the world's x; RFType::WORLD = 1 reports in the world.
    let world = [100.0, 0.0, 0.0, 0.0, 0.0, 0.0];
    lib::set_world_reference(&mut robot, world);
    assert_eq!(lib::get_world_reference(&mut robot), world);
    lib::set_reference_frame(&mut robot, 1);
    assert_eq!(robot.atom().cartesian().reference(), ReferenceFrame::World);
    let in_world = lib::get_coords(&mut robot);
    assert!(
        (in_world[0] - flange[0] - 100.0).abs() < 0.3,
        "{flange:.2?} -> {in_world:.2?}"
    );
    lib::set_reference_frame(&mut robot, 0);
    assert_near(
        &lib::get_coords(&mut robot),
        &flange,
        0.1,
        "the base frame again",
    );
}

/// Beyond the 70: the joint-limit calls the library has commented out, the manual's 0x4A..0x4D.
#[test]
fn joint_limits_are_numbered_from_0_and_read_as_the_value_alone() {
    let mut robot = seed_arm();
    let limits = *robot.atom().joint_limits();
    for joint in 0..6u8 {
        let l = limits[usize::from(joint)];
        let min = lib::get_joint_min(&mut robot, joint);
        let max = lib::get_joint_max(&mut robot, joint);
        assert_eq!(
            (min, max),
            (
                f64::from(l.min.0 / 10) / 10.0,
                f64::from(l.max.0 / 10) / 10.0
            ),
            "J{}",
            joint + 1
        );
    }
    lib::set_joint_min(&mut robot, J2, -90.0);
    lib::set_joint_max(&mut robot, J2, 90.0);
    assert_eq!(lib::get_joint_min(&mut robot, J2), -90.0);
    assert_eq!(lib::get_joint_max(&mut robot, J2), 90.0);
    assert_eq!(robot.atom().joint_limits()[1].min, Centideg(-9000));
    // A move past the new limit is refused: joint 2 stays.
    lib::write_angle(&mut robot, J2, 100.0, 50);
    wait_still(&mut robot);
    assert!(shafts(&robot)[1].abs() < 0.2);
}
