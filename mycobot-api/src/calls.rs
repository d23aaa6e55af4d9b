//! The manual's section-2 API (MyCobotBasic's functions) as methods of [`MyCobot`], one
//! request each. Every doc names the manual's function and section, and the command it sends
//! (`docs/protocol.md` section 5 has the layouts).

use protocol_core::command::{
    AtomPin, AxisValue, DataWidth, Direction, EndType, GripperModel, GripperSpeed, GripperState,
    GripperValue, JointId, MoveMode, PinMode, Pose, PositionTarget, ReferenceFrame, Reply, Request,
    Rgb, ServoId, ServoValue,
};
use protocol_core::command::{Axis, ErrorCode};
use protocol_core::port::BytePort;
use protocol_core::units::{Centideg, Decideg, SpeedPercent, Steps};

use crate::error::Error;
use crate::robot::{Clock, MyCobot};

/// The six joint angles, joints 1..6.
pub type Angles = [Centideg; 6];

impl<P: BytePort, C: Clock> MyCobot<P, C> {
    /// A command without a value.
    fn set(&mut self, request: Request) -> Result<(), Error> {
        self.request(&request).map(|_| ())
    }

    /// A command with a value, taken out of its reply by `value` (`None`: malformed).
    fn get<T>(
        &mut self,
        request: Request,
        value: impl FnOnce(Reply) -> Option<T>,
    ) -> Result<T, Error> {
        let cmd = request.cmd();
        self.request(&request)?
            .and_then(value)
            .ok_or(Error::BadReply { cmd })
    }

    // --- 2.2 overall status ---

    /// powerOn (manual 2.2): power on, every servo's torque on (0x10).
    pub fn power_on(&mut self) -> Result<(), Error> {
        self.set(Request::PowerOn)
    }

    /// powerOff (manual 2.2): power off, every servo's torque off (0x11).
    pub fn power_off(&mut self) -> Result<(), Error> {
        self.set(Request::PowerOff)
    }

    /// isPoweredOn (manual 2.2): true while powered on (0x12).
    pub fn is_powered_on(&mut self) -> Result<bool, Error> {
        self.get(Request::IsPowerOn, flag)
    }

    /// setFreeMove (manual 2.2): every servo's torque off, so the arm can be moved by hand
    /// (release all servos, 0x13).
    pub fn set_free_move(&mut self) -> Result<(), Error> {
        self.set(Request::ReleaseAllServos { undamped: None })
    }

    // --- 2.3 MDI mode and robot control ---

    /// getAngles (manual 2.3): the six joint angles (0x20).
    pub fn get_angles(&mut self) -> Result<Angles, Error> {
        self.get(Request::GetAngles, |r| match r {
            Reply::Angles(angles) => Some(angles),
            _ => None,
        })
    }

    /// writeAngle (manual 2.3): one joint to `angle` at `speed` (0x21; the seed dialect
    /// numbers the joint from 0 on the wire).
    ///
    /// ```no_run
    /// # fn demo(arm: &mut mycobot_api::MyCobot<protocol_core::NullPort, fn() -> u64>)
    /// # -> Result<(), mycobot_api::Error> {
    /// use mycobot_api::convert::deg;
    /// use protocol_core::command::JointId;
    /// use protocol_core::units::SpeedPercent;
    ///
    /// if let (Some(joint), Some(speed)) = (JointId::new(2), SpeedPercent::new(50)) {
    ///     arm.write_angle(joint, deg(-30.5), speed)?;
    /// }
    /// # Ok(()) }
    /// ```
    pub fn write_angle(
        &mut self,
        joint: JointId,
        angle: Centideg,
        speed: SpeedPercent,
    ) -> Result<(), Error> {
        self.set(Request::SendAngle {
            joint,
            angle,
            speed,
        })
    }

    /// writeAngles (manual 2.3): all six joints to `angles` at `speed`, together (0x22).
    ///
    /// ```no_run
    /// # fn demo(arm: &mut mycobot_api::MyCobot<protocol_core::NullPort, fn() -> u64>)
    /// # -> Result<(), mycobot_api::Error> {
    /// use mycobot_api::convert::angles;
    /// use protocol_core::units::SpeedPercent;
    ///
    /// arm.write_angles(angles([10.0, 20.0, -30.0, 15.0, -25.0, 40.0]), SpeedPercent::MAX)?;
    /// # Ok(()) }
    /// ```
    pub fn write_angles(&mut self, angles: Angles, speed: SpeedPercent) -> Result<(), Error> {
        self.set(Request::SendAngles { angles, speed })
    }

    /// getCoords (manual 2.3): the end's pose, in the end type and reference frame selected
    /// (0x23).
    pub fn get_coords(&mut self) -> Result<Pose, Error> {
        self.get(Request::GetCoords, pose)
    }

    /// isInPosition (manual 2.3): true once the arm is at rest at `target` (0x2A). The manual
    /// compares a pose; [`PositionTarget::Angles`] is pymycobot's, and has no frame in the
    /// seed dialect ([`Error::NotInDialect`]).
    pub fn is_in_position(&mut self, target: PositionTarget) -> Result<bool, Error> {
        self.get(Request::IsInPosition { target }, flag)
    }

    /// writeCoord (manual 2.3): one coordinate of the pose the arm is going to, changed to
    /// `target`, at `speed` (0x24; the seed dialect numbers the axis from 0 on the wire).
    ///
    /// ```no_run
    /// # fn demo(arm: &mut mycobot_api::MyCobot<protocol_core::NullPort, fn() -> u64>)
    /// # -> Result<(), mycobot_api::Error> {
    /// use mycobot_api::convert::mm;
    /// use protocol_core::command::AxisValue;
    /// use protocol_core::units::SpeedPercent;
    ///
    /// arm.write_coord(AxisValue::Z(mm(180.0)), SpeedPercent::MAX)?;
    /// # Ok(()) }
    /// ```
    pub fn write_coord(&mut self, target: AxisValue, speed: SpeedPercent) -> Result<(), Error> {
        self.set(Request::SendCoord { target, speed })
    }

    /// writeCoords (manual 2.3): the end to `pose` at `speed`, joint-interpolated or in a
    /// straight line (0x25 with its mode byte, as the manual sends it).
    pub fn write_coords(
        &mut self,
        pose: Pose,
        speed: SpeedPercent,
        mode: MoveMode,
    ) -> Result<(), Error> {
        self.set(Request::SendCoords {
            pose,
            speed,
            mode: Some(mode),
        })
    }

    /// checkRunning (manual 2.3): true while the arm moves (is moving, 0x2B).
    pub fn check_running(&mut self) -> Result<bool, Error> {
        self.get(Request::IsMoving, flag)
    }

    /// setEncoder (manual 2.3): one servo (7: the gripper) to `encoder` at the default speed
    /// (0x3A without a speed, as the manual sends it; the seed dialect numbers the servo from
    /// 0 on the wire).
    pub fn set_encoder(&mut self, servo: ServoId, encoder: Steps) -> Result<(), Error> {
        self.set(Request::SetEncoder {
            servo,
            encoder,
            speed: None,
        })
    }

    /// getEncoder (manual 2.3): one servo's position in steps, 2048 = 0 deg (0x3B).
    pub fn get_encoder(&mut self, servo: ServoId) -> Result<Steps, Error> {
        self.get(Request::GetEncoder { servo }, |r| int16(r).map(Steps))
    }

    /// setEncoders (manual 2.3): the six joint servos to `encoders` at `speed`, together
    /// (0x3C).
    pub fn set_encoders(&mut self, encoders: [Steps; 6], speed: SpeedPercent) -> Result<(), Error> {
        self.set(Request::SetEncoders { encoders, speed })
    }

    // --- 2.4 jog mode ---

    /// jogAngle (manual 2.4): one joint turning in `direction` until
    /// [`jog_stop`](Self::jog_stop), [`stop`](Self::stop) or its limit (0x30).
    pub fn jog_angle(
        &mut self,
        joint: JointId,
        direction: Direction,
        speed: SpeedPercent,
    ) -> Result<(), Error> {
        self.set(Request::JogAngle {
            joint,
            direction,
            speed,
        })
    }

    /// jogCoord (manual 2.4): the end moving along or about a base axis in `direction` until
    /// [`jog_stop`](Self::jog_stop) (0x32).
    pub fn jog_coord(
        &mut self,
        axis: Axis,
        direction: Direction,
        speed: SpeedPercent,
    ) -> Result<(), Error> {
        self.set(Request::JogCoord {
            axis,
            direction,
            speed,
        })
    }

    /// jogStop (manual 2.4): ends a jog (0x34).
    pub fn jog_stop(&mut self) -> Result<(), Error> {
        self.set(Request::JogStop)
    }

    /// pause (manual 2.4): brakes, keeping the motion for [`resume`](Self::resume) (0x26).
    pub fn pause(&mut self) -> Result<(), Error> {
        self.set(Request::Pause)
    }

    /// resume (manual 2.4): the paused motion goes on (pymycobot 0x28, the seed dialect's
    /// 0x27 "continue").
    pub fn resume(&mut self) -> Result<(), Error> {
        self.set(Request::Resume)
    }

    /// stop (manual 2.4): brakes every joint and forgets the motions queued and paused
    /// (pymycobot 0x29, the seed dialect's 0x28).
    pub fn stop(&mut self) -> Result<(), Error> {
        self.set(Request::Stop)
    }

    // --- 2.5 running status and settings ---

    /// getSpeed (manual 2.5): the default speed, for commands that carry none (0x40).
    pub fn get_speed(&mut self) -> Result<SpeedPercent, Error> {
        self.get(Request::GetSpeed, |r| byte(r).and_then(SpeedPercent::new))
    }

    /// setSpeed (manual 2.5): sets the default speed (0x41).
    pub fn set_speed(&mut self, speed: SpeedPercent) -> Result<(), Error> {
        self.set(Request::SetSpeed { speed })
    }

    /// getJointMin (manual 2.5): one joint's lower limit (0x4A; the seed dialect numbers the
    /// joint from 0 and answers the limit alone).
    pub fn get_joint_min(&mut self, joint: JointId) -> Result<Decideg, Error> {
        self.get(Request::GetJointMin { joint }, limit)
    }

    /// getJointMax (manual 2.5): one joint's upper limit (0x4B).
    pub fn get_joint_max(&mut self, joint: JointId) -> Result<Decideg, Error> {
        self.get(Request::GetJointMax { joint }, limit)
    }

    /// setJointMin (manual 2.5): narrows one joint's lower limit (0x4C; refused beyond the
    /// factory range).
    ///
    /// ```no_run
    /// # fn demo(arm: &mut mycobot_api::MyCobot<protocol_core::NullPort, fn() -> u64>)
    /// # -> Result<(), mycobot_api::Error> {
    /// use mycobot_api::convert::limit_deg;
    /// use protocol_core::command::JointId;
    ///
    /// if let Some(j1) = JointId::new(1) {
    ///     arm.set_joint_min(j1, limit_deg(-90.0))?;
    /// }
    /// # Ok(()) }
    /// ```
    pub fn set_joint_min(&mut self, joint: JointId, limit: Decideg) -> Result<(), Error> {
        self.set(Request::SetJointMin { joint, limit })
    }

    /// setJointMax (manual 2.5): narrows one joint's upper limit (0x4D).
    pub fn set_joint_max(&mut self, joint: JointId, limit: Decideg) -> Result<(), Error> {
        self.set(Request::SetJointMax { joint, limit })
    }

    // --- 2.6 joint servo control ---

    /// isServoEnabled (manual 2.6): true while one servo's torque is on (0x50 with a servo,
    /// numbered from 1 in both dialects).
    pub fn is_servo_enabled(&mut self, servo: ServoId) -> Result<bool, Error> {
        self.get(Request::IsServoEnabled { servo }, |r| match r {
            Reply::ServoEnabled { servo: s, enabled } if s == servo => Some(enabled),
            _ => None,
        })
    }

    /// isAllServoEnabled (manual 2.6): true while every joint servo's torque is on (0x51).
    pub fn is_all_servo_enabled(&mut self) -> Result<bool, Error> {
        self.get(Request::AreAllServosEnabled, flag)
    }

    /// getServoData (manual 2.6): one byte of a servo's register `address` (0x53; the seed
    /// dialect numbers the servo from 0). `FF` if the servo does not answer.
    pub fn get_servo_data(&mut self, servo: ServoId, address: u8) -> Result<u8, Error> {
        let request = Request::GetServoData {
            servo,
            address,
            width: None,
        };
        self.get(request, byte)
    }

    /// getServoData for a two-byte register (MyCobotBasic; 0x53 with width `01`): its value,
    /// 0xFFFF if the servo does not answer.
    pub fn get_servo_data_word(&mut self, servo: ServoId, address: u8) -> Result<u16, Error> {
        let request = Request::GetServoData {
            servo,
            address,
            width: Some(DataWidth::Word),
        };
        // The register's bits: -1 is 0xFFFF.
        self.get(request, |r| int16(r).map(|v| v as u16))
    }

    /// setServoData (manual 2.6): writes a servo's register `address` (0x52; the registers the
    /// firmware protects are refused: `docs/protocol.md` section 10).
    pub fn set_servo_data(
        &mut self,
        servo: ServoId,
        address: u8,
        value: ServoValue,
    ) -> Result<(), Error> {
        self.set(Request::SetServoData {
            servo,
            address,
            value,
        })
    }

    /// setServoCalibration (manual 2.6): a servo's present position becomes its zero, 2048
    /// (pymycobot 0x54, the seed dialect's 0x55 numbered from 0).
    pub fn set_servo_calibration(&mut self, servo: ServoId) -> Result<(), Error> {
        self.set(Request::SetServoCalibration { servo })
    }

    /// jointBrake (manual 2.6): one servo holds where it is (pymycobot 0x55, the seed
    /// dialect's 0x56 numbered from 0).
    pub fn joint_brake(&mut self, servo: ServoId) -> Result<(), Error> {
        self.set(Request::JointBrake { servo })
    }

    /// setPinMode (manual 2.6): an Atom pin's mode (0x60).
    pub fn set_pin_mode(&mut self, pin: AtomPin, mode: PinMode) -> Result<(), Error> {
        self.set(Request::SetPinMode { pin, mode })
    }

    // --- 2.7 Atom IO ---

    /// setLEDRGB (manual 2.7): the Atom's LED colour (0x6A).
    pub fn set_led_rgb(&mut self, rgb: Rgb) -> Result<(), Error> {
        self.set(Request::SetColor { rgb })
    }

    /// setGripper (manual 2.7): opens or closes the gripper (0x66 with the state alone, as
    /// the manual sends it: speed 50).
    pub fn set_gripper(&mut self, state: GripperState) -> Result<(), Error> {
        self.set(Request::SetGripperStateNoSpeed { state })
    }

    /// setGripperState (MyCobotBasic): opens, closes or releases the gripper at `speed`
    /// (0x66).
    pub fn set_gripper_state(
        &mut self,
        state: GripperState,
        speed: GripperSpeed,
    ) -> Result<(), Error> {
        self.set(Request::SetGripperState {
            state,
            speed,
            model: GripperModel::Default,
        })
    }

    /// setGripperValue (MyCobotBasic): the gripper to `value` (0 closed .. 100 open) at
    /// `speed`; speed 0 stops it where it is (0x67).
    pub fn set_gripper_value(
        &mut self,
        value: GripperValue,
        speed: GripperSpeed,
    ) -> Result<(), Error> {
        self.set(Request::SetGripperValue {
            value,
            speed,
            model: GripperModel::Default,
        })
    }

    /// getGripperValue (MyCobotBasic): how far the gripper is open, 0..=100 (0x65).
    pub fn get_gripper_value(&mut self) -> Result<GripperValue, Error> {
        let request = Request::GetGripperValue { gripper: None };
        self.get(request, |r| byte(r).and_then(GripperValue::new))
    }

    /// setGripperIni (MyCobotBasic): the gripper's present position becomes closed (0x68).
    pub fn set_gripper_ini(&mut self) -> Result<(), Error> {
        self.set(Request::SetGripperCalibration)
    }

    /// isGripperMoving (MyCobotBasic): true while the gripper moves (0x69).
    pub fn is_gripper_moving(&mut self) -> Result<bool, Error> {
        self.get(Request::IsGripperMoving, flag)
    }

    // --- 2.8 coordinate frames ---

    /// setToolReference (manual 2.8): the tool tip's pose in the flange frame (0x81).
    pub fn set_tool_reference(&mut self, pose: Pose) -> Result<(), Error> {
        self.set(Request::SetToolReference { pose })
    }

    /// getToolReference (manual 2.8): the tool tip's pose in the flange frame (0x82).
    pub fn get_tool_reference(&mut self) -> Result<Pose, Error> {
        self.get(Request::GetToolReference, pose)
    }

    /// setWorldReference (manual 2.8): the base's pose in the world frame (0x83).
    pub fn set_world_reference(&mut self, pose: Pose) -> Result<(), Error> {
        self.set(Request::SetWorldReference { pose })
    }

    /// getWorldReference (manual 2.8): the base's pose in the world frame (0x84).
    pub fn get_world_reference(&mut self) -> Result<Pose, Error> {
        self.get(Request::GetWorldReference, pose)
    }

    /// setReferenceFrame (manual 2.8): whether coordinates are in the base or the world frame
    /// (0x85).
    pub fn set_reference_frame(&mut self, frame: ReferenceFrame) -> Result<(), Error> {
        self.set(Request::SetReferenceFrame { frame })
    }

    /// getReferenceFrame (manual 2.8): the frame coordinates are in (0x86).
    pub fn get_reference_frame(&mut self) -> Result<ReferenceFrame, Error> {
        self.get(Request::GetReferenceFrame, |r| {
            byte(r).and_then(ReferenceFrame::from_u8)
        })
    }

    /// setEndType (manual 2.8): whether coordinates are the flange's or the tool tip's (0x89).
    pub fn set_end_type(&mut self, end: EndType) -> Result<(), Error> {
        self.set(Request::SetEndType { end })
    }

    /// getEndType (manual 2.8): the end coordinates are of (0x8A).
    pub fn get_end_type(&mut self) -> Result<EndType, Error> {
        self.get(Request::GetEndType, |r| byte(r).and_then(EndType::from_u8))
    }

    // --- beyond the manual's list ---

    /// getErrorInformation (pymycobot `get_error_information`, 0x07): the last error the
    /// robot recorded, `None` for none. A refusal asks it by itself ([`Error::Refused`]).
    pub fn get_error_information(&mut self) -> Result<Option<ErrorCode>, Error> {
        self.get(Request::GetErrorInfo, |r| {
            match ErrorCode::from_code(byte(r)?)? {
                ErrorCode::None => Some(None),
                code => Some(Some(code)),
            }
        })
    }
}

/// A one-byte reply's byte.
fn byte(reply: Reply) -> Option<u8> {
    match reply {
        Reply::Byte(b) => Some(b),
        _ => None,
    }
}

/// A one-byte reply as a flag: 0 or 1.
fn flag(reply: Reply) -> Option<bool> {
    match byte(reply)? {
        0 => Some(false),
        1 => Some(true),
        _ => None,
    }
}

/// A pose reply's pose.
fn pose(reply: Reply) -> Option<Pose> {
    match reply {
        Reply::Coords(pose) => Some(pose),
        _ => None,
    }
}

/// A joint limit reply's limit.
fn limit(reply: Reply) -> Option<Decideg> {
    match reply {
        Reply::JointLimit { limit, .. } => Some(limit),
        _ => None,
    }
}

/// An int16 reply's value.
fn int16(reply: Reply) -> Option<i16> {
    match reply {
        Reply::Int16(v) => Some(v),
        _ => None,
    }
}
