//! Host commands: every request gets exactly one reply carrying its CMD byte.
//!
//! Replies come from cached state (present positions refreshed from the servos), so they leave
//! at once; the reply to a motion command means "accepted", not "arrived". A set command
//! answers `01` when accepted and `00` when refused (out-of-limit joint, unreachable pose,
//! powered off, queue full); a refusal changes nothing and records its error code for 0x07.
//! A frame that is not a valid command (unknown code, wrong length, field out of range)
//! answers `00` too, so the client never waits for a reply that will not come.

use protocol_core::Frame;
use protocol_core::command::{
    CommandError, DataWidth, Direction, EndType, GripperState, MoveMode, Pose, Reply, Request,
    ServoErrorCode, ServoSelect, ServoValue, cmd,
};
use protocol_core::servo::reg;
use protocol_core::units::{Centideg, Decideg, Steps};

use crate::atom::{ActionError, Atom, Link, Target, Then};
use crate::cartesian::for_client;
use crate::config::{GRIPPER, JOINTS, SERVOS};
use crate::driver::Op;
use crate::io::{AtomIo, PinMode};
use crate::motion::{self, JogDirection};
use crate::safety::{Goal, GoalSet};

/// Command code of get servo data (its reply waits for a servo read).
pub(crate) const GET_SERVO_DATA: u8 = cmd::GET_SERVO_DATA;

/// Reported by get system version (0x02): 7.0, the vendor's 280 M5 generation.
const SYSTEM_VERSION_X10: u8 = 70;
/// Reported by get modify version (0x01).
const MODIFY_VERSION: u8 = 0;

/// What get servo status (0xE4) reports for a servo that does not answer: every bit set, a
/// value no answering servo reports (its status register has six fault bits).
const NO_ANSWER_STATUS: u8 = 0xFF;

/// Servo registers below this address are EEPROM: writes need the lock (55) opened first.
const FIRST_RAM_REGISTER: u8 = reg::TORQUE_ENABLE;

/// Handles one request; returns the reply (none only when the reply waits for the bus).
pub(crate) fn handle<I: AtomIo>(
    atom: &mut Atom,
    now_us: u64,
    frame: &Frame,
    link: Link,
    io: &mut I,
) -> Option<Frame> {
    let code = frame.cmd();
    let request = match Request::parse(frame) {
        Ok(r) => r,
        Err(CommandError::UnknownCommand { .. }) | Err(_) => {
            return Some(Reply::Byte(0).to_frame(code));
        }
    };
    let reply = match execute(atom, now_us, request, link, io) {
        Answer::Now(reply) => reply,
        Answer::Later => return None,
        Answer::Done(Ok(())) => Reply::Ack,
        Answer::Done(Err(e)) => {
            atom.record(e);
            Reply::Byte(0)
        }
    };
    Some(reply.to_frame(code))
}

/// What a request produced.
enum Answer {
    /// This reply.
    Now(Reply),
    /// The reply follows when a servo transaction finishes.
    Later,
    /// A set command: ack or refusal.
    Done(Result<(), ActionError>),
}

fn byte(v: bool) -> Answer {
    Answer::Now(Reply::Byte(u8::from(v)))
}

fn done_if(ok: bool) -> Answer {
    Answer::Done(if ok {
        Ok(())
    } else {
        Err(ActionError::Invalid)
    })
}

fn execute<I: AtomIo>(
    atom: &mut Atom,
    now_us: u64,
    request: Request,
    link: Link,
    io: &mut I,
) -> Answer {
    use Request as R;
    match request {
        // --- status and system ---
        R::GetModifyVersion => Answer::Now(Reply::Byte(MODIFY_VERSION)),
        R::GetSystemVersion => Answer::Now(Reply::Byte(SYSTEM_VERSION_X10)),
        R::ClearQueue => {
            atom.clear_queue();
            Answer::Done(Ok(()))
        }
        // 1: commands are acknowledged at once and run asynchronously.
        R::CheckAsyncOrSync => byte(true),
        R::GetErrorInfo => Answer::Now(Reply::Byte(atom.error_code)),
        R::ClearErrorInfo => {
            atom.error_code = 0;
            Answer::Done(Ok(()))
        }
        R::PowerOn => done_if(atom.power_on()),
        R::PowerOff => done_if(atom.power_off()),
        R::IsPowerOn => byte(atom.powered),
        R::ReleaseAllServos { .. } => {
            atom.halt(true);
            done_if((0..SERVOS).all(|i| atom.set_torque(i, false)))
        }
        R::IsControllerConnected => byte(true),
        R::ReadNextError => Answer::Now(Reply::ServoErrors(servo_errors(atom))),
        R::SetFreshMode { fresh } => {
            atom.fresh_mode = fresh;
            Answer::Done(Ok(()))
        }
        R::GetFreshMode => byte(atom.fresh_mode),
        R::SetFreeMode { on } => {
            atom.free_mode = on;
            Answer::Done(Ok(()))
        }
        R::IsFreeMode => byte(atom.free_mode),
        R::SetVisionMode { .. } => Answer::Done(Ok(())),
        R::GetRebootCount => Answer::Now(Reply::Int16(0)),

        // --- motion ---
        R::GetAngles => Answer::Now(Reply::Angles(atom.present_angles())),
        R::SendAngle {
            joint,
            angle,
            speed,
        } => {
            let mut angles = [None; JOINTS];
            if let Some(slot) = angles.get_mut(joint.index()) {
                *slot = Some(angle);
            }
            let target = Target {
                angles,
                speed_percent: speed.get(),
                linear: None,
            };
            Answer::Done(atom.submit_motion(now_us, target))
        }
        R::SendAngles { angles, speed } => Answer::Done(atom.submit_motion(
            now_us,
            Target {
                angles: angles.map(Some),
                speed_percent: speed.get(),
                linear: None,
            },
        )),
        R::GetCoords => Answer::Now(Reply::Coords(for_client(atom.present_coords()))),
        R::AnglesToCoords { angles } => {
            Answer::Now(Reply::Coords(for_client(atom.cart.forward(&angles))))
        }
        R::SendCoord { target, speed } => {
            let base = atom.planned_coords();
            let pose = base.with(target);
            let mode = atom.cart.movement;
            Answer::Done(atom.move_to_pose(now_us, pose, speed.get(), mode))
        }
        R::SendCoords { pose, speed, mode } => {
            let mode = mode.unwrap_or(atom.cart.movement);
            Answer::Done(atom.move_to_pose(now_us, pose, speed.get(), mode))
        }
        R::Pause => {
            atom.pause();
            Answer::Done(Ok(()))
        }
        R::IsPaused => byte(atom.paused.is_some()),
        R::Resume => Answer::Done(atom.resume(now_us)),
        R::Stop => {
            atom.halt(true);
            Answer::Done(Ok(()))
        }
        R::IsInPosition { target } => {
            // Near the target and at rest: pymycobot's sync_send_angles returns as soon as this
            // says 1, so a pose passed through on the way does not count.
            let present = atom.present_angles();
            let near = match target {
                protocol_core::command::PositionTarget::Angles(a) => {
                    motion::angles_match(&present, &a)
                }
                protocol_core::command::PositionTarget::Coords(p) => {
                    let now = atom.cart.forward(&present);
                    coords_match(&now, &p)
                }
            };
            byte(near && !atom.is_moving())
        }
        R::IsMoving => byte(atom.is_moving()),
        R::SolveIk { target, current } => match atom.cart.inverse(&target, &current) {
            Ok(q) => Answer::Now(Reply::Angles(q)),
            Err(_) => {
                atom.record(ActionError::Unreachable);
                Answer::Now(Reply::Angles(current))
            }
        },
        R::GetAnglesCoords => {
            let angles = atom.present_angles();
            let coords = for_client(atom.cart.forward(&angles));
            Answer::Now(Reply::AnglesAndCoords { angles, coords })
        }
        R::GetPlannedAngles => Answer::Now(Reply::Angles(atom.planned_angles())),
        R::GetPlannedCoords => Answer::Now(Reply::Coords(for_client(atom.planned_coords()))),
        // Vendor demo routines: not supported, refused.
        R::MoveRound | R::SetFourPiecesZero => Answer::Now(Reply::Byte(0)),

        // --- jog ---
        R::JogAngle {
            joint,
            direction,
            speed,
        } => Answer::Done(atom.jog_joint(now_us, joint.index(), dir(direction), speed.get())),
        R::JogRpy {
            axis,
            direction,
            speed,
        } => {
            Answer::Done(atom.jog_pose(now_us, 3 + axis as usize - 1, dir(direction), speed.get()))
        }
        R::JogCoord {
            axis,
            direction,
            speed,
        } => Answer::Done(atom.jog_pose(now_us, axis.index(), dir(direction), speed.get())),
        R::JogIncrementAngle {
            joint,
            increment,
            speed,
        } => {
            let j = joint.index();
            let base = atom.planned_angles().get(j).copied().unwrap_or_default();
            let goal = i32::from(base.0) + i32::from(increment.0);
            let Ok(goal) = i16::try_from(goal) else {
                return Answer::Done(Err(ActionError::JointLimit(j)));
            };
            let mut angles = [None; JOINTS];
            if let Some(slot) = angles.get_mut(j) {
                *slot = Some(Centideg(goal));
            }
            Answer::Done(atom.submit_motion(
                now_us,
                Target {
                    angles,
                    speed_percent: speed.get(),
                    linear: None,
                },
            ))
        }
        R::JogStop => {
            atom.halt(true);
            Answer::Done(Ok(()))
        }
        R::JogIncrementCoord { increment, speed } => {
            let base = atom.planned_coords();
            let axis = increment.axis();
            let now = base.get(axis).raw();
            let goal = i32::from(now) + i32::from(increment.raw());
            let Ok(goal) = i16::try_from(goal) else {
                return Answer::Done(Err(ActionError::Unreachable));
            };
            let pose = base.with(protocol_core::command::AxisValue::new(axis, goal));
            Answer::Done(atom.move_to_pose(now_us, pose, speed.get(), MoveMode::Joint))
        }

        // --- encoders, speed, limits ---
        R::SetEncoder {
            servo,
            encoder,
            speed,
        } => {
            let speed = speed.map_or(atom.speed_percent, |s| s.get());
            let index = usize::from(servo.get()) - 1;
            if index == GRIPPER {
                return Answer::Done(atom.move_gripper_steps(encoder, speed));
            }
            let mut angles = [None; JOINTS];
            if let Some(slot) = angles.get_mut(index) {
                *slot = Some(atom.config.steps_to_angle(index, clamp_steps(encoder)));
            }
            if encoder != clamp_steps(encoder) {
                return Answer::Done(Err(ActionError::JointLimit(index)));
            }
            Answer::Done(atom.submit_motion(
                now_us,
                Target {
                    angles,
                    speed_percent: speed,
                    linear: None,
                },
            ))
        }
        R::GetEncoder { servo } => {
            let index = usize::from(servo.get()) - 1;
            let steps = atom.servo_health(index).map_or(0, |h| h.position.0);
            Answer::Now(Reply::Int16(steps))
        }
        R::SetEncoders { encoders, speed } => {
            if let Some(j) = encoders.iter().position(|&e| e != clamp_steps(e)) {
                return Answer::Done(Err(ActionError::JointLimit(j)));
            }
            let mut angles = [None; JOINTS];
            for (j, (slot, e)) in angles.iter_mut().zip(encoders).enumerate() {
                *slot = Some(atom.config.steps_to_angle(j, e));
            }
            Answer::Done(atom.submit_motion(
                now_us,
                Target {
                    angles,
                    speed_percent: speed.get(),
                    linear: None,
                },
            ))
        }
        R::GetEncoders => Answer::Now(Reply::Encoders(atom.present_steps())),
        R::SetEncodersDrag {
            encoders,
            speeds_steps_per_s,
        } => Answer::Done(atom.drag_to(encoders, speeds_steps_per_s)),
        R::GetSpeed => Answer::Now(Reply::Byte(atom.speed_percent)),
        R::SetSpeed { speed } => {
            atom.speed_percent = speed.get();
            Answer::Done(Ok(()))
        }
        R::GetJointMin { joint } => {
            let l = atom.limits.get(joint.index()).map_or(0, |l| l.min.0);
            Answer::Now(Reply::JointLimit {
                joint,
                limit: Decideg(l / 10),
            })
        }
        R::GetJointMax { joint } => {
            let l = atom.limits.get(joint.index()).map_or(0, |l| l.max.0);
            Answer::Now(Reply::JointLimit {
                joint,
                limit: Decideg(l / 10),
            })
        }
        R::SetJointMin { joint, limit } => {
            Answer::Done(atom.set_limit(joint.index(), Some(limit), None))
        }
        R::SetJointMax { joint, limit } => {
            Answer::Done(atom.set_limit(joint.index(), None, Some(limit)))
        }

        // --- servos ---
        R::IsServoEnabled { servo } => {
            let h = atom.servo_health(usize::from(servo.get()) - 1);
            Answer::Now(Reply::ServoEnabled {
                servo,
                enabled: h.is_some_and(|h| h.answering && h.torque_on),
            })
        }
        R::AreAllServosEnabled => byte(
            atom.health
                .iter()
                .take(JOINTS)
                .all(|h| h.answering && h.torque_on),
        ),
        R::SetServoData {
            servo,
            address,
            value,
        } => Answer::Done(atom.write_register(usize::from(servo.get()) - 1, address, value)),
        R::GetServoData {
            servo,
            address,
            width,
        } => {
            let two_bytes = width == Some(DataWidth::Word);
            let id = atom
                .config
                .servo_ids
                .get(usize::from(servo.get()) - 1)
                .copied();
            let op = id.map(|id| Op::Read {
                id,
                addr: address,
                count: if two_bytes { 2 } else { 1 },
            });
            let queued =
                op.is_some_and(|op| atom.queue_op(op, Then::ReplyServoData { link, two_bytes }));
            if queued {
                Answer::Later
            } else {
                Answer::Done(Err(ActionError::Busy))
            }
        }
        R::SetServoCalibration { servo } => {
            let index = usize::from(servo.get()) - 1;
            Answer::Done(atom.calibrate(index))
        }
        R::JointBrake { servo } => {
            let index = usize::from(servo.get()) - 1;
            Answer::Done(atom.brake(index))
        }
        R::ReleaseServo { servo, .. } => {
            let index = usize::from(servo.get()) - 1;
            if index < JOINTS {
                atom.halt(false);
            }
            done_if(atom.set_torque(index, false))
        }
        R::FocusServo { servo } => match servo {
            ServoSelect::All => done_if((0..SERVOS).all(|i| atom.set_torque(i, true))),
            ServoSelect::One(s) => done_if(atom.set_torque(usize::from(s.get()) - 1, true)),
        },
        R::GetServoSpeeds => Answer::Now(Reply::Int16x6(per_joint(atom, |h| h.speed_steps_per_s))),
        R::GetServoCurrents => Answer::Now(Reply::Int16x6(per_joint(atom, |h| {
            // The STS current register counts 6.5 mA units.
            (i32::from(h.current_raw) * 65 / 10).clamp(-32_768, 32_767) as i16
        }))),
        R::GetServoVoltages => Answer::Now(Reply::Bytes6(per_joint(atom, |h| h.voltage_decivolt))),
        R::GetServoStatus => Answer::Now(Reply::Bytes6(per_joint(atom, |h| {
            if h.answering {
                h.fault_bits
            } else {
                NO_ANSWER_STATUS
            }
        }))),
        R::GetServoTemps => Answer::Now(Reply::Bytes6(per_joint(atom, |h| h.temperature_c))),
        // Servo parameters live in the servos' own EEPROM; there is nothing to back up.
        R::BackupServoParams { .. } | R::RestoreServoParams { .. } => Answer::Done(Ok(())),

        // --- Atom IO, LED, gripper ---
        R::SetPinMode { pin, mode } => {
            let mode = match mode {
                protocol_core::command::PinMode::Input => PinMode::Input,
                protocol_core::command::PinMode::Output => PinMode::Output,
                protocol_core::command::PinMode::InputPullUp => PinMode::InputPullUp,
            };
            let allowed = mode != PinMode::Output || crate::io::is_output_pin(pin.gpio());
            done_if(allowed && io.set_pin_mode(pin.gpio(), mode))
        }
        R::SetDigitalOutput { pin, high } => {
            done_if(crate::io::is_output_pin(pin.gpio()) && io.write_pin(pin.gpio(), high))
        }
        R::GetDigitalInput { pin } => match io.read_pin(pin.gpio()) {
            Some(high) => Answer::Now(Reply::PinLevel {
                pin: pin.gpio(),
                high,
            }),
            None => Answer::Done(Err(ActionError::Invalid)),
        },
        R::SetPwmOutput {
            pin,
            frequency_hz,
            duty,
        } => done_if(
            crate::io::is_output_pin(pin.gpio()) && io.set_pwm(pin.gpio(), frequency_hz, duty),
        ),
        R::GetGripperValue { .. } => Answer::Now(Reply::Byte(atom.gripper_value())),
        R::SetGripperStateNoSpeed { state } => Answer::Done(atom.gripper_state(state, 50)),
        R::SetGripperState { state, speed, .. } => {
            Answer::Done(atom.gripper_state(state, speed.get()))
        }
        R::SetGripperValue { value, speed, .. } => {
            Answer::Done(atom.gripper_to(value.get(), speed.get()))
        }
        R::SetGripperCalibration => Answer::Done(atom.calibrate(GRIPPER)),
        R::IsGripperMoving => byte(atom.servo_moving(GRIPPER)),
        R::SetColor { rgb } => {
            io.set_rgb(rgb.r, rgb.g, rgb.b);
            Answer::Done(Ok(()))
        }
        R::SetHtsGripperTorque { torque } => {
            atom.gripper_torque = torque;
            Answer::Now(Reply::Byte(1))
        }
        R::GetHtsGripperTorque => Answer::Now(Reply::Int16(atom.gripper_torque)),
        R::GetGripperProtectCurrent => Answer::Now(Reply::Int16(atom.gripper_protect_current)),
        R::InitGripper => Answer::Now(Reply::Byte(u8::from(atom.calibrate(GRIPPER).is_ok()))),
        R::SetGripperProtectCurrent { current } => {
            atom.gripper_protect_current = current;
            Answer::Done(Ok(()))
        }

        // --- coordinate frames ---
        R::SetToolReference { pose } => {
            atom.cart.tool = pose;
            atom.cart.apply_frames();
            Answer::Done(Ok(()))
        }
        R::GetToolReference => Answer::Now(Reply::Coords(atom.cart.tool)),
        R::SetWorldReference { pose } => {
            atom.cart.world = pose;
            atom.cart.apply_frames();
            Answer::Done(Ok(()))
        }
        R::GetWorldReference => Answer::Now(Reply::Coords(atom.cart.world)),
        R::SetReferenceFrame { frame } => {
            atom.cart.reference = frame;
            atom.cart.apply_frames();
            Answer::Done(Ok(()))
        }
        R::GetReferenceFrame => Answer::Now(Reply::Byte(atom.cart.reference as u8)),
        R::SetMovementType { mode } => {
            atom.cart.movement = mode;
            Answer::Done(Ok(()))
        }
        R::GetMovementType => Answer::Now(Reply::Byte(atom.cart.movement as u8)),
        R::SetEndType { end } => {
            atom.cart.end = end;
            atom.cart.apply_frames();
            Answer::Done(Ok(()))
        }
        R::GetEndType => Answer::Now(Reply::Byte(match atom.cart.end {
            EndType::Flange => 0,
            EndType::Tool => 1,
        })),

        // The Basic answers these itself; one reaching the Atom (a client on the Atom's own
        // USB) is refused. Drag teaching is not supported.
        R::SetBasicOutput { .. }
        | R::GetBasicInput { .. }
        | R::SetSsidPwd { .. }
        | R::GetSsidPwd
        | R::SetServerPort { .. }
        | R::GetTofDistance
        | R::GetBasicVersion
        | R::SetTransponderMode { .. }
        | R::GetTransponderMode
        | R::DragStartRecord
        | R::DragEndRecord
        | R::DragGetRecordData
        | R::DragGetRecordLen
        | R::DragClearRecordData => Answer::Now(Reply::Byte(0)),
    }
}

fn dir(d: Direction) -> JogDirection {
    match d {
        Direction::Negative => JogDirection::Negative,
        Direction::Positive => JogDirection::Positive,
    }
}

/// An encoder value limited to the servo's range 0..=4095 (`Steps` from the wire may be 4096).
fn clamp_steps(s: Steps) -> Steps {
    Steps(s.0.clamp(0, 4095))
}

/// Positions within 2 mm and orientations within 1 degree count as in position.
fn coords_match(a: &Pose, b: &Pose) -> bool {
    let (a, b) = (a.to_array(), b.to_array());
    a.iter().zip(&b).enumerate().all(|(i, (x, y))| {
        let diff = (i32::from(*x) - i32::from(*y)).abs();
        if i < 3 {
            diff <= 20
        } else {
            // Angles wrap at +-180 degrees.
            diff.min(36_000 - diff) <= 100
        }
    })
}

fn per_joint<T: Default + Copy>(
    atom: &Atom,
    f: impl Fn(&crate::health::ServoHealth) -> T,
) -> [T; JOINTS] {
    core::array::from_fn(|j| atom.servo_health(j).map(&f).unwrap_or_default())
}

/// Read next error (0x15): one code per servo 1..=7 (`ServoErrorCode`).
fn servo_errors(atom: &Atom) -> [u8; SERVOS] {
    core::array::from_fn(|i| {
        let code = match atom.servo_health(i) {
            Some(h) if !h.answering && h.corrupt_answers => ServoErrorCode::BadAnswer,
            Some(h) if !h.answering => ServoErrorCode::NoAnswer,
            Some(h) if h.fault_bits & ServoErrorCode::FAULT_MASK != 0 => {
                ServoErrorCode::Fault(h.fault_bits)
            }
            _ => ServoErrorCode::Ok,
        };
        code.code()
    })
}

impl Atom {
    /// Writes a servo register for 0x52. EEPROM registers are unlocked and locked around the
    /// write. A write touching the goal position is a motion and goes through the choke point;
    /// torque writes go through the torque bookkeeping; id and baud rate are refused.
    fn write_register(
        &mut self,
        index: usize,
        addr: u8,
        value: ServoValue,
    ) -> Result<(), ActionError> {
        let id = *self
            .config
            .servo_ids
            .get(index)
            .ok_or(ActionError::Invalid)?;
        let (data, len): ([u8; 2], u8) = match value {
            ServoValue::Byte(b) => ([b, 0], 1),
            ServoValue::Word(w) => (w.to_le_bytes(), 2),
        };
        let touches = |r: u8| addr <= r && r < addr.saturating_add(len);
        // Changing a servo's id or baud rate takes it off the arm's bus for good.
        if touches(reg::ID) || touches(reg::BAUD_RATE) {
            return Err(ActionError::Invalid);
        }
        // Torque 128 is the calibration: same bookkeeping as 0x54.
        if addr == reg::TORQUE_ENABLE && value == ServoValue::Byte(128) {
            return self.calibrate(index);
        }
        // Any other torque write is torque on/off, with the hold goal a torque-on needs.
        if addr == reg::TORQUE_ENABLE
            && let ServoValue::Byte(b) = value
        {
            return if self.set_torque(index, b != 0) {
                Ok(())
            } else {
                Err(ActionError::Invalid)
            };
        }
        if touches(reg::GOAL_POSITION) || touches(reg::GOAL_POSITION + 1) {
            return match value {
                ServoValue::Word(w) if addr == reg::GOAL_POSITION => {
                    let steps = Steps(protocol_core::servo::sign_magnitude(w, 15));
                    if index == GRIPPER {
                        self.move_gripper_steps(steps, self.speed_percent)
                    } else {
                        self.move_joint_steps(index, steps)
                    }
                }
                _ => Err(ActionError::Invalid),
            };
        }
        let data = data.get(..usize::from(len)).ok_or(ActionError::Invalid)?;
        let eeprom = addr < FIRST_RAM_REGISTER;
        let needed = if eeprom { 3 } else { 1 };
        if self.op_room() < needed {
            return Err(ActionError::Busy);
        }
        let write = Op::write(id, addr, data).ok_or(ActionError::Invalid)?;
        if eeprom && let Some(unlock) = Op::write(id, reg::EEPROM_LOCK, &[0]) {
            self.queue_op(unlock, Then::Nothing);
        }
        self.queue_op(write, Then::Nothing);
        if eeprom && let Some(lock) = Op::write(id, reg::EEPROM_LOCK, &[1]) {
            self.queue_op(lock, Then::Nothing);
        }
        Ok(())
    }

    /// Moves one joint to an encoder position (0x52 at the goal register).
    fn move_joint_steps(&mut self, j: usize, steps: Steps) -> Result<(), ActionError> {
        let mut goals: GoalSet = [None; SERVOS];
        if let Some(slot) = goals.get_mut(j) {
            *slot = Some(Goal {
                position: steps,
                speed_steps_per_s: motion::joint_speed_steps(&self.config, self.speed_percent)
                    as u16,
                accel: motion::joint_accel_register(&self.config),
            });
        }
        self.send_goals(goals)
    }

    /// Calibration (0x54, 0x68): the servo's present position becomes 2048.
    fn calibrate(&mut self, index: usize) -> Result<(), ActionError> {
        let id = *self
            .config
            .servo_ids
            .get(index)
            .ok_or(ActionError::Invalid)?;
        if index < JOINTS {
            self.halt(false);
        }
        let op = Op::write(id, reg::TORQUE_ENABLE, &[128]).ok_or(ActionError::Invalid)?;
        if !self.queue_op(op, Then::Nothing) {
            return Err(ActionError::Busy);
        }
        if let Some(h) = self.health.get_mut(index) {
            h.position = Steps(crate::config::STEPS_ZERO as i16);
        }
        if let Some(g) = self.last_goal.get_mut(index) {
            *g = None;
        }
        if index == GRIPPER {
            let span = self.gripper.open.0 - self.gripper.closed.0;
            self.gripper.closed = Steps(crate::config::STEPS_ZERO as i16);
            self.gripper.open = Steps(crate::config::STEPS_ZERO as i16 + span);
        }
        Ok(())
    }

    /// Joint brake (0x55): the joint holds where it is.
    fn brake(&mut self, index: usize) -> Result<(), ActionError> {
        let steps = self
            .servo_health(index)
            .map(|h| h.position)
            .ok_or(ActionError::Invalid)?;
        if index == GRIPPER {
            return self.move_gripper_steps(steps, 100);
        }
        self.move_joint_steps(index, steps)
    }

    /// Moves to six encoder positions with per-servo speeds (0x3E).
    fn drag_to(
        &mut self,
        encoders: [Steps; JOINTS],
        speeds: [i16; JOINTS],
    ) -> Result<(), ActionError> {
        let accel = motion::joint_accel_register(&self.config);
        let mut goals: GoalSet = [None; SERVOS];
        for (slot, (e, s)) in goals.iter_mut().zip(encoders.iter().zip(speeds)) {
            *slot = Some(Goal {
                position: *e,
                speed_steps_per_s: s.unsigned_abs().max(1),
                accel,
            });
        }
        self.send_goals(goals)
    }

    /// Opens (100), closes (0) or releases the gripper (0x66).
    fn gripper_state(&mut self, state: GripperState, speed: u8) -> Result<(), ActionError> {
        match state {
            GripperState::Open => self.gripper_to(100, speed),
            GripperState::Close => self.gripper_to(0, speed),
            GripperState::Release => {
                if self.set_torque(GRIPPER, false) {
                    Ok(())
                } else {
                    Err(ActionError::Busy)
                }
            }
        }
    }

    /// Moves the gripper to opening `value` 0..=100 (0x67).
    fn gripper_to(&mut self, value: u8, speed: u8) -> Result<(), ActionError> {
        let closed = i32::from(self.gripper.closed.0);
        let open = i32::from(self.gripper.open.0);
        let steps = closed + (open - closed) * i32::from(value.min(100)) / 100;
        self.move_gripper_steps(Steps(steps as i16), speed)
    }

    /// Moves the gripper servo to an encoder position within its range.
    fn move_gripper_steps(&mut self, steps: Steps, speed: u8) -> Result<(), ActionError> {
        let mut goals: GoalSet = [None; SERVOS];
        if let Some(slot) = goals.get_mut(GRIPPER) {
            *slot = Some(Goal {
                position: steps,
                speed_steps_per_s: motion::joint_speed_steps(&self.config, speed.max(1)) as u16,
                accel: motion::joint_accel_register(&self.config),
            });
        }
        self.send_goals(goals)
    }

    /// Sets a joint limit (0x4C/0x4D); refused if min would exceed max or +-180 degrees.
    fn set_limit(
        &mut self,
        j: usize,
        min: Option<Decideg>,
        max: Option<Decideg>,
    ) -> Result<(), ActionError> {
        let limit = self.limits.get(j).copied().ok_or(ActionError::Invalid)?;
        let to_cd = |d: Decideg| i32::from(d.0) * 10;
        let new_min = min.map_or(i32::from(limit.min.0), to_cd);
        let new_max = max.map_or(i32::from(limit.max.0), to_cd);
        if new_min > new_max || new_min < -18_000 || new_max > 18_000 {
            return Err(ActionError::Invalid);
        }
        if let Some(l) = self.limits.get_mut(j) {
            l.min = Centideg(new_min as i16);
            l.max = Centideg(new_max as i16);
        }
        let limits = self.limits;
        self.cart.set_limits(&limits);
        Ok(())
    }
}
