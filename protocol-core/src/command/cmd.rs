/// Get modify (patch) version: 1 byte.
pub const GET_MODIFY_VERSION: u8 = 0x01;
/// Get system version: 1 byte, version x 10 (`SOFTWARE_VERSION`).
pub const GET_SYSTEM_VERSION: u8 = 0x02;
/// Clear the motion queue (`CLEAR_COMMAND_QUEUE`).
pub const CLEAR_QUEUE: u8 = 0x05;
/// Check async or sync: 1 byte.
pub const CHECK_ASYNC_OR_SYNC: u8 = 0x06;
/// Get error information: 1 byte [`ErrorCode`](super::ErrorCode).
pub const GET_ERROR_INFO: u8 = 0x07;
/// Clear error information.
pub const CLEAR_ERROR_INFO: u8 = 0x08;
/// Power on: torque on, servos ready.
pub const POWER_ON: u8 = 0x10;
/// Power off.
pub const POWER_OFF: u8 = 0x11;
/// Is powered on: 1 byte.
pub const IS_POWER_ON: u8 = 0x12;
/// Release all servos (torque off), optional undamped flag.
pub const RELEASE_ALL_SERVOS: u8 = 0x13;
/// Is controller connected: 1 byte.
pub const IS_CONTROLLER_CONNECTED: u8 = 0x14;
/// Read next error: 7 bytes of [`ServoErrorCode`](super::ServoErrorCode).
pub const READ_NEXT_ERROR: u8 = 0x15;
/// Set fresh mode (1 newest command preempts, 0 queue).
pub const SET_FRESH_MODE: u8 = 0x16;
/// Get fresh mode: 1 byte.
pub const GET_FRESH_MODE: u8 = 0x17;
/// Set free mode.
pub const SET_FREE_MODE: u8 = 0x1A;
/// Is free mode: 1 byte.
pub const IS_FREE_MODE: u8 = 0x1B;
/// Set vision mode.
pub const SET_VISION_MODE: u8 = 0x1D;
/// Get angles: 6 x int16 centidegrees.
pub const GET_ANGLES: u8 = 0x20;
/// Send one joint angle.
pub const SEND_ANGLE: u8 = 0x21;
/// Send six joint angles.
pub const SEND_ANGLES: u8 = 0x22;
/// Get coords (LEN 2) / angles to coords (LEN 0x0E).
pub const GET_COORDS: u8 = 0x23;
/// Send one coordinate.
pub const SEND_COORD: u8 = 0x24;
/// Send a pose.
pub const SEND_COORDS: u8 = 0x25;
/// Pause motion.
pub const PAUSE: u8 = 0x26;
/// Is paused: 1 byte.
pub const IS_PAUSED: u8 = 0x27;
/// Resume motion.
pub const RESUME: u8 = 0x28;
/// Stop motion.
pub const STOP: u8 = 0x29;
/// Is in position: 1 byte.
pub const IS_IN_POSITION: u8 = 0x2A;
/// Is moving: 1 byte.
pub const IS_MOVING: u8 = 0x2B;
/// Set the position-loop gains (MyCobotBasic `setPid`, `SET_PID`): six bytes, P, I, D of
/// joints 1..3 then of joints 4..6.
pub const SET_PID: u8 = 0x2C;
/// Get the position-loop gains (MyCobotBasic `getPid`, `GET_PID`): six bytes as 0x2C.
pub const GET_PID: u8 = 0x2D;
/// Jog one joint.
pub const JOG_ANGLE: u8 = 0x30;
/// Jog rotation about a base axis (`JOG_ABSOLUTE` in pymycobot).
pub const JOG_RPY: u8 = 0x31;
/// Jog along / about a Cartesian axis.
pub const JOG_COORD: u8 = 0x32;
/// Jog one joint by an increment (`JOG_INCREMENT`).
pub const JOG_INCREMENT_ANGLE: u8 = 0x33;
/// Jog stop (LEN 2) / jog increment coord (LEN 6).
pub const JOG_INCREMENT_COORD: u8 = 0x34;
/// Jog stop: the LEN-2 form of 0x34.
pub const JOG_STOP: u8 = 0x34;
/// Set HTS gripper torque (`SetHTSGripperTorque`).
pub const SET_HTS_GRIPPER_TORQUE: u8 = 0x35;
/// Get HTS gripper torque: int16.
pub const GET_HTS_GRIPPER_TORQUE: u8 = 0x36;
/// Get gripper protect current: int16.
pub const GET_GRIPPER_PROTECT_CURRENT: u8 = 0x37;
/// Init gripper.
pub const INIT_GRIPPER: u8 = 0x38;
/// Set gripper protect current.
pub const SET_GRIPPER_PROTECT_CURRENT: u8 = 0x39;
/// Set one servo's encoder.
pub const SET_ENCODER: u8 = 0x3A;
/// Get one servo's encoder: int16.
pub const GET_ENCODER: u8 = 0x3B;
/// Set six encoders.
pub const SET_ENCODERS: u8 = 0x3C;
/// Get six encoders: 6 x int16.
pub const GET_ENCODERS: u8 = 0x3D;
/// Set six encoders with per-servo speeds.
pub const SET_ENCODERS_DRAG: u8 = 0x3E;
/// Get speed (older clients): 1 byte.
pub const GET_SPEED: u8 = 0x40;
/// Set speed (older clients).
pub const SET_SPEED: u8 = 0x41;
/// Get joint min limit: joint, int16 decidegrees (`GET_JOINT_MIN_ANGLE`).
pub const GET_JOINT_MIN: u8 = 0x4A;
/// Get joint max limit: joint, int16 decidegrees (`GET_JOINT_MAX_ANGLE`).
pub const GET_JOINT_MAX: u8 = 0x4B;
/// Set joint min limit.
pub const SET_JOINT_MIN: u8 = 0x4C;
/// Set joint max limit.
pub const SET_JOINT_MAX: u8 = 0x4D;
/// Is servo enabled: servo, state (`IS_SERVO_ENABLE`).
pub const IS_SERVO_ENABLED: u8 = 0x50;
/// Are all servos enabled: 1 byte (`IS_ALL_SERVO_ENABLE`).
pub const ARE_ALL_SERVOS_ENABLED: u8 = 0x51;
/// Write a servo register.
pub const SET_SERVO_DATA: u8 = 0x52;
/// Read a servo register: 1 byte or int16.
pub const GET_SERVO_DATA: u8 = 0x53;
/// Make a servo's current position its zero (2048).
pub const SET_SERVO_CALIBRATION: u8 = 0x54;
/// Brake one joint.
pub const JOINT_BRAKE: u8 = 0x55;
/// Release one servo (torque off).
pub const RELEASE_SERVO: u8 = 0x56;
/// Focus servo (torque on); 0 = all.
pub const FOCUS_SERVO: u8 = 0x57;
/// Set an Atom pin's mode.
pub const SET_PIN_MODE: u8 = 0x60;
/// Set an Atom digital output.
pub const SET_DIGITAL_OUTPUT: u8 = 0x61;
/// Get an Atom digital input: pin, level.
pub const GET_DIGITAL_INPUT: u8 = 0x62;
/// Set an Atom PWM output.
pub const SET_PWM_OUTPUT: u8 = 0x64;
/// Get gripper value: 1 byte 0..100.
pub const GET_GRIPPER_VALUE: u8 = 0x65;
/// Set gripper state (open / close / release).
pub const SET_GRIPPER_STATE: u8 = 0x66;
/// Set gripper opening.
pub const SET_GRIPPER_VALUE: u8 = 0x67;
/// Calibrate the gripper (current position = zero).
pub const SET_GRIPPER_CALIBRATION: u8 = 0x68;
/// Is gripper moving: 1 byte.
pub const IS_GRIPPER_MOVING: u8 = 0x69;
/// Set the Atom LED colour (`SET_COLOR`).
pub const SET_COLOR: u8 = 0x6A;
/// Set tool reference (tool pose in the flange frame).
pub const SET_TOOL_REFERENCE: u8 = 0x81;
/// Get tool reference: 6 x int16.
pub const GET_TOOL_REFERENCE: u8 = 0x82;
/// Set world reference (base pose in the world frame).
pub const SET_WORLD_REFERENCE: u8 = 0x83;
/// Get world reference: 6 x int16.
pub const GET_WORLD_REFERENCE: u8 = 0x84;
/// Set reference frame (0 base, 1 world).
pub const SET_REFERENCE_FRAME: u8 = 0x85;
/// Get reference frame: 1 byte.
pub const GET_REFERENCE_FRAME: u8 = 0x86;
/// Set movement type (0 joint, 1 linear).
pub const SET_MOVEMENT_TYPE: u8 = 0x87;
/// Get movement type: 1 byte.
pub const GET_MOVEMENT_TYPE: u8 = 0x88;
/// Set end type (0 flange, 1 tool).
pub const SET_END_TYPE: u8 = 0x89;
/// Get end type: 1 byte.
pub const GET_END_TYPE: u8 = 0x8A;
/// Circular arc through three poses: begin, middle, end (MyCobotBasic `moveCCoords` with
/// three poses, `MOVEC_COORDS_DEFAULT`).
pub const MOVE_C_COORDS: u8 = 0x8B;
/// Circular arc from the present pose through middle to end (MyCobotBasic `moveCCoords`
/// with two poses, `MOVEC_COORDS`).
pub const MOVE_C_COORDS_FROM_HERE: u8 = 0x8C;
/// Solve inverse kinematics: 6 x int16 angles.
pub const SOLVE_INV_KINEMATICS: u8 = 0x8D;
/// Set a Basic output (answered by the Basic).
pub const SET_BASIC_OUTPUT: u8 = 0xA0;
/// Get a Basic input: pin, level (answered by the Basic).
pub const GET_BASIC_INPUT: u8 = 0xA1;
/// Set Wi-Fi SSID and password (answered by the Basic).
pub const SET_SSID_PWD: u8 = 0xB0;
/// Get Wi-Fi SSID and password (answered by the Basic).
pub const GET_SSID_PWD: u8 = 0xB1;
/// Set the server port (answered by the Basic).
pub const SET_SERVER_PORT: u8 = 0xB2;
/// Get ToF distance: int16 mm (answered by the Basic).
pub const GET_TOF_DISTANCE: u8 = 0xC0;
/// Get Basic version: 1 byte, version x 10 (answered by the Basic).
pub const GET_BASIC_VERSION: u8 = 0xC1;
/// Set transponder mode (answered by the Basic; `SET_COMMUNICATE_MODE`).
pub const SET_TRANSPONDER_MODE: u8 = 0xC2;
/// Get transponder mode: 1 byte (answered by the Basic; `GET_COMMUNICATE_MODE`).
pub const GET_TRANSPONDER_MODE: u8 = 0xC3;
/// The protocol dialect (this firmware's own, answered by the Basic in both dialects): LEN 2
/// asks, LEN 3 sets (1 pymycobot, 2 seed); 1 byte, the dialect in force.
pub const DIALECT: u8 = 0xC5;
/// Move round (pymycobot `move_round`, `SET_GSERVO_ROUND`): one turn of the 9 g hobby
/// servo of the Connect-4 kit's piece dispenser (no data).
pub const MOVE_ROUND: u8 = 0xD4;
/// Get angles and coords: 12 x int16.
pub const GET_ANGLES_COORDS: u8 = 0xD5;
/// Set four pieces zero (pymycobot `set_four_pieces_zero`): the Connect-4 ("four pieces")
/// dispenser servo back to its rest position; 1 byte.
pub const SET_FOUR_PIECES_ZERO: u8 = 0xD7;
/// Get reboot count: int16.
pub const GET_REBOOT_COUNT: u8 = 0xD8;
/// Get servo speeds: 6 x int16 steps/s (`GET_SERVO_SPEED`).
pub const GET_SERVO_SPEEDS: u8 = 0xE1;
/// Get servo currents: 6 x int16 mA.
pub const GET_SERVO_CURRENTS: u8 = 0xE2;
/// Get servo voltages: 6 bytes, volts x 10.
pub const GET_SERVO_VOLTAGES: u8 = 0xE3;
/// Get servo status: 6 bytes of fault bits.
pub const GET_SERVO_STATUS: u8 = 0xE4;
/// Get servo temperatures: 6 bytes, deg C.
pub const GET_SERVO_TEMPS: u8 = 0xE5;
/// Back up servo parameters; 254 = all.
pub const BACKUP_SERVO_PARAMS: u8 = 0xEA;
/// Restore servo parameters; 254 = all (`RESUME_SERVO_PARAMS`).
pub const RESTORE_SERVO_PARAMS: u8 = 0xEB;
/// Drag teaching: start recording; int16 points recorded.
pub const DRAG_START_RECORD: u8 = 0xF1;
/// Drag teaching: end recording; int16 points recorded.
pub const DRAG_END_RECORD: u8 = 0xF2;
/// Drag teaching: the next recorded point ([`DragPoint`](super::DragPoint)), one per call.
pub const DRAG_GET_RECORD_DATA: u8 = 0xF3;
/// Drag teaching: int16 points recorded.
pub const DRAG_GET_RECORD_LEN: u8 = 0xF4;
/// Drag teaching: forget the recorded points; int16 0.
pub const DRAG_CLEAR_RECORD_DATA: u8 = 0xF5;
/// Get planned angles (target being executed): 6 x int16 (`GET_ANGLES_PLAN`).
pub const GET_PLANNED_ANGLES: u8 = 0xF6;
/// Get planned coords (target being executed): 6 x int16 (`GET_COORDS_PLAN`).
pub const GET_PLANNED_COORDS: u8 = 0xF7;
/// Set collision mode: 1 byte, 0 off, 1 on (pymycobot's `SET_COLLISION_MODE`).
pub const SET_COLLISION_MODE: u8 = 0x74;
/// Get collision mode: 1 byte (`GET_COLLISION_MODE`).
pub const GET_COLLISION_MODE: u8 = 0xFD;
/// Set one joint's collision threshold: joint 1..=6, threshold 50..=250
/// (`SET_COLLISION_THRESHOLD`).
pub const SET_COLLISION_THRESHOLD: u8 = 0x75;
/// Get the six joints' collision thresholds: 6 bytes (`GET_COLLISION_THRESHOLD`).
pub const GET_COLLISION_THRESHOLDS: u8 = 0x76;

/// Every command code this crate models, ascending.
pub const ALL: [u8; 115] = [
    0x01, 0x02, 0x05, 0x06, 0x07, 0x08, 0x10, 0x11, 0x12, 0x13, 0x14, 0x15, 0x16, 0x17, 0x1A, 0x1B,
    0x1D, 0x20, 0x21, 0x22, 0x23, 0x24, 0x25, 0x26, 0x27, 0x28, 0x29, 0x2A, 0x2B, 0x2C, 0x2D, 0x30,
    0x31, 0x32, 0x33, 0x34, 0x35, 0x36, 0x37, 0x38, 0x39, 0x3A, 0x3B, 0x3C, 0x3D, 0x3E, 0x40, 0x41,
    0x4A, 0x4B, 0x4C, 0x4D, 0x50, 0x51, 0x52, 0x53, 0x54, 0x55, 0x56, 0x57, 0x60, 0x61, 0x62, 0x64,
    0x65, 0x66, 0x67, 0x68, 0x69, 0x6A, 0x74, 0x75, 0x76, 0x81, 0x82, 0x83, 0x84, 0x85, 0x86, 0x87,
    0x88, 0x89, 0x8A, 0x8B, 0x8C, 0x8D, 0xA0, 0xA1, 0xB0, 0xB1, 0xB2, 0xC0, 0xC1, 0xC2, 0xC3, 0xC5,
    0xD4, 0xD5, 0xD7, 0xD8, 0xE1, 0xE2, 0xE3, 0xE4, 0xE5, 0xEA, 0xEB, 0xF1, 0xF2, 0xF3, 0xF4, 0xF5,
    0xF6, 0xF7, 0xFD,
];

/// True if `code` is a command this crate models.
pub fn is_known(code: u8) -> bool {
    ALL.binary_search(&code).is_ok()
}
