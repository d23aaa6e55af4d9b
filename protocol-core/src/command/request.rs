//! [`Request`]: every host command as a typed, validated value.
//!
//! The commands are one table (the `requests!` invocation below, the macro in
//! `request/table.rs`): each entry holds one command's doc, fields, code, reply kind, layout
//! (data length), parse and emit, so everything about a command is in one place and a new
//! command is one new entry, which every match over [`Request`] then handles.

use heapless::Vec;

use crate::frame::{Frame, MAX_DATA};
use crate::units::{Centideg, Decideg, SpeedPercent, Steps};

use super::cmd;
use super::error::CommandError;
use super::reply::ReplyKind;
use super::types::{
    AtomPin, Axis, AxisValue, BasicInputPin, BasicOutputPin, CollisionThreshold, DataWidth,
    Dialect, Direction, EndType, GripperModel, GripperSpeed, GripperState, GripperType,
    GripperValue, JointId, MoveMode, PinMode, Pose, PositionTarget, ReferenceFrame, Rgb, RpyAxis,
    ServoId, ServoSelect, ServoValue, TransponderMode,
};
use super::wire::Writer;

mod fields;
mod table;

pub use fields::MAX_DRAG_SPEED;

use fields::Fields;
use table::requests;

/// Allowed HTS gripper torque range of 0x35 (pymycobot: 150..=980).
pub const HTS_TORQUE_RANGE: core::ops::RangeInclusive<i16> = 150..=980;
/// Allowed gripper protect current range of 0x39 (pymycobot: 1..=500).
pub const PROTECT_CURRENT_RANGE: core::ops::RangeInclusive<i16> = 1..=500;

requests! {
    /// One host command, typed and validated: every field holds a value the protocol allows.
    ///
    /// Parse with [`Request::parse`], write with [`Request::to_frame`]. Variants follow
    /// `protocol.md` section 5; each doc names the code and, where a command has several
    /// layouts, the LEN of this one.
    #[derive(Clone, Debug, PartialEq, Eq, Hash)]
    pub enum Request {
        // --- status and system ---

        /// 0x01 get modify version.
        GetModifyVersion = cmd::GET_MODIFY_VERSION, reply ReplyKind::Byte;
        /// 0x02 get system version.
        GetSystemVersion = cmd::GET_SYSTEM_VERSION, reply ReplyKind::Byte;
        /// 0x05 clear queue.
        ClearQueue = cmd::CLEAR_QUEUE, reply ReplyKind::Ack;
        /// 0x06 check async or sync.
        CheckAsyncOrSync = cmd::CHECK_ASYNC_OR_SYNC, reply ReplyKind::Byte;
        /// 0x07 get error information.
        GetErrorInfo = cmd::GET_ERROR_INFO, reply ReplyKind::Byte;
        /// 0x08 clear error information.
        ClearErrorInfo = cmd::CLEAR_ERROR_INFO, reply ReplyKind::Ack;
        /// 0x10 power on.
        PowerOn = cmd::POWER_ON, reply ReplyKind::Ack;
        /// 0x11 power off.
        PowerOff = cmd::POWER_OFF, reply ReplyKind::Ack;
        /// 0x12 is powered on.
        IsPowerOn = cmd::IS_POWER_ON, reply ReplyKind::Byte;
        /// 0x13 release all servos. `undamped`: `None` for LEN 2, else the flag byte of LEN 3
        /// (1 = undamped, 0 = damped).
        ReleaseAllServos {
            /// Optional undamped flag.
            undamped: Option<bool>,
        } = cmd::RELEASE_ALL_SERVOS, reply ReplyKind::Ack,
        data 0 | 1 => |f| Self::ReleaseAllServos { undamped: f.optional(Fields::flag)? },
        emit |w| {
            if let Some(u) = undamped {
                w.u8(u8::from(*u));
            }
        };
        /// 0x14 is controller connected.
        IsControllerConnected = cmd::IS_CONTROLLER_CONNECTED, reply ReplyKind::Byte;
        /// 0x15 read next error.
        ReadNextError = cmd::READ_NEXT_ERROR, reply ReplyKind::ServoErrors;
        /// 0x16 set fresh mode.
        SetFreshMode {
            /// True: the newest command preempts; false: commands queue.
            fresh: bool,
        } = cmd::SET_FRESH_MODE, reply ReplyKind::Ack,
        data 1 => |f| Self::SetFreshMode { fresh: f.flag()? },
        emit |w| { w.u8(u8::from(*fresh)); };
        /// 0x17 get fresh mode.
        GetFreshMode = cmd::GET_FRESH_MODE, reply ReplyKind::Byte;
        /// 0x1A set free mode.
        SetFreeMode {
            /// Free mode on.
            on: bool,
        } = cmd::SET_FREE_MODE, reply ReplyKind::Ack,
        data 1 => |f| Self::SetFreeMode { on: f.flag()? },
        emit |w| { w.u8(u8::from(*on)); };
        /// 0x1B is free mode.
        IsFreeMode = cmd::IS_FREE_MODE, reply ReplyKind::Byte;
        /// 0x1D set vision mode.
        SetVisionMode {
            /// Vision mode on.
            on: bool,
        } = cmd::SET_VISION_MODE, reply ReplyKind::Ack,
        data 1 => |f| Self::SetVisionMode { on: f.flag()? },
        emit |w| { w.u8(u8::from(*on)); };
        /// 0xD8 get reboot count.
        GetRebootCount = cmd::GET_REBOOT_COUNT, reply ReplyKind::Int16;

        // --- motion ---

        /// 0x20 get angles.
        GetAngles = cmd::GET_ANGLES, reply ReplyKind::Angles;
        /// 0x21 send one joint angle.
        SendAngle {
            /// Joint.
            joint: JointId,
            /// Target angle.
            angle: Centideg,
            /// Speed.
            speed: SpeedPercent,
        } = cmd::SEND_ANGLE, reply ReplyKind::Ack,
        data 4 => |f| Self::SendAngle {
            joint: f.joint()?,
            angle: Centideg(f.i16()?),
            speed: f.speed()?,
        },
        emit |w| { w.u8(joint.get()).i16(angle.0).u8(speed.get()); };
        /// 0x22 send six joint angles.
        SendAngles {
            /// Target angles, joints 1..6.
            angles: [Centideg; 6],
            /// Speed.
            speed: SpeedPercent,
        } = cmd::SEND_ANGLES, reply ReplyKind::Ack,
        data 13 => |f| Self::SendAngles { angles: f.centideg6()?, speed: f.speed()? },
        emit |w| { w.centideg6(angles).u8(speed.get()); };
        /// 0x23 (LEN 2) get coords.
        GetCoords = cmd::GET_COORDS, reply ReplyKind::Coords;
        /// 0x23 (LEN 0x0E) angles to coords: forward kinematics, no motion.
        AnglesToCoords {
            /// Joint angles.
            angles: [Centideg; 6],
        } = cmd::GET_COORDS, reply ReplyKind::Coords,
        data 12 => |f| Self::AnglesToCoords { angles: f.centideg6()? },
        emit |w| { w.centideg6(angles); };
        /// 0x24 send one coordinate.
        SendCoord {
            /// Axis and target value.
            target: AxisValue,
            /// Speed.
            speed: SpeedPercent,
        } = cmd::SEND_COORD, reply ReplyKind::Ack,
        data 4 => |f| Self::SendCoord { target: f.send_coord_axis_value()?, speed: f.speed()? },
        emit |w| { w.u8(target.axis() as u8).i16(target.raw()).u8(speed.get()); };
        /// 0x25 send a pose: LEN 0x0F without mode, LEN 0x10 with mode.
        SendCoords {
            /// Target pose.
            pose: Pose,
            /// Speed.
            speed: SpeedPercent,
            /// Interpolation; `None` when the client sent no mode byte.
            mode: Option<MoveMode>,
        } = cmd::SEND_COORDS, reply ReplyKind::Ack,
        data 13 | 14 => |f| Self::SendCoords {
            pose: f.pose()?,
            speed: f.speed()?,
            mode: f.optional(|f| f.enum_byte(MoveMode::from_u8))?,
        },
        emit |w| {
            w.pose(pose).u8(speed.get());
            if let Some(m) = mode {
                w.u8(*m as u8);
            }
        };
        /// 0x26 pause.
        Pause = cmd::PAUSE, reply ReplyKind::Ack;
        /// 0x27 is paused.
        IsPaused = cmd::IS_PAUSED, reply ReplyKind::Byte;
        /// 0x28 resume.
        Resume = cmd::RESUME, reply ReplyKind::Ack;
        /// 0x29 stop.
        Stop = cmd::STOP, reply ReplyKind::Ack;
        /// 0x2A is in position.
        IsInPosition {
            /// Angles (flag 0) or coords (flag 1).
            target: PositionTarget,
        } = cmd::IS_IN_POSITION, reply ReplyKind::Byte,
        data 13 => |f| {
            let values = f.i16x6()?;
            Self::IsInPosition {
                target: match f.flag()? {
                    false => PositionTarget::Angles(values.map(Centideg)),
                    true => PositionTarget::Coords(Pose::from_array(values)),
                },
            }
        },
        emit |w| {
            match target {
                PositionTarget::Angles(a) => w.centideg6(a).u8(0),
                PositionTarget::Coords(p) => w.pose(p).u8(1),
            };
        };
        /// 0x2B is moving.
        IsMoving = cmd::IS_MOVING, reply ReplyKind::Byte;
        /// 0x2C (LEN 8, MyCobotBasic `setPid`) set the servos' position-loop gains: P, I, D of
        /// joints 1..3, then P, I, D of joints 4..6, one byte each.
        SetPid {
            /// P, I, D of joints 1..3, then of joints 4..6.
            gains: [u8; 6],
        } = cmd::SET_PID, reply ReplyKind::Ack,
        data 6 => |f| Self::SetPid {
            gains: [f.u8()?, f.u8()?, f.u8()?, f.u8()?, f.u8()?, f.u8()?],
        },
        emit |w| { w.bytes(gains); };
        /// 0x2D (MyCobotBasic `getPid`) get the gains as 0x2C sets them.
        GetPid = cmd::GET_PID, reply ReplyKind::Bytes6;
        /// 0x8B (LEN 38, MyCobotBasic `moveCCoords(begin, middle, end)`) go to `begin`, then
        /// along the circle through `begin`, `middle` and `end` to `end`, at the default speed
        /// (0x41).
        MoveCCoords {
            /// Where the arc starts.
            begin: Pose,
            /// A pose the arc passes through.
            middle: Pose,
            /// Where the arc ends.
            end: Pose,
        } = cmd::MOVE_C_COORDS, reply ReplyKind::Ack,
        data 36 => |f| Self::MoveCCoords { begin: f.pose()?, middle: f.pose()?, end: f.pose()? },
        emit |w| { w.pose(begin).pose(middle).pose(end); };
        /// 0x8C (LEN 26, MyCobotBasic `moveCCoords(middle, end)`) along the circle through the
        /// present pose, `middle` and `end` to `end`, at the default speed (0x41).
        MoveCCoordsFromHere {
            /// A pose the arc passes through.
            middle: Pose,
            /// Where the arc ends.
            end: Pose,
        } = cmd::MOVE_C_COORDS_FROM_HERE, reply ReplyKind::Ack,
        data 24 => |f| Self::MoveCCoordsFromHere { middle: f.pose()?, end: f.pose()? },
        emit |w| { w.pose(middle).pose(end); };
        /// 0x8D solve inverse kinematics.
        SolveIk {
            /// Pose to reach.
            target: Pose,
            /// Current joint angles (the seed of the solution).
            current: [Centideg; 6],
        } = cmd::SOLVE_INV_KINEMATICS, reply ReplyKind::Angles,
        data 24 => |f| Self::SolveIk { target: f.pose()?, current: f.centideg6()? },
        emit |w| { w.pose(target).centideg6(current); };
        /// 0xD5 get angles and coords.
        GetAnglesCoords = cmd::GET_ANGLES_COORDS, reply ReplyKind::AnglesAndCoords;
        /// 0xF6 get planned angles.
        GetPlannedAngles = cmd::GET_PLANNED_ANGLES, reply ReplyKind::Angles;
        /// 0xF7 get planned coords.
        GetPlannedCoords = cmd::GET_PLANNED_COORDS, reply ReplyKind::Coords;
        /// 0xD4 move round (pymycobot `move_round`).
        MoveRound = cmd::MOVE_ROUND, reply ReplyKind::Ack;
        /// 0xD7 set four pieces zero (pymycobot `set_four_pieces_zero`).
        SetFourPiecesZero = cmd::SET_FOUR_PIECES_ZERO, reply ReplyKind::Byte;

        // --- jog ---

        /// 0x30 jog one joint until jog stop / stop.
        JogAngle {
            /// Joint.
            joint: JointId,
            /// Direction.
            direction: Direction,
            /// Speed.
            speed: SpeedPercent,
        } = cmd::JOG_ANGLE, reply ReplyKind::Ack,
        data 3 => |f| Self::JogAngle {
            joint: f.joint()?,
            direction: f.direction()?,
            speed: f.speed()?,
        },
        emit |w| { w.u8(joint.get()).u8(*direction as u8).u8(speed.get()); };
        /// 0x31 jog rotation about a base axis.
        JogRpy {
            /// Axis.
            axis: RpyAxis,
            /// Direction.
            direction: Direction,
            /// Speed.
            speed: SpeedPercent,
        } = cmd::JOG_RPY, reply ReplyKind::Ack,
        data 3 => |f| Self::JogRpy {
            axis: f.rpy_axis()?,
            direction: f.direction()?,
            speed: f.speed()?,
        },
        emit |w| { w.u8(*axis as u8).u8(*direction as u8).u8(speed.get()); };
        /// 0x32 jog along / about a Cartesian axis.
        JogCoord {
            /// Axis.
            axis: Axis,
            /// Direction.
            direction: Direction,
            /// Speed.
            speed: SpeedPercent,
        } = cmd::JOG_COORD, reply ReplyKind::Ack,
        data 3 => |f| Self::JogCoord {
            axis: f.axis()?,
            direction: f.direction()?,
            speed: f.speed()?,
        },
        emit |w| { w.u8(*axis as u8).u8(*direction as u8).u8(speed.get()); };
        /// 0x33 jog one joint by an increment.
        JogIncrementAngle {
            /// Joint.
            joint: JointId,
            /// Increment.
            increment: Centideg,
            /// Speed.
            speed: SpeedPercent,
        } = cmd::JOG_INCREMENT_ANGLE, reply ReplyKind::Ack,
        data 4 => |f| Self::JogIncrementAngle {
            joint: f.joint()?,
            increment: Centideg(f.i16()?),
            speed: f.speed()?,
        },
        emit |w| { w.u8(joint.get()).i16(increment.0).u8(speed.get()); };
        /// 0x34 (LEN 2) jog stop.
        JogStop = cmd::JOG_STOP, reply ReplyKind::Ack;
        /// 0x34 (LEN 6) jog increment coord.
        JogIncrementCoord {
            /// Axis and increment.
            increment: AxisValue,
            /// Speed.
            speed: SpeedPercent,
        } = cmd::JOG_INCREMENT_COORD, reply ReplyKind::Ack,
        data 4 => |f| Self::JogIncrementCoord { increment: f.axis_value()?, speed: f.speed()? },
        emit |w| { w.u8(increment.axis() as u8).i16(increment.raw()).u8(speed.get()); };

        // --- encoders, speed, limits ---

        /// 0x3A set one servo's encoder: LEN 5 without speed (seed manual), LEN 6 with speed.
        SetEncoder {
            /// Servo 1..7.
            servo: ServoId,
            /// Target, 0..=4096.
            encoder: Steps,
            /// Speed; `None` for the LEN-5 form.
            speed: Option<SpeedPercent>,
        } = cmd::SET_ENCODER, reply ReplyKind::Ack,
        data 3 | 4 => |f| Self::SetEncoder {
            servo: f.servo()?,
            encoder: f.encoder()?,
            speed: f.optional(Fields::speed)?,
        },
        emit |w| {
            w.u8(servo.get()).i16(encoder.0);
            if let Some(s) = speed {
                w.u8(s.get());
            }
        };
        /// 0x3B get one servo's encoder.
        GetEncoder {
            /// Servo 1..7.
            servo: ServoId,
        } = cmd::GET_ENCODER, reply ReplyKind::Int16,
        data 1 => |f| Self::GetEncoder { servo: f.servo()? },
        emit |w| { w.u8(servo.get()); };
        /// 0x3C set six encoders.
        SetEncoders {
            /// Targets, 0..=4096 each.
            encoders: [Steps; 6],
            /// Speed.
            speed: SpeedPercent,
        } = cmd::SET_ENCODERS, reply ReplyKind::Ack,
        data 13 => |f| Self::SetEncoders { encoders: f.encoders()?, speed: f.speed()? },
        emit |w| { w.steps6(encoders).u8(speed.get()); };
        /// 0x3D get six encoders.
        GetEncoders = cmd::GET_ENCODERS, reply ReplyKind::Encoders;
        /// 0x3E set six encoders with per-servo speeds.
        SetEncodersDrag {
            /// Targets, 0..=4096 each.
            encoders: [Steps; 6],
            /// Servo speeds, steps per second, 0..=6000 each.
            speeds_steps_per_s: [i16; 6],
        } = cmd::SET_ENCODERS_DRAG, reply ReplyKind::Ack,
        data 24 => |f| Self::SetEncodersDrag {
            encoders: f.encoders()?,
            speeds_steps_per_s: f.drag_speeds()?,
        },
        emit |w| { w.steps6(encoders).i16s(speeds_steps_per_s); };
        /// 0x40 get speed.
        GetSpeed = cmd::GET_SPEED, reply ReplyKind::Byte;
        /// 0x41 set speed.
        SetSpeed {
            /// Default speed.
            speed: SpeedPercent,
        } = cmd::SET_SPEED, reply ReplyKind::Ack,
        data 1 => |f| Self::SetSpeed { speed: f.speed()? },
        emit |w| { w.u8(speed.get()); };
        /// 0x4A get joint min limit.
        GetJointMin {
            /// Joint.
            joint: JointId,
        } = cmd::GET_JOINT_MIN, reply ReplyKind::JointLimit,
        data 1 => |f| Self::GetJointMin { joint: f.joint()? },
        emit |w| { w.u8(joint.get()); };
        /// 0x4B get joint max limit.
        GetJointMax {
            /// Joint.
            joint: JointId,
        } = cmd::GET_JOINT_MAX, reply ReplyKind::JointLimit,
        data 1 => |f| Self::GetJointMax { joint: f.joint()? },
        emit |w| { w.u8(joint.get()); };
        /// 0x4C set joint min limit.
        SetJointMin {
            /// Joint.
            joint: JointId,
            /// Limit (tenths of a degree on the wire).
            limit: Decideg,
        } = cmd::SET_JOINT_MIN, reply ReplyKind::Ack,
        data 3 => |f| Self::SetJointMin { joint: f.joint()?, limit: Decideg(f.i16()?) },
        emit |w| { w.u8(joint.get()).i16(limit.0); };
        /// 0x4D set joint max limit.
        SetJointMax {
            /// Joint.
            joint: JointId,
            /// Limit (tenths of a degree on the wire).
            limit: Decideg,
        } = cmd::SET_JOINT_MAX, reply ReplyKind::Ack,
        data 3 => |f| Self::SetJointMax { joint: f.joint()?, limit: Decideg(f.i16()?) },
        emit |w| { w.u8(joint.get()).i16(limit.0); };

        // --- servos ---

        /// 0x50 is servo enabled.
        IsServoEnabled {
            /// Servo.
            servo: ServoId,
        } = cmd::IS_SERVO_ENABLED, reply ReplyKind::ServoEnabled,
        data 1 => |f| Self::IsServoEnabled { servo: f.servo()? },
        emit |w| { w.u8(servo.get()); };
        /// 0x51 are all servos enabled.
        AreAllServosEnabled = cmd::ARE_ALL_SERVOS_ENABLED, reply ReplyKind::Byte;
        /// 0x52 write a servo register: LEN 5 one byte; LEN 7 a 16-bit value and a width flag
        /// (`01` two bytes, `00` one byte: the value must fit in it).
        SetServoData {
            /// Servo.
            servo: ServoId,
            /// Register address, >= 5.
            address: u8,
            /// Value.
            value: ServoValue,
        } = cmd::SET_SERVO_DATA, reply ReplyKind::Ack,
        data 3 | 5 => |f| {
            let servo = f.servo()?;
            let address = f.address()?;
            let value = if f.remaining() == 1 {
                ServoValue::Byte(f.u8()?)
            } else {
                let word = f.i16()? as u16;
                // pymycobot's `set_servo_data(.., mode)` always sends the value in two bytes
                // and the flag says the register's width: 1 a word, 0 one byte (the low one).
                match (f.u8()?, u8::try_from(word)) {
                    (1, _) => ServoValue::Word(word),
                    (0, Ok(byte)) => ServoValue::Byte(byte),
                    (v, _) => return Err(CommandError::BadFlag(v)),
                }
            };
            Self::SetServoData { servo, address, value }
        },
        emit |w| {
            w.u8(servo.get()).u8(*address);
            match value {
                ServoValue::Byte(b) => w.u8(*b),
                ServoValue::Word(v) => w.bytes(&v.to_be_bytes()).u8(1),
            };
        };
        /// 0x53 read a servo register: LEN 4 (one byte) or LEN 5 with a width byte.
        GetServoData {
            /// Servo.
            servo: ServoId,
            /// Register address.
            address: u8,
            /// Width byte; `None` for the LEN-4 form (one byte).
            width: Option<DataWidth>,
        } = cmd::GET_SERVO_DATA,
        reply match width {
            Some(DataWidth::Word) => ReplyKind::Int16,
            Some(DataWidth::Byte) | None => ReplyKind::Byte,
        },
        data 2 | 3 => |f| Self::GetServoData {
            servo: f.servo()?,
            address: f.u8()?,
            width: f.optional(|f| f.enum_byte(DataWidth::from_u8))?,
        },
        emit |w| {
            w.u8(servo.get()).u8(*address);
            if let Some(wd) = width {
                w.u8(*wd as u8);
            }
        };
        /// 0x54 make the servo's current position its zero.
        SetServoCalibration {
            /// Servo.
            servo: ServoId,
        } = cmd::SET_SERVO_CALIBRATION, reply ReplyKind::Ack,
        data 1 => |f| Self::SetServoCalibration { servo: f.servo()? },
        emit |w| { w.u8(servo.get()); };
        /// 0x55 brake one joint.
        JointBrake {
            /// Servo.
            servo: ServoId,
        } = cmd::JOINT_BRAKE, reply ReplyKind::Ack,
        data 1 => |f| Self::JointBrake { servo: f.servo()? },
        emit |w| { w.u8(servo.get()); };
        /// 0x56 release one servo: LEN 3, or LEN 4 with the undamped flag.
        ReleaseServo {
            /// Servo.
            servo: ServoId,
            /// Optional undamped flag.
            undamped: Option<bool>,
        } = cmd::RELEASE_SERVO, reply ReplyKind::Ack,
        data 1 | 2 => |f| Self::ReleaseServo {
            servo: f.servo()?,
            undamped: f.optional(Fields::flag)?,
        },
        emit |w| {
            w.u8(servo.get());
            if let Some(u) = undamped {
                w.u8(u8::from(*u));
            }
        };
        /// 0x57 focus servo (torque on); wire 0 = all.
        FocusServo {
            /// Servo or all.
            servo: ServoSelect,
        } = cmd::FOCUS_SERVO, reply ReplyKind::Ack,
        data 1 => |f| Self::FocusServo { servo: f.servo_or_all(0)? },
        emit |w| { w.u8(select_byte(*servo, 0)); };
        /// 0xE1 get servo speeds.
        GetServoSpeeds = cmd::GET_SERVO_SPEEDS, reply ReplyKind::Int16x6;
        /// 0xE2 get servo currents.
        GetServoCurrents = cmd::GET_SERVO_CURRENTS, reply ReplyKind::Int16x6;
        /// 0xE3 get servo voltages.
        GetServoVoltages = cmd::GET_SERVO_VOLTAGES, reply ReplyKind::Bytes6;
        /// 0xE4 get servo status.
        GetServoStatus = cmd::GET_SERVO_STATUS, reply ReplyKind::Bytes6;
        /// 0xE5 get servo temperatures.
        GetServoTemps = cmd::GET_SERVO_TEMPS, reply ReplyKind::Bytes6;
        /// 0xEA back up servo parameters; wire 254 = all.
        BackupServoParams {
            /// Servo or all.
            servo: ServoSelect,
        } = cmd::BACKUP_SERVO_PARAMS, reply ReplyKind::Ack,
        data 1 => |f| Self::BackupServoParams { servo: f.servo_or_all(254)? },
        emit |w| { w.u8(select_byte(*servo, 254)); };
        /// 0xEB restore servo parameters; wire 254 = all.
        RestoreServoParams {
            /// Servo or all.
            servo: ServoSelect,
        } = cmd::RESTORE_SERVO_PARAMS, reply ReplyKind::Ack,
        data 1 => |f| Self::RestoreServoParams { servo: f.servo_or_all(254)? },
        emit |w| { w.u8(select_byte(*servo, 254)); };

        // --- collision protection ---

        /// 0x74 set collision mode (protection on or off).
        SetCollisionMode {
            /// Collision protection on.
            on: bool,
        } = cmd::SET_COLLISION_MODE, reply ReplyKind::Ack,
        data 1 => |f| Self::SetCollisionMode { on: f.flag()? },
        emit |w| { w.u8(u8::from(*on)); };
        /// 0xFD get collision mode.
        GetCollisionMode = cmd::GET_COLLISION_MODE, reply ReplyKind::Byte;
        /// 0x75 set one joint's collision threshold.
        SetCollisionThreshold {
            /// Joint.
            joint: JointId,
            /// Threshold, 50..=250 (smaller triggers more easily).
            threshold: CollisionThreshold,
        } = cmd::SET_COLLISION_THRESHOLD, reply ReplyKind::Ack,
        data 2 => |f| Self::SetCollisionThreshold {
            joint: f.joint()?,
            threshold: f.collision_threshold()?,
        },
        emit |w| { w.u8(joint.get()).u8(threshold.get()); };
        /// 0x76 get the six joints' collision thresholds.
        GetCollisionThresholds = cmd::GET_COLLISION_THRESHOLDS, reply ReplyKind::Bytes6;

        // --- Atom IO, LED, gripper ---

        /// 0x60 set an Atom pin's mode.
        SetPinMode {
            /// Pin.
            pin: AtomPin,
            /// Mode (pin 39 is input only).
            mode: PinMode,
        } = cmd::SET_PIN_MODE, reply ReplyKind::Ack,
        data 2 => |f| {
            let pin = f.atom_pin()?;
            let mode = f.enum_byte(PinMode::from_u8)?;
            if mode == PinMode::Output && !pin.can_output() {
                return Err(CommandError::BadPin(pin.gpio()));
            }
            Self::SetPinMode { pin, mode }
        },
        emit |w| { w.u8(pin.gpio()).u8(*mode as u8); };
        /// 0x61 set an Atom digital output.
        SetDigitalOutput {
            /// Pin (never 39).
            pin: AtomPin,
            /// High.
            high: bool,
        } = cmd::SET_DIGITAL_OUTPUT, reply ReplyKind::Ack,
        data 2 => |f| Self::SetDigitalOutput { pin: f.atom_output_pin()?, high: f.flag()? },
        emit |w| { w.u8(pin.gpio()).u8(u8::from(*high)); };
        /// 0x62 get an Atom digital input.
        GetDigitalInput {
            /// Pin.
            pin: AtomPin,
        } = cmd::GET_DIGITAL_INPUT, reply ReplyKind::PinLevel,
        data 1 => |f| Self::GetDigitalInput { pin: f.atom_pin()? },
        emit |w| { w.u8(pin.gpio()); };
        /// 0x64 set an Atom PWM output.
        SetPwmOutput {
            /// Pin (never 39).
            pin: AtomPin,
            /// Frequency, hertz.
            frequency_hz: u16,
            /// Duty, 0..=255 of full scale.
            duty: u8,
        } = cmd::SET_PWM_OUTPUT, reply ReplyKind::Ack,
        data 4 => |f| Self::SetPwmOutput {
            pin: f.atom_output_pin()?,
            frequency_hz: f.i16()? as u16,
            duty: f.u8()?,
        },
        emit |w| { w.u8(pin.gpio()).bytes(&frequency_hz.to_be_bytes()).u8(*duty); };
        /// 0x65 get gripper value: LEN 2, or LEN 3 with a gripper type.
        GetGripperValue {
            /// Gripper type, if given.
            gripper: Option<GripperType>,
        } = cmd::GET_GRIPPER_VALUE, reply ReplyKind::Byte,
        data 0 | 1 => |f| Self::GetGripperValue { gripper: f.optional(Fields::gripper_type)? },
        emit |w| {
            if let Some(g) = gripper {
                w.u8(g.get());
            }
        };
        /// 0x66 (LEN 3, seed manual) set gripper state with no speed.
        SetGripperStateNoSpeed {
            /// State.
            state: GripperState,
        } = cmd::SET_GRIPPER_STATE, reply ReplyKind::Ack,
        data 1 => |f| Self::SetGripperStateNoSpeed { state: f.gripper_state()? },
        emit |w| { w.u8(*state as u8); };
        /// 0x66 set gripper state: LEN 4, 5 (type) or 6 (type, torque).
        SetGripperState {
            /// State.
            state: GripperState,
            /// Speed.
            speed: GripperSpeed,
            /// Optional type / torque tail.
            model: GripperModel,
        } = cmd::SET_GRIPPER_STATE, reply ReplyKind::Ack,
        data 2..=4 => |f| Self::SetGripperState {
            state: f.gripper_state()?,
            speed: f.gripper_speed()?,
            model: f.gripper_model()?,
        },
        emit |w| {
            w.u8(*state as u8).u8(speed.get());
            gripper_model(w, *model);
        };
        /// 0x67 set gripper opening: LEN 4, 5 (type) or 6 (type, torque).
        SetGripperValue {
            /// Opening.
            value: GripperValue,
            /// Speed.
            speed: GripperSpeed,
            /// Optional type / torque tail.
            model: GripperModel,
        } = cmd::SET_GRIPPER_VALUE, reply ReplyKind::Ack,
        data 2..=4 => |f| Self::SetGripperValue {
            value: f.gripper_value()?,
            speed: f.gripper_speed()?,
            model: f.gripper_model()?,
        },
        emit |w| {
            w.u8(value.get()).u8(speed.get());
            gripper_model(w, *model);
        };
        /// 0x68 calibrate the gripper.
        SetGripperCalibration = cmd::SET_GRIPPER_CALIBRATION, reply ReplyKind::Ack;
        /// 0x69 is gripper moving.
        IsGripperMoving = cmd::IS_GRIPPER_MOVING, reply ReplyKind::Byte;
        /// 0x6A set the Atom LED colour.
        SetColor {
            /// Colour.
            rgb: Rgb,
        } = cmd::SET_COLOR, reply ReplyKind::Ack,
        data 3 => |f| Self::SetColor { rgb: Rgb { r: f.u8()?, g: f.u8()?, b: f.u8()? } },
        emit |w| { w.u8(rgb.r).u8(rgb.g).u8(rgb.b); };
        /// 0x35 set HTS gripper torque, 150..=980.
        SetHtsGripperTorque {
            /// Torque.
            torque: i16,
        } = cmd::SET_HTS_GRIPPER_TORQUE, reply ReplyKind::Ack,
        data 2 => |f| Self::SetHtsGripperTorque { torque: f.limited_i16(HTS_TORQUE_RANGE)? },
        emit |w| { w.i16(*torque); };
        /// 0x36 get HTS gripper torque.
        GetHtsGripperTorque = cmd::GET_HTS_GRIPPER_TORQUE, reply ReplyKind::Int16;
        /// 0x37 get gripper protect current.
        GetGripperProtectCurrent = cmd::GET_GRIPPER_PROTECT_CURRENT, reply ReplyKind::Int16;
        /// 0x38 init gripper.
        InitGripper = cmd::INIT_GRIPPER, reply ReplyKind::Byte;
        /// 0x39 set gripper protect current, 1..=500.
        SetGripperProtectCurrent {
            /// Current.
            current: i16,
        } = cmd::SET_GRIPPER_PROTECT_CURRENT, reply ReplyKind::Ack,
        data 2 => |f| Self::SetGripperProtectCurrent {
            current: f.limited_i16(PROTECT_CURRENT_RANGE)?,
        },
        emit |w| { w.i16(*current); };

        // --- coordinate frames ---

        /// 0x81 set tool reference.
        SetToolReference {
            /// Tool pose in the flange frame.
            pose: Pose,
        } = cmd::SET_TOOL_REFERENCE, reply ReplyKind::Ack,
        data 12 => |f| Self::SetToolReference { pose: f.pose()? },
        emit |w| { w.pose(pose); };
        /// 0x82 get tool reference.
        GetToolReference = cmd::GET_TOOL_REFERENCE, reply ReplyKind::Coords;
        /// 0x83 set world reference.
        SetWorldReference {
            /// Base pose in the world frame.
            pose: Pose,
        } = cmd::SET_WORLD_REFERENCE, reply ReplyKind::Ack,
        data 12 => |f| Self::SetWorldReference { pose: f.pose()? },
        emit |w| { w.pose(pose); };
        /// 0x84 get world reference.
        GetWorldReference = cmd::GET_WORLD_REFERENCE, reply ReplyKind::Coords;
        /// 0x85 set reference frame.
        SetReferenceFrame {
            /// Frame.
            frame: ReferenceFrame,
        } = cmd::SET_REFERENCE_FRAME, reply ReplyKind::Ack,
        data 1 => |f| Self::SetReferenceFrame { frame: f.enum_byte(ReferenceFrame::from_u8)? },
        emit |w| { w.u8(*frame as u8); };
        /// 0x86 get reference frame.
        GetReferenceFrame = cmd::GET_REFERENCE_FRAME, reply ReplyKind::Byte;
        /// 0x87 set movement type.
        SetMovementType {
            /// Type.
            mode: MoveMode,
        } = cmd::SET_MOVEMENT_TYPE, reply ReplyKind::Ack,
        data 1 => |f| Self::SetMovementType { mode: f.enum_byte(MoveMode::from_u8)? },
        emit |w| { w.u8(*mode as u8); };
        /// 0x88 get movement type.
        GetMovementType = cmd::GET_MOVEMENT_TYPE, reply ReplyKind::Byte;
        /// 0x89 set end type.
        SetEndType {
            /// End.
            end: EndType,
        } = cmd::SET_END_TYPE, reply ReplyKind::Ack,
        data 1 => |f| Self::SetEndType { end: f.enum_byte(EndType::from_u8)? },
        emit |w| { w.u8(*end as u8); };
        /// 0x8A get end type.
        GetEndType = cmd::GET_END_TYPE, reply ReplyKind::Byte;

        // --- answered by the Basic ---

        /// 0xA0 set a Basic output.
        SetBasicOutput {
            /// Pin.
            pin: BasicOutputPin,
            /// High.
            high: bool,
        } = cmd::SET_BASIC_OUTPUT, reply ReplyKind::Ack,
        data 2 => |f| Self::SetBasicOutput { pin: f.basic_output_pin()?, high: f.flag()? },
        emit |w| { w.u8(pin.gpio()).u8(u8::from(*high)); };
        /// 0xA1 get a Basic input.
        GetBasicInput {
            /// Pin.
            pin: BasicInputPin,
        } = cmd::GET_BASIC_INPUT, reply ReplyKind::PinLevel,
        data 1 => |f| Self::GetBasicInput { pin: f.basic_input_pin()? },
        emit |w| { w.u8(pin.gpio()); };
        /// 0xB0 set Wi-Fi SSID and password. pymycobot sends it empty (an announcing frame) and
        /// the credentials 20 ms later as bare text `'ssid'(password)`, outside any frame; a
        /// client may also frame that text here (`firmware_basic::wifi::config`).
        SetSsidPwd {
            /// Payload.
            payload: Vec<u8, MAX_DATA>,
        } = cmd::SET_SSID_PWD, reply ReplyKind::Ack,
        data _ => |f| Self::SetSsidPwd { payload: f.payload()? },
        emit |w| { w.bytes(payload); };
        /// 0xB1 get Wi-Fi SSID and password.
        GetSsidPwd = cmd::GET_SSID_PWD, reply ReplyKind::Raw;
        /// 0xB2 set server port.
        SetServerPort {
            /// TCP port.
            port: u16,
        } = cmd::SET_SERVER_PORT, reply ReplyKind::Ack,
        data 2 => |f| Self::SetServerPort { port: f.i16()? as u16 },
        emit |w| { w.bytes(&port.to_be_bytes()); };
        /// 0xC0 get ToF distance.
        GetTofDistance = cmd::GET_TOF_DISTANCE, reply ReplyKind::Int16;
        /// 0xC1 get Basic version.
        GetBasicVersion = cmd::GET_BASIC_VERSION, reply ReplyKind::Byte;
        /// 0xC2 set transponder mode.
        SetTransponderMode {
            /// Mode.
            mode: TransponderMode,
        } = cmd::SET_TRANSPONDER_MODE, reply ReplyKind::Ack,
        data 1 => |f| Self::SetTransponderMode { mode: f.enum_byte(TransponderMode::from_u8)? },
        emit |w| { w.u8(*mode as u8); };
        /// 0xC3 get transponder mode.
        GetTransponderMode = cmd::GET_TRANSPONDER_MODE, reply ReplyKind::Byte;
        /// 0xC5 the protocol dialect: LEN 2 asks, LEN 3 sets. Answered in both dialects with
        /// the dialect in force.
        Dialect {
            /// The dialect to switch to; `None` asks.
            set: Option<Dialect>,
        } = cmd::DIALECT, reply ReplyKind::Byte,
        data 0 | 1 => |f| Self::Dialect {
            set: f.optional(|f| f.enum_byte(Dialect::from_u8))?,
        },
        emit |w| {
            if let Some(d) = set {
                w.u8(*d as u8);
            }
        };

        // --- drag teaching ---

        /// 0xF1 start recording.
        DragStartRecord = cmd::DRAG_START_RECORD, reply ReplyKind::Int16;
        /// 0xF2 end recording.
        DragEndRecord = cmd::DRAG_END_RECORD, reply ReplyKind::Int16;
        /// 0xF3 get recorded data.
        DragGetRecordData = cmd::DRAG_GET_RECORD_DATA, reply ReplyKind::DragPoint;
        /// 0xF4 get record length.
        DragGetRecordLen = cmd::DRAG_GET_RECORD_LEN, reply ReplyKind::Int16;
        /// 0xF5 clear recorded data.
        DragClearRecordData = cmd::DRAG_CLEAR_RECORD_DATA, reply ReplyKind::Int16;
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
        let bad_len = if cmd::is_known(code) {
            CommandError::BadLength {
                cmd: code,
                // data.len() <= MAX_DATA = 62, so the cast is exact.
                data_len: data.len() as u8,
            }
        } else {
            CommandError::UnknownCommand { cmd: code }
        };
        Self::parse_data(code, &mut Fields::new(data, bad_len))
    }

    /// The command code (CMD byte) of this request.
    pub fn cmd(&self) -> u8 {
        self.kind().cmd()
    }

    /// The frame a client sends for this request. `Request::parse(&r.to_frame()) == Ok(r)`
    /// for every valid request.
    pub fn to_frame(&self) -> Frame {
        let mut w = Writer::default();
        self.emit(&mut w);
        w.frame(self.cmd())
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
    fn the_table_gives_every_known_code_a_command_and_no_other() {
        let codes: std::collections::BTreeSet<u8> =
            RequestKind::ALL.iter().map(|k| k.cmd()).collect();
        let known: std::collections::BTreeSet<u8> = cmd::ALL.into_iter().collect();
        assert_eq!(codes, known, "cmd::ALL and the table of requests disagree");
        let kinds: std::collections::BTreeSet<String> =
            RequestKind::ALL.iter().map(|k| format!("{k:?}")).collect();
        assert_eq!(kinds.len(), RequestKind::ALL.len(), "a kind listed twice");
    }

    #[test]
    fn kind_and_cmd_come_from_the_entry_of_the_variant() {
        assert_eq!(Request::GetAngles.kind(), RequestKind::GetAngles);
        let to_coords = Request::AnglesToCoords {
            angles: [Centideg(0); 6],
        };
        assert_eq!(to_coords.kind(), RequestKind::AnglesToCoords);
        // Two layouts of one code: two kinds, one CMD byte.
        assert_eq!(to_coords.cmd(), cmd::GET_COORDS);
        assert_eq!(Request::GetCoords.cmd(), cmd::GET_COORDS);
        assert_eq!(
            RequestKind::JogStop.cmd(),
            RequestKind::JogIncrementCoord.cmd()
        );
    }

    #[test]
    fn a_command_without_fields_is_its_bare_frame() {
        for r in [Request::GetAngles, Request::Stop, Request::DragEndRecord] {
            let frame = r.to_frame();
            assert_eq!((frame.cmd(), frame.data()), (r.cmd(), &[][..]));
            assert_eq!(Request::parse(&frame), Ok(r.clone()));
            assert!(matches!(
                parse(r.cmd(), &[0]),
                Err(CommandError::BadLength { data_len: 1, .. })
            ));
        }
    }

    #[test]
    fn reply_kind_may_depend_on_the_fields() {
        let read = |width| Request::GetServoData {
            servo: ServoId::new(1).unwrap(),
            address: 56,
            width,
        };
        assert_eq!(read(None).reply_kind(), ReplyKind::Byte);
        assert_eq!(read(Some(DataWidth::Byte)).reply_kind(), ReplyKind::Byte);
        assert_eq!(read(Some(DataWidth::Word)).reply_kind(), ReplyKind::Int16);
    }

    #[test]
    fn collision_settings_have_the_layouts_of_pymycobots_closed_loop_arms() {
        let on = Request::SetCollisionMode { on: true }.to_frame();
        assert_eq!(
            on.to_bytes().as_slice(),
            &[0xFE, 0xFE, 0x03, 0x74, 0x01, 0xFA]
        );
        let mode = Request::GetCollisionMode.to_frame();
        assert_eq!(mode.to_bytes().as_slice(), &[0xFE, 0xFE, 0x02, 0xFD, 0xFA]);
        let threshold = Request::SetCollisionThreshold {
            joint: JointId::new(3).unwrap(),
            threshold: CollisionThreshold::new(250).unwrap(),
        };
        let wire = [0xFE, 0xFE, 0x04, 0x75, 0x03, 0xFA, 0xFA];
        assert_eq!(threshold.to_frame().to_bytes().as_slice(), &wire);
        assert_eq!(
            Request::GetCollisionThresholds.reply_kind(),
            ReplyKind::Bytes6
        );
        assert_eq!(Request::GetCollisionMode.reply_kind(), ReplyKind::Byte);
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
            (cmd::SET_COLLISION_MODE, &[2], E::BadFlag(2)),
            (cmd::SET_COLLISION_THRESHOLD, &[0, 100], E::BadJoint(0)),
            (cmd::SET_COLLISION_THRESHOLD, &[7, 100], E::BadJoint(7)),
            (cmd::SET_COLLISION_THRESHOLD, &[1, 49], E::BadThreshold(49)),
            (
                cmd::SET_COLLISION_THRESHOLD,
                &[1, 251],
                E::BadThreshold(251),
            ),
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
