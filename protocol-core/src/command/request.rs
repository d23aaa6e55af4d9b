//! [`Request`]: every host command as a typed, validated value.

use heapless::Vec;

use crate::frame::{Frame, MAX_DATA};
use crate::units::{Centideg, Decideg, SpeedPercent, Steps};

use super::cmd;
use super::error::CommandError;
use super::reply::ReplyKind;
use super::types::{
    AtomPin, Axis, AxisValue, BasicInputPin, BasicOutputPin, DataWidth, Direction, EndType,
    GripperModel, GripperSpeed, GripperState, GripperType, GripperValue, JointId, MoveMode,
    PinMode, Pose, PositionTarget, ReferenceFrame, Rgb, RpyAxis, ServoId, ServoSelect, ServoValue,
    TransponderMode,
};
use super::wire::{Reader, Writer};

/// Highest encoder value a client may send (pymycobot allows 0..=4096).
pub const MAX_ENCODER: i16 = 4096;
/// Highest per-servo drag speed of 0x3E, steps per second (pymycobot: 0..=6000).
pub const MAX_DRAG_SPEED: i16 = 6000;
/// Allowed HTS gripper torque range of 0x35 (pymycobot: 150..=980).
pub const HTS_TORQUE_RANGE: core::ops::RangeInclusive<i16> = 150..=980;
/// Allowed gripper protect current range of 0x39 (pymycobot: 1..=500).
pub const PROTECT_CURRENT_RANGE: core::ops::RangeInclusive<i16> = 1..=500;
/// Servo registers below this address (firmware version, model) are refused by set servo data
/// (0x52), as pymycobot does. Reading them is allowed (pymycobot's `is_torque_gripper` reads
/// register 1 of servo 7).
pub const MIN_SERVO_ADDRESS: u8 = 5;

/// One host command, typed and validated: every field holds a value the protocol allows.
///
/// Parse with [`Request::parse`], write with [`Request::to_frame`]. Variants follow
/// `protocol.md` section 5; each doc names the code and, where a command has several layouts,
/// the LEN of this one.
#[derive(Clone, Debug, PartialEq, Eq, Hash)]
pub enum Request {
    // --- status and system ---
    /// 0x01 get modify version.
    GetModifyVersion,
    /// 0x02 get system version.
    GetSystemVersion,
    /// 0x05 clear queue.
    ClearQueue,
    /// 0x06 check async or sync.
    CheckAsyncOrSync,
    /// 0x07 get error information.
    GetErrorInfo,
    /// 0x08 clear error information.
    ClearErrorInfo,
    /// 0x10 power on.
    PowerOn,
    /// 0x11 power off.
    PowerOff,
    /// 0x12 is powered on.
    IsPowerOn,
    /// 0x13 release all servos. `undamped`: `None` for LEN 2, else the flag byte of LEN 3
    /// (1 = undamped, 0 = damped).
    ReleaseAllServos {
        /// Optional undamped flag.
        undamped: Option<bool>,
    },
    /// 0x14 is controller connected.
    IsControllerConnected,
    /// 0x15 read next error.
    ReadNextError,
    /// 0x16 set fresh mode.
    SetFreshMode {
        /// True: the newest command preempts; false: commands queue.
        fresh: bool,
    },
    /// 0x17 get fresh mode.
    GetFreshMode,
    /// 0x1A set free mode.
    SetFreeMode {
        /// Free mode on.
        on: bool,
    },
    /// 0x1B is free mode.
    IsFreeMode,
    /// 0x1D set vision mode.
    SetVisionMode {
        /// Vision mode on.
        on: bool,
    },
    /// 0xD8 get reboot count.
    GetRebootCount,

    // --- motion ---
    /// 0x20 get angles.
    GetAngles,
    /// 0x21 send one joint angle.
    SendAngle {
        /// Joint.
        joint: JointId,
        /// Target angle.
        angle: Centideg,
        /// Speed.
        speed: SpeedPercent,
    },
    /// 0x22 send six joint angles.
    SendAngles {
        /// Target angles, joints 1..6.
        angles: [Centideg; 6],
        /// Speed.
        speed: SpeedPercent,
    },
    /// 0x23 (LEN 2) get coords.
    GetCoords,
    /// 0x23 (LEN 0x0E) angles to coords: forward kinematics, no motion.
    AnglesToCoords {
        /// Joint angles.
        angles: [Centideg; 6],
    },
    /// 0x24 send one coordinate.
    SendCoord {
        /// Axis and target value.
        target: AxisValue,
        /// Speed.
        speed: SpeedPercent,
    },
    /// 0x25 send a pose: LEN 0x0F without mode, LEN 0x10 with mode.
    SendCoords {
        /// Target pose.
        pose: Pose,
        /// Speed.
        speed: SpeedPercent,
        /// Interpolation; `None` when the client sent no mode byte.
        mode: Option<MoveMode>,
    },
    /// 0x26 pause.
    Pause,
    /// 0x27 is paused.
    IsPaused,
    /// 0x28 resume.
    Resume,
    /// 0x29 stop.
    Stop,
    /// 0x2A is in position.
    IsInPosition {
        /// Angles (flag 0) or coords (flag 1).
        target: PositionTarget,
    },
    /// 0x2B is moving.
    IsMoving,
    /// 0x2C (LEN 8, MyCobotBasic `setPid`) set the servos' position-loop gains: P, I, D of
    /// joints 1..3, then P, I, D of joints 4..6, one byte each.
    SetPid {
        /// P, I, D of joints 1..3, then of joints 4..6.
        gains: [u8; 6],
    },
    /// 0x2D (MyCobotBasic `getPid`) get the gains as 0x2C sets them.
    GetPid,
    /// 0x8B (LEN 38, MyCobotBasic `moveCCoords(begin, middle, end)`) go to `begin`, then along
    /// the circle through `begin`, `middle` and `end` to `end`, at the default speed (0x41).
    MoveCCoords {
        /// Where the arc starts.
        begin: Pose,
        /// A pose the arc passes through.
        middle: Pose,
        /// Where the arc ends.
        end: Pose,
    },
    /// 0x8C (LEN 26, MyCobotBasic `moveCCoords(middle, end)`) along the circle through the
    /// present pose, `middle` and `end` to `end`, at the default speed (0x41).
    MoveCCoordsFromHere {
        /// A pose the arc passes through.
        middle: Pose,
        /// Where the arc ends.
        end: Pose,
    },
    /// 0x8D solve inverse kinematics.
    SolveIk {
        /// Pose to reach.
        target: Pose,
        /// Current joint angles (the seed of the solution).
        current: [Centideg; 6],
    },
    /// 0xD5 get angles and coords.
    GetAnglesCoords,
    /// 0xF6 get planned angles.
    GetPlannedAngles,
    /// 0xF7 get planned coords.
    GetPlannedCoords,
    /// 0xD4 move round (pymycobot `move_round`).
    MoveRound,
    /// 0xD7 set four pieces zero (pymycobot `set_four_pieces_zero`).
    SetFourPiecesZero,

    // --- jog ---
    /// 0x30 jog one joint until jog stop / stop.
    JogAngle {
        /// Joint.
        joint: JointId,
        /// Direction.
        direction: Direction,
        /// Speed.
        speed: SpeedPercent,
    },
    /// 0x31 jog rotation about a base axis.
    JogRpy {
        /// Axis.
        axis: RpyAxis,
        /// Direction.
        direction: Direction,
        /// Speed.
        speed: SpeedPercent,
    },
    /// 0x32 jog along / about a Cartesian axis.
    JogCoord {
        /// Axis.
        axis: Axis,
        /// Direction.
        direction: Direction,
        /// Speed.
        speed: SpeedPercent,
    },
    /// 0x33 jog one joint by an increment.
    JogIncrementAngle {
        /// Joint.
        joint: JointId,
        /// Increment.
        increment: Centideg,
        /// Speed.
        speed: SpeedPercent,
    },
    /// 0x34 (LEN 2) jog stop.
    JogStop,
    /// 0x34 (LEN 6) jog increment coord.
    JogIncrementCoord {
        /// Axis and increment.
        increment: AxisValue,
        /// Speed.
        speed: SpeedPercent,
    },

    // --- encoders, speed, limits ---
    /// 0x3A set one servo's encoder: LEN 5 without speed (seed manual), LEN 6 with speed.
    SetEncoder {
        /// Servo 1..7.
        servo: ServoId,
        /// Target, 0..=4096.
        encoder: Steps,
        /// Speed; `None` for the LEN-5 form.
        speed: Option<SpeedPercent>,
    },
    /// 0x3B get one servo's encoder.
    GetEncoder {
        /// Servo 1..7.
        servo: ServoId,
    },
    /// 0x3C set six encoders.
    SetEncoders {
        /// Targets, 0..=4096 each.
        encoders: [Steps; 6],
        /// Speed.
        speed: SpeedPercent,
    },
    /// 0x3D get six encoders.
    GetEncoders,
    /// 0x3E set six encoders with per-servo speeds.
    SetEncodersDrag {
        /// Targets, 0..=4096 each.
        encoders: [Steps; 6],
        /// Servo speeds, steps per second, 0..=6000 each.
        speeds_steps_per_s: [i16; 6],
    },
    /// 0x40 get speed.
    GetSpeed,
    /// 0x41 set speed.
    SetSpeed {
        /// Default speed.
        speed: SpeedPercent,
    },
    /// 0x4A get joint min limit.
    GetJointMin {
        /// Joint.
        joint: JointId,
    },
    /// 0x4B get joint max limit.
    GetJointMax {
        /// Joint.
        joint: JointId,
    },
    /// 0x4C set joint min limit.
    SetJointMin {
        /// Joint.
        joint: JointId,
        /// Limit (tenths of a degree on the wire).
        limit: Decideg,
    },
    /// 0x4D set joint max limit.
    SetJointMax {
        /// Joint.
        joint: JointId,
        /// Limit (tenths of a degree on the wire).
        limit: Decideg,
    },

    // --- servos ---
    /// 0x50 is servo enabled.
    IsServoEnabled {
        /// Servo.
        servo: ServoId,
    },
    /// 0x51 are all servos enabled.
    AreAllServosEnabled,
    /// 0x52 write a servo register: LEN 5 one byte; LEN 7 a 16-bit value and a width flag
    /// (`01` two bytes, `00` one byte: the value must fit in it).
    SetServoData {
        /// Servo.
        servo: ServoId,
        /// Register address, >= 5.
        address: u8,
        /// Value.
        value: ServoValue,
    },
    /// 0x53 read a servo register: LEN 4 (one byte) or LEN 5 with a width byte.
    GetServoData {
        /// Servo.
        servo: ServoId,
        /// Register address.
        address: u8,
        /// Width byte; `None` for the LEN-4 form (one byte).
        width: Option<DataWidth>,
    },
    /// 0x54 make the servo's current position its zero.
    SetServoCalibration {
        /// Servo.
        servo: ServoId,
    },
    /// 0x55 brake one joint.
    JointBrake {
        /// Servo.
        servo: ServoId,
    },
    /// 0x56 release one servo: LEN 3, or LEN 4 with the undamped flag.
    ReleaseServo {
        /// Servo.
        servo: ServoId,
        /// Optional undamped flag.
        undamped: Option<bool>,
    },
    /// 0x57 focus servo (torque on); wire 0 = all.
    FocusServo {
        /// Servo or all.
        servo: ServoSelect,
    },
    /// 0xE1 get servo speeds.
    GetServoSpeeds,
    /// 0xE2 get servo currents.
    GetServoCurrents,
    /// 0xE3 get servo voltages.
    GetServoVoltages,
    /// 0xE4 get servo status.
    GetServoStatus,
    /// 0xE5 get servo temperatures.
    GetServoTemps,
    /// 0xEA back up servo parameters; wire 254 = all.
    BackupServoParams {
        /// Servo or all.
        servo: ServoSelect,
    },
    /// 0xEB restore servo parameters; wire 254 = all.
    RestoreServoParams {
        /// Servo or all.
        servo: ServoSelect,
    },

    // --- Atom IO, LED, gripper ---
    /// 0x60 set an Atom pin's mode.
    SetPinMode {
        /// Pin.
        pin: AtomPin,
        /// Mode (pin 39 is input only).
        mode: PinMode,
    },
    /// 0x61 set an Atom digital output.
    SetDigitalOutput {
        /// Pin (never 39).
        pin: AtomPin,
        /// High.
        high: bool,
    },
    /// 0x62 get an Atom digital input.
    GetDigitalInput {
        /// Pin.
        pin: AtomPin,
    },
    /// 0x64 set an Atom PWM output.
    SetPwmOutput {
        /// Pin (never 39).
        pin: AtomPin,
        /// Frequency, hertz.
        frequency_hz: u16,
        /// Duty, 0..=255 of full scale.
        duty: u8,
    },
    /// 0x65 get gripper value: LEN 2, or LEN 3 with a gripper type.
    GetGripperValue {
        /// Gripper type, if given.
        gripper: Option<GripperType>,
    },
    /// 0x66 (LEN 3, seed manual) set gripper state with no speed.
    SetGripperStateNoSpeed {
        /// State.
        state: GripperState,
    },
    /// 0x66 set gripper state: LEN 4, 5 (type) or 6 (type, torque).
    SetGripperState {
        /// State.
        state: GripperState,
        /// Speed.
        speed: GripperSpeed,
        /// Optional type / torque tail.
        model: GripperModel,
    },
    /// 0x67 set gripper opening: LEN 4, 5 (type) or 6 (type, torque).
    SetGripperValue {
        /// Opening.
        value: GripperValue,
        /// Speed.
        speed: GripperSpeed,
        /// Optional type / torque tail.
        model: GripperModel,
    },
    /// 0x68 calibrate the gripper.
    SetGripperCalibration,
    /// 0x69 is gripper moving.
    IsGripperMoving,
    /// 0x6A set the Atom LED colour.
    SetColor {
        /// Colour.
        rgb: Rgb,
    },
    /// 0x35 set HTS gripper torque, 150..=980.
    SetHtsGripperTorque {
        /// Torque.
        torque: i16,
    },
    /// 0x36 get HTS gripper torque.
    GetHtsGripperTorque,
    /// 0x37 get gripper protect current.
    GetGripperProtectCurrent,
    /// 0x38 init gripper.
    InitGripper,
    /// 0x39 set gripper protect current, 1..=500.
    SetGripperProtectCurrent {
        /// Current.
        current: i16,
    },

    // --- coordinate frames ---
    /// 0x81 set tool reference.
    SetToolReference {
        /// Tool pose in the flange frame.
        pose: Pose,
    },
    /// 0x82 get tool reference.
    GetToolReference,
    /// 0x83 set world reference.
    SetWorldReference {
        /// Base pose in the world frame.
        pose: Pose,
    },
    /// 0x84 get world reference.
    GetWorldReference,
    /// 0x85 set reference frame.
    SetReferenceFrame {
        /// Frame.
        frame: ReferenceFrame,
    },
    /// 0x86 get reference frame.
    GetReferenceFrame,
    /// 0x87 set movement type.
    SetMovementType {
        /// Type.
        mode: MoveMode,
    },
    /// 0x88 get movement type.
    GetMovementType,
    /// 0x89 set end type.
    SetEndType {
        /// End.
        end: EndType,
    },
    /// 0x8A get end type.
    GetEndType,

    // --- answered by the Basic ---
    /// 0xA0 set a Basic output.
    SetBasicOutput {
        /// Pin.
        pin: BasicOutputPin,
        /// High.
        high: bool,
    },
    /// 0xA1 get a Basic input.
    GetBasicInput {
        /// Pin.
        pin: BasicInputPin,
    },
    /// 0xB0 set Wi-Fi SSID and password. pymycobot sends it empty (an announcing frame) and
    /// the credentials 20 ms later as bare text `'ssid'(password)`, outside any frame; a
    /// client may also frame that text here (`firmware_basic::wifi::config`).
    SetSsidPwd {
        /// Payload.
        payload: Vec<u8, MAX_DATA>,
    },
    /// 0xB1 get Wi-Fi SSID and password.
    GetSsidPwd,
    /// 0xB2 set server port.
    SetServerPort {
        /// TCP port.
        port: u16,
    },
    /// 0xC0 get ToF distance.
    GetTofDistance,
    /// 0xC1 get Basic version.
    GetBasicVersion,
    /// 0xC2 set transponder mode.
    SetTransponderMode {
        /// Mode.
        mode: TransponderMode,
    },
    /// 0xC3 get transponder mode.
    GetTransponderMode,

    // --- drag teaching ---
    /// 0xF1 start recording.
    DragStartRecord,
    /// 0xF2 end recording.
    DragEndRecord,
    /// 0xF3 get recorded data.
    DragGetRecordData,
    /// 0xF4 get record length.
    DragGetRecordLen,
    /// 0xF5 clear recorded data.
    DragClearRecordData,
}

/// Generates the two directions of the mapping between data-less variants and their codes
/// from one list, so they cannot drift apart.
macro_rules! no_data_commands {
    ($($variant:ident = $code:path),* $(,)?) => {
        impl Request {
            /// The data-less request for `code`, if that command has a LEN-2 layout.
            fn from_no_data(code: u8) -> Option<Self> {
                match code {
                    $($code => Some(Self::$variant),)*
                    _ => None,
                }
            }

            /// The code of a data-less request.
            fn no_data_code(&self) -> Option<u8> {
                match self {
                    $(Self::$variant => Some($code),)*
                    _ => None,
                }
            }
        }
    };
}

no_data_commands! {
    GetModifyVersion = cmd::GET_MODIFY_VERSION,
    GetSystemVersion = cmd::GET_SYSTEM_VERSION,
    ClearQueue = cmd::CLEAR_QUEUE,
    CheckAsyncOrSync = cmd::CHECK_ASYNC_OR_SYNC,
    GetErrorInfo = cmd::GET_ERROR_INFO,
    ClearErrorInfo = cmd::CLEAR_ERROR_INFO,
    PowerOn = cmd::POWER_ON,
    PowerOff = cmd::POWER_OFF,
    IsPowerOn = cmd::IS_POWER_ON,
    IsControllerConnected = cmd::IS_CONTROLLER_CONNECTED,
    ReadNextError = cmd::READ_NEXT_ERROR,
    GetFreshMode = cmd::GET_FRESH_MODE,
    IsFreeMode = cmd::IS_FREE_MODE,
    GetRebootCount = cmd::GET_REBOOT_COUNT,
    GetAngles = cmd::GET_ANGLES,
    GetCoords = cmd::GET_COORDS,
    Pause = cmd::PAUSE,
    IsPaused = cmd::IS_PAUSED,
    Resume = cmd::RESUME,
    Stop = cmd::STOP,
    IsMoving = cmd::IS_MOVING,
    GetAnglesCoords = cmd::GET_ANGLES_COORDS,
    GetPlannedAngles = cmd::GET_PLANNED_ANGLES,
    GetPlannedCoords = cmd::GET_PLANNED_COORDS,
    MoveRound = cmd::MOVE_ROUND,
    SetFourPiecesZero = cmd::SET_FOUR_PIECES_ZERO,
    JogStop = cmd::JOG_STOP,
    GetEncoders = cmd::GET_ENCODERS,
    GetSpeed = cmd::GET_SPEED,
    AreAllServosEnabled = cmd::ARE_ALL_SERVOS_ENABLED,
    GetServoSpeeds = cmd::GET_SERVO_SPEEDS,
    GetServoCurrents = cmd::GET_SERVO_CURRENTS,
    GetServoVoltages = cmd::GET_SERVO_VOLTAGES,
    GetServoStatus = cmd::GET_SERVO_STATUS,
    GetServoTemps = cmd::GET_SERVO_TEMPS,
    SetGripperCalibration = cmd::SET_GRIPPER_CALIBRATION,
    IsGripperMoving = cmd::IS_GRIPPER_MOVING,
    GetHtsGripperTorque = cmd::GET_HTS_GRIPPER_TORQUE,
    GetGripperProtectCurrent = cmd::GET_GRIPPER_PROTECT_CURRENT,
    InitGripper = cmd::INIT_GRIPPER,
    GetToolReference = cmd::GET_TOOL_REFERENCE,
    GetWorldReference = cmd::GET_WORLD_REFERENCE,
    GetReferenceFrame = cmd::GET_REFERENCE_FRAME,
    GetMovementType = cmd::GET_MOVEMENT_TYPE,
    GetEndType = cmd::GET_END_TYPE,
    GetSsidPwd = cmd::GET_SSID_PWD,
    GetTofDistance = cmd::GET_TOF_DISTANCE,
    GetBasicVersion = cmd::GET_BASIC_VERSION,
    GetTransponderMode = cmd::GET_TRANSPONDER_MODE,
    DragStartRecord = cmd::DRAG_START_RECORD,
    DragEndRecord = cmd::DRAG_END_RECORD,
    DragGetRecordData = cmd::DRAG_GET_RECORD_DATA,
    DragGetRecordLen = cmd::DRAG_GET_RECORD_LEN,
    DragClearRecordData = cmd::DRAG_CLEAR_RECORD_DATA,
    GetPid = cmd::GET_PID,
}

/// Reads a frame's fields, turning each raw byte into its validated type.
struct Fields<'a> {
    r: Reader<'a>,
    short: CommandError,
}

impl Fields<'_> {
    fn u8(&mut self) -> Result<u8, CommandError> {
        self.r.u8().ok_or(self.short)
    }

    fn i16(&mut self) -> Result<i16, CommandError> {
        self.r.i16().ok_or(self.short)
    }

    fn flag(&mut self) -> Result<bool, CommandError> {
        match self.u8()? {
            0 => Ok(false),
            1 => Ok(true),
            v => Err(CommandError::BadFlag(v)),
        }
    }

    fn enum_byte<T>(&mut self, from: fn(u8) -> Option<T>) -> Result<T, CommandError> {
        let v = self.u8()?;
        from(v).ok_or(CommandError::BadFlag(v))
    }

    fn joint(&mut self) -> Result<JointId, CommandError> {
        let v = self.u8()?;
        JointId::new(v).ok_or(CommandError::BadJoint(v))
    }

    fn servo(&mut self) -> Result<ServoId, CommandError> {
        let v = self.u8()?;
        ServoId::new(v).ok_or(CommandError::BadServo(v))
    }

    fn servo_or_all(&mut self, all: u8) -> Result<ServoSelect, CommandError> {
        let v = self.u8()?;
        if v == all {
            return Ok(ServoSelect::All);
        }
        ServoId::new(v)
            .map(ServoSelect::One)
            .ok_or(CommandError::BadServo(v))
    }

    fn address(&mut self) -> Result<u8, CommandError> {
        let v = self.u8()?;
        if v < MIN_SERVO_ADDRESS {
            return Err(CommandError::BadAddress(v));
        }
        Ok(v)
    }

    fn speed(&mut self) -> Result<SpeedPercent, CommandError> {
        let v = self.u8()?;
        SpeedPercent::new(v).ok_or(CommandError::BadSpeed(v))
    }

    fn gripper_speed(&mut self) -> Result<GripperSpeed, CommandError> {
        let v = self.u8()?;
        GripperSpeed::new(v).ok_or(CommandError::BadSpeed(v))
    }

    fn gripper_type(&mut self) -> Result<GripperType, CommandError> {
        let v = self.u8()?;
        GripperType::new(v).ok_or(CommandError::BadGripperValue(v))
    }

    /// The optional type / torque tail of 0x66/0x67, from the number of bytes left.
    fn gripper_model(&mut self, tail_len: usize) -> Result<GripperModel, CommandError> {
        Ok(match tail_len {
            0 => GripperModel::Default,
            1 => GripperModel::Typed(self.gripper_type()?),
            _ => {
                let kind = self.gripper_type()?;
                GripperModel::TypedTorque(kind, self.flag()?)
            }
        })
    }

    fn direction(&mut self) -> Result<Direction, CommandError> {
        let v = self.u8()?;
        Direction::from_u8(v).ok_or(CommandError::BadDirection(v))
    }

    fn axis(&mut self) -> Result<Axis, CommandError> {
        let v = self.u8()?;
        Axis::from_u8(v).ok_or(CommandError::BadAxis(v))
    }

    fn axis_value(&mut self) -> Result<AxisValue, CommandError> {
        let axis = self.axis()?;
        Ok(AxisValue::new(axis, self.i16()?))
    }

    fn encoder(&mut self) -> Result<Steps, CommandError> {
        let v = self.i16()?;
        if !(0..=MAX_ENCODER).contains(&v) {
            return Err(CommandError::BadEncoder(v));
        }
        Ok(Steps(v))
    }

    fn encoders(&mut self) -> Result<[Steps; 6], CommandError> {
        let mut out = [Steps(0); 6];
        for e in &mut out {
            *e = self.encoder()?;
        }
        Ok(out)
    }

    fn centideg6(&mut self) -> Result<[Centideg; 6], CommandError> {
        self.r.centideg6().ok_or(self.short)
    }

    fn pose(&mut self) -> Result<Pose, CommandError> {
        self.r.pose().ok_or(self.short)
    }

    fn atom_pin(&mut self) -> Result<AtomPin, CommandError> {
        let v = self.u8()?;
        AtomPin::new(v).ok_or(CommandError::BadPin(v))
    }

    fn atom_output_pin(&mut self) -> Result<AtomPin, CommandError> {
        let v = self.u8()?;
        AtomPin::output(v).ok_or(CommandError::BadPin(v))
    }

    fn limited_i16(&mut self, range: core::ops::RangeInclusive<i16>) -> Result<i16, CommandError> {
        let v = self.i16()?;
        if !range.contains(&v) {
            return Err(CommandError::BadGripperSetting(v));
        }
        Ok(v)
    }
}

impl Request {
    /// Parses a frame into a command.
    ///
    /// Errors: [`CommandError::UnknownCommand`] for a code no command has,
    /// [`CommandError::BadLength`] for a known code with a LEN none of its layouts has, and a
    /// field-specific variant for any field outside its allowed values. Never panics.
    pub fn parse(frame: &Frame) -> Result<Self, CommandError> {
        let code = frame.cmd();
        let data = frame.data();
        let n = data.len();
        // n <= MAX_DATA = 62, so the cast is exact.
        let bad_len = if cmd::is_known(code) {
            CommandError::BadLength {
                cmd: code,
                data_len: n as u8,
            }
        } else {
            CommandError::UnknownCommand { cmd: code }
        };
        if n == 0
            && let Some(req) = Self::from_no_data(code)
        {
            return Ok(req);
        }
        let mut f = Fields {
            r: Reader::new(data),
            short: bad_len,
        };
        let req = match (code, n) {
            (cmd::RELEASE_ALL_SERVOS, 0) => Self::ReleaseAllServos { undamped: None },
            (cmd::RELEASE_ALL_SERVOS, 1) => Self::ReleaseAllServos {
                undamped: Some(f.flag()?),
            },
            (cmd::SET_FRESH_MODE, 1) => Self::SetFreshMode { fresh: f.flag()? },
            (cmd::SET_FREE_MODE, 1) => Self::SetFreeMode { on: f.flag()? },
            (cmd::SET_VISION_MODE, 1) => Self::SetVisionMode { on: f.flag()? },

            (cmd::SEND_ANGLE, 4) => Self::SendAngle {
                joint: f.joint()?,
                angle: Centideg(f.i16()?),
                speed: f.speed()?,
            },
            (cmd::SEND_ANGLES, 13) => Self::SendAngles {
                angles: f.centideg6()?,
                speed: f.speed()?,
            },
            (cmd::GET_COORDS, 12) => Self::AnglesToCoords {
                angles: f.centideg6()?,
            },
            (cmd::SEND_COORD, 4) => Self::SendCoord {
                target: {
                    let v = f.u8()?;
                    let axis = Axis::from_send_coord_byte(v).ok_or(CommandError::BadAxis(v))?;
                    AxisValue::new(axis, f.i16()?)
                },
                speed: f.speed()?,
            },
            (cmd::SEND_COORDS, 13 | 14) => Self::SendCoords {
                pose: f.pose()?,
                speed: f.speed()?,
                mode: if n == 14 {
                    Some(f.enum_byte(MoveMode::from_u8)?)
                } else {
                    None
                },
            },
            (cmd::IS_IN_POSITION, 13) => {
                let values = f.r.i16x6().ok_or(bad_len)?;
                Self::IsInPosition {
                    target: match f.flag()? {
                        false => PositionTarget::Angles(values.map(Centideg)),
                        true => PositionTarget::Coords(Pose::from_array(values)),
                    },
                }
            }
            (cmd::SET_PID, 6) => Self::SetPid {
                gains: [f.u8()?, f.u8()?, f.u8()?, f.u8()?, f.u8()?, f.u8()?],
            },
            (cmd::MOVE_C_COORDS, 36) => Self::MoveCCoords {
                begin: f.pose()?,
                middle: f.pose()?,
                end: f.pose()?,
            },
            (cmd::MOVE_C_COORDS_FROM_HERE, 24) => Self::MoveCCoordsFromHere {
                middle: f.pose()?,
                end: f.pose()?,
            },
            (cmd::SOLVE_INV_KINEMATICS, 24) => Self::SolveIk {
                target: f.pose()?,
                current: f.centideg6()?,
            },

            (cmd::JOG_ANGLE, 3) => Self::JogAngle {
                joint: f.joint()?,
                direction: f.direction()?,
                speed: f.speed()?,
            },
            (cmd::JOG_RPY, 3) => Self::JogRpy {
                axis: {
                    let v = f.u8()?;
                    RpyAxis::from_u8(v).ok_or(CommandError::BadAxis(v))?
                },
                direction: f.direction()?,
                speed: f.speed()?,
            },
            (cmd::JOG_COORD, 3) => Self::JogCoord {
                axis: f.axis()?,
                direction: f.direction()?,
                speed: f.speed()?,
            },
            (cmd::JOG_INCREMENT_ANGLE, 4) => Self::JogIncrementAngle {
                joint: f.joint()?,
                increment: Centideg(f.i16()?),
                speed: f.speed()?,
            },
            (cmd::JOG_INCREMENT_COORD, 4) => Self::JogIncrementCoord {
                increment: f.axis_value()?,
                speed: f.speed()?,
            },

            (cmd::SET_ENCODER, 3 | 4) => Self::SetEncoder {
                servo: f.servo()?,
                encoder: f.encoder()?,
                speed: if n == 4 { Some(f.speed()?) } else { None },
            },
            (cmd::GET_ENCODER, 1) => Self::GetEncoder { servo: f.servo()? },
            (cmd::SET_ENCODERS, 13) => Self::SetEncoders {
                encoders: f.encoders()?,
                speed: f.speed()?,
            },
            (cmd::SET_ENCODERS_DRAG, 24) => {
                let encoders = f.encoders()?;
                let speeds = f.r.i16x6().ok_or(bad_len)?;
                if let Some(&bad) = speeds.iter().find(|s| !(0..=MAX_DRAG_SPEED).contains(*s)) {
                    return Err(CommandError::BadDragSpeed(bad));
                }
                Self::SetEncodersDrag {
                    encoders,
                    speeds_steps_per_s: speeds,
                }
            }
            (cmd::SET_SPEED, 1) => Self::SetSpeed { speed: f.speed()? },
            (cmd::GET_JOINT_MIN, 1) => Self::GetJointMin { joint: f.joint()? },
            (cmd::GET_JOINT_MAX, 1) => Self::GetJointMax { joint: f.joint()? },
            (cmd::SET_JOINT_MIN, 3) => Self::SetJointMin {
                joint: f.joint()?,
                limit: Decideg(f.i16()?),
            },
            (cmd::SET_JOINT_MAX, 3) => Self::SetJointMax {
                joint: f.joint()?,
                limit: Decideg(f.i16()?),
            },

            (cmd::IS_SERVO_ENABLED, 1) => Self::IsServoEnabled { servo: f.servo()? },
            (cmd::SET_SERVO_DATA, 3) => Self::SetServoData {
                servo: f.servo()?,
                address: f.address()?,
                value: ServoValue::Byte(f.u8()?),
            },
            (cmd::SET_SERVO_DATA, 5) => {
                let servo = f.servo()?;
                let address = f.address()?;
                let word = f.i16()? as u16;
                // pymycobot's `set_servo_data(.., mode)` always sends the value in two bytes
                // and the flag says the register's width: 1 a word, 0 one byte (the low one).
                match (f.u8()?, u8::try_from(word)) {
                    (1, _) => Self::SetServoData {
                        servo,
                        address,
                        value: ServoValue::Word(word),
                    },
                    (0, Ok(byte)) => Self::SetServoData {
                        servo,
                        address,
                        value: ServoValue::Byte(byte),
                    },
                    (v, _) => return Err(CommandError::BadFlag(v)),
                }
            }
            (cmd::GET_SERVO_DATA, 2 | 3) => Self::GetServoData {
                servo: f.servo()?,
                address: f.u8()?,
                width: if n == 3 {
                    Some(f.enum_byte(DataWidth::from_u8)?)
                } else {
                    None
                },
            },
            (cmd::SET_SERVO_CALIBRATION, 1) => Self::SetServoCalibration { servo: f.servo()? },
            (cmd::JOINT_BRAKE, 1) => Self::JointBrake { servo: f.servo()? },
            (cmd::RELEASE_SERVO, 1 | 2) => Self::ReleaseServo {
                servo: f.servo()?,
                undamped: if n == 2 { Some(f.flag()?) } else { None },
            },
            (cmd::FOCUS_SERVO, 1) => Self::FocusServo {
                servo: f.servo_or_all(0)?,
            },
            (cmd::BACKUP_SERVO_PARAMS, 1) => Self::BackupServoParams {
                servo: f.servo_or_all(254)?,
            },
            (cmd::RESTORE_SERVO_PARAMS, 1) => Self::RestoreServoParams {
                servo: f.servo_or_all(254)?,
            },

            (cmd::SET_PIN_MODE, 2) => {
                let pin = f.atom_pin()?;
                let mode = f.enum_byte(PinMode::from_u8)?;
                if mode == PinMode::Output && !pin.can_output() {
                    return Err(CommandError::BadPin(pin.gpio()));
                }
                Self::SetPinMode { pin, mode }
            }
            (cmd::SET_DIGITAL_OUTPUT, 2) => Self::SetDigitalOutput {
                pin: f.atom_output_pin()?,
                high: f.flag()?,
            },
            (cmd::GET_DIGITAL_INPUT, 1) => Self::GetDigitalInput { pin: f.atom_pin()? },
            (cmd::SET_PWM_OUTPUT, 4) => Self::SetPwmOutput {
                pin: f.atom_output_pin()?,
                frequency_hz: f.i16()? as u16,
                duty: f.u8()?,
            },
            (cmd::GET_GRIPPER_VALUE, 0 | 1) => Self::GetGripperValue {
                gripper: if n == 1 {
                    Some(f.gripper_type()?)
                } else {
                    None
                },
            },
            (cmd::SET_GRIPPER_STATE, 1) => Self::SetGripperStateNoSpeed {
                state: {
                    let v = f.u8()?;
                    GripperState::from_u8(v).ok_or(CommandError::BadGripperValue(v))?
                },
            },
            (cmd::SET_GRIPPER_STATE, 2..=4) => Self::SetGripperState {
                state: {
                    let v = f.u8()?;
                    GripperState::from_u8(v).ok_or(CommandError::BadGripperValue(v))?
                },
                speed: f.gripper_speed()?,
                model: f.gripper_model(n - 2)?,
            },
            (cmd::SET_GRIPPER_VALUE, 2..=4) => Self::SetGripperValue {
                value: {
                    let v = f.u8()?;
                    GripperValue::new(v).ok_or(CommandError::BadGripperValue(v))?
                },
                speed: f.gripper_speed()?,
                model: f.gripper_model(n - 2)?,
            },
            (cmd::SET_COLOR, 3) => Self::SetColor {
                rgb: Rgb {
                    r: f.u8()?,
                    g: f.u8()?,
                    b: f.u8()?,
                },
            },
            (cmd::SET_HTS_GRIPPER_TORQUE, 2) => Self::SetHtsGripperTorque {
                torque: f.limited_i16(HTS_TORQUE_RANGE)?,
            },
            (cmd::SET_GRIPPER_PROTECT_CURRENT, 2) => Self::SetGripperProtectCurrent {
                current: f.limited_i16(PROTECT_CURRENT_RANGE)?,
            },

            (cmd::SET_TOOL_REFERENCE, 12) => Self::SetToolReference { pose: f.pose()? },
            (cmd::SET_WORLD_REFERENCE, 12) => Self::SetWorldReference { pose: f.pose()? },
            (cmd::SET_REFERENCE_FRAME, 1) => Self::SetReferenceFrame {
                frame: f.enum_byte(ReferenceFrame::from_u8)?,
            },
            (cmd::SET_MOVEMENT_TYPE, 1) => Self::SetMovementType {
                mode: f.enum_byte(MoveMode::from_u8)?,
            },
            (cmd::SET_END_TYPE, 1) => Self::SetEndType {
                end: f.enum_byte(EndType::from_u8)?,
            },

            (cmd::SET_BASIC_OUTPUT, 2) => Self::SetBasicOutput {
                pin: {
                    let v = f.u8()?;
                    BasicOutputPin::new(v).ok_or(CommandError::BadPin(v))?
                },
                high: f.flag()?,
            },
            (cmd::GET_BASIC_INPUT, 1) => Self::GetBasicInput {
                pin: {
                    let v = f.u8()?;
                    BasicInputPin::new(v).ok_or(CommandError::BadPin(v))?
                },
            },
            (cmd::SET_SSID_PWD, _) => Self::SetSsidPwd {
                // data.len() <= MAX_DATA, the capacity.
                payload: Vec::from_slice(data).map_err(|_| bad_len)?,
            },
            (cmd::SET_SERVER_PORT, 2) => Self::SetServerPort {
                port: f.i16()? as u16,
            },
            (cmd::SET_TRANSPONDER_MODE, 1) => Self::SetTransponderMode {
                mode: f.enum_byte(TransponderMode::from_u8)?,
            },
            _ => return Err(bad_len),
        };
        Ok(req)
    }

    /// The command code (CMD byte) of this request.
    pub fn cmd(&self) -> u8 {
        self.encode().0
    }

    /// The frame a client sends for this request. `Request::parse(&r.to_frame()) == Ok(r)`
    /// for every valid request.
    pub fn to_frame(&self) -> Frame {
        let (code, w) = self.encode();
        w.frame(code)
    }

    /// Shape of the reply this request expects (`protocol.md` section 5), for
    /// [`Reply::parse`](super::Reply::parse).
    pub fn reply_kind(&self) -> ReplyKind {
        use ReplyKind as K;
        match self {
            Self::GetModifyVersion
            | Self::GetSystemVersion
            | Self::CheckAsyncOrSync
            | Self::GetErrorInfo
            | Self::IsPowerOn
            | Self::IsControllerConnected
            | Self::GetFreshMode
            | Self::IsFreeMode
            | Self::IsPaused
            | Self::IsInPosition { .. }
            | Self::IsMoving
            | Self::GetSpeed
            | Self::AreAllServosEnabled
            | Self::GetGripperValue { .. }
            | Self::IsGripperMoving
            | Self::GetReferenceFrame
            | Self::GetMovementType
            | Self::GetEndType
            | Self::GetBasicVersion
            | Self::GetTransponderMode
            | Self::SetFourPiecesZero
            | Self::InitGripper => K::Byte,
            Self::GetServoData {
                width: Some(DataWidth::Word),
                ..
            } => K::Int16,
            Self::GetServoData { .. } => K::Byte,
            Self::GetRebootCount
            | Self::GetEncoder { .. }
            | Self::GetTofDistance
            | Self::GetHtsGripperTorque
            | Self::GetGripperProtectCurrent
            | Self::DragStartRecord
            | Self::DragEndRecord
            | Self::DragGetRecordLen
            | Self::DragClearRecordData => K::Int16,
            Self::DragGetRecordData => K::DragPoint,
            Self::GetAngles | Self::GetPlannedAngles | Self::SolveIk { .. } => K::Angles,
            Self::GetCoords
            | Self::AnglesToCoords { .. }
            | Self::GetPlannedCoords
            | Self::GetToolReference
            | Self::GetWorldReference => K::Coords,
            Self::GetEncoders => K::Encoders,
            Self::GetServoSpeeds | Self::GetServoCurrents => K::Int16x6,
            Self::GetServoVoltages | Self::GetServoStatus | Self::GetServoTemps | Self::GetPid => {
                K::Bytes6
            }
            Self::ReadNextError => K::ServoErrors,
            Self::GetAnglesCoords => K::AnglesAndCoords,
            Self::GetDigitalInput { .. } | Self::GetBasicInput { .. } => K::PinLevel,
            Self::GetJointMin { .. } | Self::GetJointMax { .. } => K::JointLimit,
            Self::IsServoEnabled { .. } => K::ServoEnabled,
            Self::GetSsidPwd => K::Raw,
            _ => K::Ack,
        }
    }

    /// The command code and data bytes of this request.
    fn encode(&self) -> (u8, Writer) {
        let mut w = Writer::default();
        if let Some(code) = self.no_data_code() {
            return (code, w);
        }
        let code = match self {
            Self::ReleaseAllServos { undamped } => {
                if let Some(u) = undamped {
                    w.u8(u8::from(*u));
                }
                cmd::RELEASE_ALL_SERVOS
            }
            Self::SetFreshMode { fresh } => {
                w.u8(u8::from(*fresh));
                cmd::SET_FRESH_MODE
            }
            Self::SetFreeMode { on } => {
                w.u8(u8::from(*on));
                cmd::SET_FREE_MODE
            }
            Self::SetVisionMode { on } => {
                w.u8(u8::from(*on));
                cmd::SET_VISION_MODE
            }
            Self::SendAngle {
                joint,
                angle,
                speed,
            } => {
                w.u8(joint.get()).i16(angle.0).u8(speed.get());
                cmd::SEND_ANGLE
            }
            Self::SendAngles { angles, speed } => {
                w.centideg6(angles).u8(speed.get());
                cmd::SEND_ANGLES
            }
            Self::AnglesToCoords { angles } => {
                w.centideg6(angles);
                cmd::GET_COORDS
            }
            Self::SendCoord { target, speed } => {
                w.u8(target.axis() as u8).i16(target.raw()).u8(speed.get());
                cmd::SEND_COORD
            }
            Self::SendCoords { pose, speed, mode } => {
                w.pose(pose).u8(speed.get());
                if let Some(m) = mode {
                    w.u8(*m as u8);
                }
                cmd::SEND_COORDS
            }
            Self::IsInPosition { target } => {
                match target {
                    PositionTarget::Angles(a) => w.centideg6(a).u8(0),
                    PositionTarget::Coords(p) => w.pose(p).u8(1),
                };
                cmd::IS_IN_POSITION
            }
            Self::SolveIk { target, current } => {
                w.pose(target).centideg6(current);
                cmd::SOLVE_INV_KINEMATICS
            }
            Self::SetPid { gains } => {
                w.bytes(gains);
                cmd::SET_PID
            }
            Self::MoveCCoords { begin, middle, end } => {
                w.pose(begin).pose(middle).pose(end);
                cmd::MOVE_C_COORDS
            }
            Self::MoveCCoordsFromHere { middle, end } => {
                w.pose(middle).pose(end);
                cmd::MOVE_C_COORDS_FROM_HERE
            }
            Self::JogAngle {
                joint,
                direction,
                speed,
            } => {
                w.u8(joint.get()).u8(*direction as u8).u8(speed.get());
                cmd::JOG_ANGLE
            }
            Self::JogRpy {
                axis,
                direction,
                speed,
            } => {
                w.u8(*axis as u8).u8(*direction as u8).u8(speed.get());
                cmd::JOG_RPY
            }
            Self::JogCoord {
                axis,
                direction,
                speed,
            } => {
                w.u8(*axis as u8).u8(*direction as u8).u8(speed.get());
                cmd::JOG_COORD
            }
            Self::JogIncrementAngle {
                joint,
                increment,
                speed,
            } => {
                w.u8(joint.get()).i16(increment.0).u8(speed.get());
                cmd::JOG_INCREMENT_ANGLE
            }
            Self::JogIncrementCoord { increment, speed } => {
                w.u8(increment.axis() as u8)
                    .i16(increment.raw())
                    .u8(speed.get());
                cmd::JOG_INCREMENT_COORD
            }
            Self::SetEncoder {
                servo,
                encoder,
                speed,
            } => {
                w.u8(servo.get()).i16(encoder.0);
                if let Some(s) = speed {
                    w.u8(s.get());
                }
                cmd::SET_ENCODER
            }
            Self::GetEncoder { servo } => {
                w.u8(servo.get());
                cmd::GET_ENCODER
            }
            Self::SetEncoders { encoders, speed } => {
                w.steps6(encoders).u8(speed.get());
                cmd::SET_ENCODERS
            }
            Self::SetEncodersDrag {
                encoders,
                speeds_steps_per_s,
            } => {
                w.steps6(encoders).i16s(speeds_steps_per_s);
                cmd::SET_ENCODERS_DRAG
            }
            Self::SetSpeed { speed } => {
                w.u8(speed.get());
                cmd::SET_SPEED
            }
            Self::GetJointMin { joint } => {
                w.u8(joint.get());
                cmd::GET_JOINT_MIN
            }
            Self::GetJointMax { joint } => {
                w.u8(joint.get());
                cmd::GET_JOINT_MAX
            }
            Self::SetJointMin { joint, limit } => {
                w.u8(joint.get()).i16(limit.0);
                cmd::SET_JOINT_MIN
            }
            Self::SetJointMax { joint, limit } => {
                w.u8(joint.get()).i16(limit.0);
                cmd::SET_JOINT_MAX
            }
            Self::IsServoEnabled { servo } => {
                w.u8(servo.get());
                cmd::IS_SERVO_ENABLED
            }
            Self::SetServoData {
                servo,
                address,
                value,
            } => {
                w.u8(servo.get()).u8(*address);
                match value {
                    ServoValue::Byte(b) => w.u8(*b),
                    ServoValue::Word(v) => w.bytes(&v.to_be_bytes()).u8(1),
                };
                cmd::SET_SERVO_DATA
            }
            Self::GetServoData {
                servo,
                address,
                width,
            } => {
                w.u8(servo.get()).u8(*address);
                if let Some(wd) = width {
                    w.u8(*wd as u8);
                }
                cmd::GET_SERVO_DATA
            }
            Self::SetServoCalibration { servo } => {
                w.u8(servo.get());
                cmd::SET_SERVO_CALIBRATION
            }
            Self::JointBrake { servo } => {
                w.u8(servo.get());
                cmd::JOINT_BRAKE
            }
            Self::ReleaseServo { servo, undamped } => {
                w.u8(servo.get());
                if let Some(u) = undamped {
                    w.u8(u8::from(*u));
                }
                cmd::RELEASE_SERVO
            }
            Self::FocusServo { servo } => {
                w.u8(select_byte(*servo, 0));
                cmd::FOCUS_SERVO
            }
            Self::BackupServoParams { servo } => {
                w.u8(select_byte(*servo, 254));
                cmd::BACKUP_SERVO_PARAMS
            }
            Self::RestoreServoParams { servo } => {
                w.u8(select_byte(*servo, 254));
                cmd::RESTORE_SERVO_PARAMS
            }
            Self::SetPinMode { pin, mode } => {
                w.u8(pin.gpio()).u8(*mode as u8);
                cmd::SET_PIN_MODE
            }
            Self::SetDigitalOutput { pin, high } => {
                w.u8(pin.gpio()).u8(u8::from(*high));
                cmd::SET_DIGITAL_OUTPUT
            }
            Self::GetDigitalInput { pin } => {
                w.u8(pin.gpio());
                cmd::GET_DIGITAL_INPUT
            }
            Self::SetPwmOutput {
                pin,
                frequency_hz,
                duty,
            } => {
                w.u8(pin.gpio())
                    .bytes(&frequency_hz.to_be_bytes())
                    .u8(*duty);
                cmd::SET_PWM_OUTPUT
            }
            Self::GetGripperValue { gripper } => {
                if let Some(g) = gripper {
                    w.u8(g.get());
                }
                cmd::GET_GRIPPER_VALUE
            }
            Self::SetGripperStateNoSpeed { state } => {
                w.u8(*state as u8);
                cmd::SET_GRIPPER_STATE
            }
            Self::SetGripperState {
                state,
                speed,
                model,
            } => {
                w.u8(*state as u8).u8(speed.get());
                gripper_model(&mut w, *model);
                cmd::SET_GRIPPER_STATE
            }
            Self::SetGripperValue {
                value,
                speed,
                model,
            } => {
                w.u8(value.get()).u8(speed.get());
                gripper_model(&mut w, *model);
                cmd::SET_GRIPPER_VALUE
            }
            Self::SetColor { rgb } => {
                w.u8(rgb.r).u8(rgb.g).u8(rgb.b);
                cmd::SET_COLOR
            }
            Self::SetHtsGripperTorque { torque } => {
                w.i16(*torque);
                cmd::SET_HTS_GRIPPER_TORQUE
            }
            Self::SetGripperProtectCurrent { current } => {
                w.i16(*current);
                cmd::SET_GRIPPER_PROTECT_CURRENT
            }
            Self::SetToolReference { pose } => {
                w.pose(pose);
                cmd::SET_TOOL_REFERENCE
            }
            Self::SetWorldReference { pose } => {
                w.pose(pose);
                cmd::SET_WORLD_REFERENCE
            }
            Self::SetReferenceFrame { frame } => {
                w.u8(*frame as u8);
                cmd::SET_REFERENCE_FRAME
            }
            Self::SetMovementType { mode } => {
                w.u8(*mode as u8);
                cmd::SET_MOVEMENT_TYPE
            }
            Self::SetEndType { end } => {
                w.u8(*end as u8);
                cmd::SET_END_TYPE
            }
            Self::SetBasicOutput { pin, high } => {
                w.u8(pin.gpio()).u8(u8::from(*high));
                cmd::SET_BASIC_OUTPUT
            }
            Self::GetBasicInput { pin } => {
                w.u8(pin.gpio());
                cmd::GET_BASIC_INPUT
            }
            Self::SetSsidPwd { payload } => {
                w.bytes(payload);
                cmd::SET_SSID_PWD
            }
            Self::SetServerPort { port } => {
                w.bytes(&port.to_be_bytes());
                cmd::SET_SERVER_PORT
            }
            Self::SetTransponderMode { mode } => {
                w.u8(*mode as u8);
                cmd::SET_TRANSPONDER_MODE
            }
            // Every data-less variant returned above through `no_data_code`.
            _ => 0,
        };
        (code, w)
    }
}

/// The wire byte of a [`ServoSelect`], given the byte this command uses for "all".
fn select_byte(s: ServoSelect, all: u8) -> u8 {
    match s {
        ServoSelect::All => all,
        ServoSelect::One(id) => id.get(),
    }
}

/// Appends the optional type / torque tail of 0x66/0x67.
fn gripper_model(w: &mut Writer, model: GripperModel) {
    match model {
        GripperModel::Default => {}
        GripperModel::Typed(t) => {
            w.u8(t.get());
        }
        GripperModel::TypedTorque(t, torque) => {
            w.u8(t.get()).u8(u8::from(torque));
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn parse(cmd: u8, data: &[u8]) -> Result<Request, CommandError> {
        Request::parse(&Frame::new(cmd, data).unwrap())
    }

    #[test]
    fn impossible_values_are_errors_not_commands() {
        use CommandError as E;
        let cases: &[(u8, &[u8], CommandError)] = &[
            (cmd::SEND_ANGLE, &[9, 0, 0, 50], E::BadJoint(9)),
            (cmd::SEND_ANGLE, &[0, 0, 0, 50], E::BadJoint(0)),
            (cmd::SEND_ANGLE, &[1, 0, 0, 0], E::BadSpeed(0)),
            (cmd::SEND_ANGLE, &[1, 0, 0, 200], E::BadSpeed(200)),
            (cmd::SEND_COORD, &[7, 0, 0, 50], E::BadAxis(7)),
            (cmd::JOG_RPY, &[4, 0, 50], E::BadAxis(4)),
            (cmd::JOG_ANGLE, &[1, 2, 50], E::BadDirection(2)),
            (cmd::GET_ENCODER, &[8], E::BadServo(8)),
            (cmd::SET_ENCODER, &[1, 0x10, 0x01, 50], E::BadEncoder(4097)),
            (cmd::SET_ENCODER, &[1, 0xFF, 0xFF], E::BadEncoder(-1)),
            (cmd::SET_DIGITAL_OUTPUT, &[39, 1], E::BadPin(39)),
            (cmd::SET_DIGITAL_OUTPUT, &[25, 1], E::BadPin(25)),
            (cmd::SET_PIN_MODE, &[39, 1], E::BadPin(39)),
            (cmd::SET_PIN_MODE, &[19, 3], E::BadFlag(3)),
            (cmd::SET_BASIC_OUTPUT, &[35, 1], E::BadPin(35)),
            (cmd::GET_BASIC_INPUT, &[2], E::BadPin(2)),
            (cmd::SET_FREE_MODE, &[2], E::BadFlag(2)),
            (cmd::SEND_COORDS, &[0; 14], E::BadSpeed(0)),
            (cmd::SET_GRIPPER_VALUE, &[101, 50], E::BadGripperValue(101)),
            (cmd::SET_GRIPPER_VALUE, &[50, 101], E::BadSpeed(101)),
            (cmd::SET_GRIPPER_STATE, &[2, 50], E::BadGripperValue(2)),
            (cmd::SET_GRIPPER_STATE, &[1, 50, 6], E::BadGripperValue(6)),
            (cmd::SET_GRIPPER_STATE, &[1, 50, 1, 2], E::BadFlag(2)),
            (
                cmd::SET_HTS_GRIPPER_TORQUE,
                &[0, 100],
                E::BadGripperSetting(100),
            ),
            (
                cmd::SET_GRIPPER_PROTECT_CURRENT,
                &[0, 0],
                E::BadGripperSetting(0),
            ),
            (cmd::SET_SERVO_DATA, &[1, 3, 0], E::BadAddress(3)),
            (cmd::SET_SERVO_DATA, &[1, 42, 8, 0, 0], E::BadFlag(0)),
            (cmd::FOCUS_SERVO, &[254], E::BadServo(254)),
            (cmd::BACKUP_SERVO_PARAMS, &[0], E::BadServo(0)),
            (
                cmd::IS_IN_POSITION,
                &[0, 0, 0, 0, 0, 0, 0, 0, 0, 0, 0, 0, 2],
                E::BadFlag(2),
            ),
        ];
        for (code, data, want) in cases {
            assert_eq!(parse(*code, data), Err(*want), "{code:#04x} {data:02x?}");
        }
    }

    #[test]
    fn unknown_command_and_unknown_layout_are_told_apart() {
        assert_eq!(
            parse(0x03, &[]),
            Err(CommandError::UnknownCommand { cmd: 0x03 })
        );
        assert_eq!(
            parse(0xFF, &[1, 2]),
            Err(CommandError::UnknownCommand { cmd: 0xFF })
        );
        for (code, len) in [
            (cmd::GET_ANGLES, 1),
            (cmd::SEND_ANGLES, 12),
            (cmd::SEND_COORDS, 15),
        ] {
            assert_eq!(
                parse(code, &[1; 20][..len]),
                Err(CommandError::BadLength {
                    cmd: code,
                    data_len: len as u8
                })
            );
        }
    }

    #[test]
    fn layouts_of_one_command_are_told_apart_by_length() {
        assert_eq!(parse(cmd::GET_COORDS, &[]), Ok(Request::GetCoords));
        assert!(matches!(
            parse(cmd::GET_COORDS, &[0; 12]),
            Ok(Request::AnglesToCoords { .. })
        ));
        assert_eq!(parse(cmd::JOG_STOP, &[]), Ok(Request::JogStop));
        assert!(matches!(
            parse(cmd::JOG_INCREMENT_COORD, &[3, 0xFF, 0xFA, 10]),
            Ok(Request::JogIncrementCoord {
                increment: AxisValue::Z(crate::units::DeciMm(-6)),
                ..
            })
        ));
        assert!(matches!(
            parse(cmd::SET_SERVO_DATA, &[1, 42, 0x08, 0x00, 1]),
            Ok(Request::SetServoData {
                value: ServoValue::Word(2048),
                ..
            })
        ));
        assert!(matches!(
            parse(cmd::SET_SERVO_DATA, &[1, 21, 0x00, 40, 0]),
            Ok(Request::SetServoData {
                value: ServoValue::Byte(40),
                ..
            })
        ));
        assert!(matches!(
            parse(cmd::SET_SERVO_DATA, &[1, 42, 7]),
            Ok(Request::SetServoData {
                value: ServoValue::Byte(7),
                ..
            })
        ));
        assert!(matches!(
            parse(cmd::SET_GRIPPER_STATE, &[1]),
            Ok(Request::SetGripperStateNoSpeed { .. })
        ));
    }

    #[test]
    fn send_coord_takes_both_axis_numberings_where_they_are_unambiguous() {
        use crate::units::{Centideg as C, DeciMm as M};
        let coord = |data: &[u8]| match parse(cmd::SEND_COORD, data) {
            Ok(Request::SendCoord { target, .. }) => Ok(target),
            other => Err(other),
        };
        // MyCobotBasic writeCoord(Axis::X, 200, 30): axis 0 (seed manual numbering).
        assert_eq!(coord(&[0, 0x07, 0xD0, 30]), Ok(AxisValue::X(M(2000))));
        // pymycobot send_coord(1, 200, 30) and send_coord(6, -90, 30).
        assert_eq!(coord(&[1, 0x07, 0xD0, 30]), Ok(AxisValue::X(M(2000))));
        assert_eq!(coord(&[6, 0xDC, 0xD8, 30]), Ok(AxisValue::Rz(C(-9000))));
        // 1..=5 follow pymycobot: 3 is z, not the seed's rx.
        assert_eq!(coord(&[3, 0x00, 0x64, 30]), Ok(AxisValue::Z(M(100))));
        assert_eq!(
            parse(cmd::SEND_COORD, &[7, 0, 0, 30]),
            Err(CommandError::BadAxis(7))
        );
        // Jog coord keeps pymycobot's 1..=6 only.
        assert_eq!(
            parse(cmd::JOG_COORD, &[0, 1, 30]),
            Err(CommandError::BadAxis(0))
        );
    }

    #[test]
    fn my_cobot_basic_pid_and_arc_layouts() {
        // setPid: FE FE 08 2C p i d p i d FA.
        assert_eq!(
            parse(cmd::SET_PID, &[10, 0, 1, 32, 0, 32]),
            Ok(Request::SetPid {
                gains: [10, 0, 1, 32, 0, 32]
            })
        );
        assert_eq!(parse(cmd::GET_PID, &[]), Ok(Request::GetPid));
        assert_eq!(Request::GetPid.reply_kind(), ReplyKind::Bytes6);
        let pose = |x: i16| Pose {
            x: crate::units::DeciMm(x),
            ..Pose::default()
        };
        let three = Request::MoveCCoords {
            begin: pose(1),
            middle: pose(2),
            end: pose(3),
        };
        let frame = three.to_frame();
        // MOVEC_COORDS_DEFAULT_LEN 38: three poses, no speed.
        assert_eq!(frame.data().len(), 36);
        assert_eq!(Request::parse(&frame), Ok(three));
        let two = Request::MoveCCoordsFromHere {
            middle: pose(2),
            end: pose(3),
        };
        assert_eq!(two.to_frame().data().len(), 24);
        assert_eq!(Request::parse(&two.to_frame()), Ok(two));
        assert!(matches!(
            parse(cmd::MOVE_C_COORDS, &[0; 24]),
            Err(CommandError::BadLength { .. })
        ));
    }

    #[test]
    fn drag_teaching_replies_are_what_pymycobot_parses() {
        use super::super::{DragPoint, Reply};
        for r in [
            Request::DragStartRecord,
            Request::DragEndRecord,
            Request::DragGetRecordLen,
            Request::DragClearRecordData,
        ] {
            assert_eq!(r.reply_kind(), ReplyKind::Int16, "{r:?}");
        }
        let point = DragPoint {
            encoders: [2048, 2100, 1990, 2048, 3000, 1024].map(Steps),
            speeds_steps_per_s: [0, 120, -40, 0, 6000, 1],
        };
        let frame = Reply::DragPoint(Some(point)).to_frame(cmd::DRAG_GET_RECORD_DATA);
        // Joint by joint, encoder then speed: pymycobot takes the even values as encoders.
        assert_eq!(
            frame.data().get(..8),
            Some(&[0x08, 0x00, 0x00, 0x00, 0x08, 0x34, 0x00, 0x78][..])
        );
        assert_eq!(
            Reply::parse(ReplyKind::DragPoint, &frame),
            Ok(Reply::DragPoint(Some(point)))
        );
        let none = Reply::DragPoint(None).to_frame(cmd::DRAG_GET_RECORD_DATA);
        assert_eq!(none.data(), &[0; 24]);
        assert_eq!(
            Reply::parse(ReplyKind::DragPoint, &none),
            Ok(Reply::DragPoint(None))
        );
    }

    #[test]
    fn reply_kinds_fit_pymycobot_limit() {
        // Every request kind's reply has at most 28 data bytes.
        use super::super::Reply;
        let biggest = Reply::AnglesAndCoords {
            angles: [Centideg(0); 6],
            coords: Pose::default(),
        };
        assert!(biggest.to_frame(cmd::GET_ANGLES_COORDS).data().len() <= 28);
    }
}
