//! Host commands: every request gets exactly one reply carrying its CMD byte.
//!
//! This module only translates: a [`Request`] becomes calls on the Atom's parts and a
//! [`Reply`]. Replies come from cached state (present positions refreshed from the servos), so
//! they leave at once; the reply to a motion command means "accepted", not "arrived". A set
//! command answers `01` when accepted and `00` when refused (out-of-limit joint, unreachable
//! pose, powered off, queue full); a refusal changes nothing and records its error code for
//! 0x07. A frame that is not a valid command (unknown code, wrong length, field out of range)
//! answers `00` too, so the client never waits for a reply that will not come.

use protocol_core::Frame;
use protocol_core::command::{
    DataWidth, Direction, EndType, MoveMode, PinMode as WirePinMode, Pose, PositionTarget, Reply,
    Request, ServoErrorCode, ServoSelect, cmd,
};
use protocol_core::units::{Centideg, Decideg, Steps};

use crate::atom::Parts;
use crate::cartesian::for_client;
use crate::config::{GRIPPER, JOINTS, SERVOS};
use crate::error::AtomError;
use crate::health::ServoHealth;
use crate::io::{AtomIo, PinMode, is_output_pin, mode_allowed};
use crate::link::Link;
use crate::motion::{JogDirection, Target, Way, angles_match};
use crate::registers::{self, ServoAccess};

/// Reported by get system version (0x02): 7.0, the vendor's 280 M5 generation.
const SYSTEM_VERSION_X10: u8 = 70;
/// Reported by get modify version (0x01).
const MODIFY_VERSION: u8 = 0;

/// What get servo status (0xE4) reports for a servo that does not answer: every bit set, a
/// value no answering servo reports (its status register has six fault bits).
const NO_ANSWER_STATUS: u8 = 0xFF;

/// Handles one request; returns the reply (none only when the reply waits for the bus).
pub(crate) fn handle<I: AtomIo>(
    parts: &mut Parts,
    now_us: u64,
    frame: &Frame,
    link: Link,
    io: &mut I,
) -> Option<Frame> {
    let code = frame.cmd();
    // The Basic's own liveness probe (is powered on, every second while the wire is idle)
    // says nothing about the client, so it does not keep a jog alive.
    if code != cmd::IS_POWER_ON {
        parts.motion.note_host_command(now_us);
    }
    let Ok(request) = Request::parse(frame) else {
        return Some(Reply::Byte(0).to_frame(code));
    };
    let reply = match execute(parts, now_us, request, link, io) {
        Answer::Now(reply) => reply,
        Answer::Later => return None,
        Answer::Done(Ok(())) => Reply::Ack,
        Answer::Done(Err(e)) => {
            parts.errors.record(e);
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
    Done(Result<(), AtomError>),
}

fn byte(v: bool) -> Answer {
    Answer::Now(Reply::Byte(u8::from(v)))
}

fn done_if(ok: bool) -> Answer {
    Answer::Done(if ok { Ok(()) } else { Err(AtomError::Invalid) })
}

fn done() -> Answer {
    Answer::Done(Ok(()))
}

fn execute<I: AtomIo>(
    p: &mut Parts,
    now_us: u64,
    request: Request,
    link: Link,
    io: &mut I,
) -> Answer {
    use Request as R;
    let Parts {
        settings,
        bank,
        motion,
        gripper,
        drag,
        gains,
        dispenser,
        errors,
        ..
    } = p;
    match request {
        // --- status and system ---
        R::GetModifyVersion => Answer::Now(Reply::Byte(MODIFY_VERSION)),
        R::GetSystemVersion => Answer::Now(Reply::Byte(SYSTEM_VERSION_X10)),
        R::ClearQueue => {
            motion.clear_queue();
            done()
        }
        // 1: commands are acknowledged at once and run asynchronously.
        R::CheckAsyncOrSync => byte(true),
        R::GetErrorInfo => Answer::Now(Reply::Byte(errors.code())),
        R::ClearErrorInfo => {
            errors.clear();
            done()
        }
        R::PowerOn => {
            settings.set_free_mode(false);
            if bank.powered() {
                // Already on (the Basic says so at its boot): a running move goes on; only
                // a servo released since gets its torque back.
                let mut ok = true;
                for i in 0..SERVOS {
                    if !bank.enabled(i) {
                        ok &= bank.set_torque(settings, i, true);
                    }
                }
                return done_if(ok);
            }
            let ok = bank.power(settings, true);
            // Hold where the arm is now instead of jumping to an old goal.
            motion.stop(now_us, bank, settings);
            done_if(ok)
        }
        R::PowerOff => {
            motion.abandon();
            done_if(bank.power(settings, false))
        }
        R::IsPowerOn => byte(bank.powered()),
        R::ReleaseAllServos { .. } => {
            motion.abandon();
            done_if((0..SERVOS).all(|i| bank.set_torque(settings, i, false)))
        }
        R::IsControllerConnected => byte(true),
        R::ReadNextError => Answer::Now(Reply::ServoErrors(core::array::from_fn(|i| {
            servo_error(bank.health(i)).code()
        }))),
        R::SetFreshMode { fresh } => {
            settings.set_fresh_mode(fresh);
            done()
        }
        R::GetFreshMode => byte(settings.fresh_mode()),
        R::SetFreeMode { on } => {
            settings.set_free_mode(on);
            done()
        }
        R::IsFreeMode => byte(settings.free_mode()),
        R::SetVisionMode { .. } => done(),
        R::GetRebootCount => Answer::Now(Reply::Int16(0)),

        // --- motion ---
        R::GetAngles => Answer::Now(Reply::Angles(bank.present_angles(settings))),
        R::SendAngle {
            joint,
            angle,
            speed,
        } => {
            let target = Target::joints(one_joint(joint.index(), angle), speed.get());
            Answer::Done(motion.submit(now_us, target, bank, settings))
        }
        R::SendAngles { angles, speed } => {
            let target = Target::joints(angles.map(Some), speed.get());
            Answer::Done(motion.submit(now_us, target, bank, settings))
        }
        R::GetCoords => {
            let present = bank.present_angles(settings);
            Answer::Now(Reply::Coords(for_client(
                settings.cart_mut().forward(&present),
            )))
        }
        R::AnglesToCoords { angles } => Answer::Now(Reply::Coords(for_client(
            settings.cart_mut().forward(&angles),
        ))),
        R::SendCoord { target, speed } => {
            let pose = planned_pose(p).with(target);
            let mode = p.settings.cart().movement;
            Answer::Done(move_to_pose(p, now_us, pose, speed.get(), mode))
        }
        R::SendCoords { pose, speed, mode } => {
            let mode = mode.unwrap_or(settings.cart().movement);
            Answer::Done(move_to_pose(p, now_us, pose, speed.get(), mode))
        }
        R::Pause => {
            motion.pause(now_us, bank, settings);
            done()
        }
        R::IsPaused => byte(motion.is_paused()),
        R::Resume => Answer::Done(motion.resume(now_us, bank, settings)),
        R::Stop | R::JogStop => {
            motion.stop(now_us, bank, settings);
            done()
        }
        R::IsInPosition { target } => {
            // Near the target and at rest: pymycobot's sync_send_angles returns as soon as this
            // says 1, so a pose passed through on the way does not count.
            let present = bank.present_angles(settings);
            let near = match target {
                PositionTarget::Angles(a) => angles_match(&present, &a),
                PositionTarget::Coords(pose) => {
                    coords_match(&settings.cart_mut().forward(&present), &pose)
                }
            };
            byte(near && !is_moving(p))
        }
        R::IsMoving => byte(is_moving(p)),
        // No solution: `00` (pymycobot then returns 0, never a list of angles) and error 32.
        R::SolveIk { target, current } => match settings.cart().inverse(&target, &current) {
            Ok(q) => Answer::Now(Reply::Angles(q)),
            Err(e) => Answer::Done(Err(e.into())),
        },
        R::GetAnglesCoords => {
            let angles = bank.present_angles(settings);
            let coords = for_client(settings.cart_mut().forward(&angles));
            Answer::Now(Reply::AnglesAndCoords { angles, coords })
        }
        R::GetPlannedAngles => Answer::Now(Reply::Angles(motion.planned_angles(bank, settings))),
        R::GetPlannedCoords => Answer::Now(Reply::Coords(for_client(planned_pose(p)))),
        R::MoveCCoords { begin, middle, end } => Answer::Done(motion.submit_arc(
            now_us,
            Some(begin),
            middle,
            end,
            settings.speed_percent(),
            bank,
            settings,
        )),
        R::MoveCCoordsFromHere { middle, end } => Answer::Done(motion.submit_arc(
            now_us,
            None,
            middle,
            end,
            settings.speed_percent(),
            bank,
            settings,
        )),
        R::SetPid { gains: values } => Answer::Done(gains.set(bank, settings, values)),
        R::GetPid => match gains.read(bank, settings, link) {
            Ok(()) => Answer::Later,
            Err(e) => Answer::Done(Err(e)),
        },
        R::MoveRound => Answer::Done(dispenser.turn(now_us, io)),
        R::SetFourPiecesZero => byte(dispenser.zero(io)),

        // --- jog ---
        R::JogAngle {
            joint,
            direction,
            speed,
        } => Answer::Done(motion.jog_joint(
            now_us,
            joint.index(),
            dir(direction),
            speed.get(),
            bank,
            settings,
        )),
        R::JogRpy {
            axis,
            direction,
            speed,
        } => Answer::Done(motion.jog_pose(
            now_us,
            3 + axis as usize - 1,
            dir(direction),
            speed.get(),
            bank,
            settings,
        )),
        R::JogCoord {
            axis,
            direction,
            speed,
        } => Answer::Done(motion.jog_pose(
            now_us,
            axis.index(),
            dir(direction),
            speed.get(),
            bank,
            settings,
        )),
        R::JogIncrementAngle {
            joint,
            increment,
            speed,
        } => {
            let j = joint.index();
            let base = motion.planned_angles(bank, settings);
            let from = base.get(j).copied().unwrap_or_default();
            let Ok(goal) = i16::try_from(i32::from(from.0) + i32::from(increment.0)) else {
                return Answer::Done(Err(AtomError::JointLimit(j)));
            };
            let target = Target::joints(one_joint(j, Centideg(goal)), speed.get());
            Answer::Done(motion.submit(now_us, target, bank, settings))
        }
        R::JogIncrementCoord { increment, speed } => {
            let base = planned_pose(p);
            let axis = increment.axis();
            let goal = i32::from(base.get(axis).raw()) + i32::from(increment.raw());
            let Ok(goal) = i16::try_from(goal) else {
                return Answer::Done(Err(AtomError::Unreachable));
            };
            let pose = base.with(protocol_core::command::AxisValue::new(axis, goal));
            Answer::Done(move_to_pose(p, now_us, pose, speed.get(), MoveMode::Joint))
        }

        // --- encoders, speed, limits ---
        R::SetEncoder {
            servo,
            encoder,
            speed,
        } => {
            let speed = speed.map_or(settings.speed_percent(), |s| s.get());
            let index = usize::from(servo.get()) - 1;
            if index == GRIPPER {
                return Answer::Done(crate::gripper::move_steps(bank, settings, encoder, speed));
            }
            if encoder != clamp_steps(encoder) {
                return Answer::Done(Err(AtomError::JointLimit(index)));
            }
            let angle = settings.angle(index, encoder);
            let target = Target::joints(one_joint(index, angle), speed);
            Answer::Done(motion.submit(now_us, target, bank, settings))
        }
        R::GetEncoder { servo } => {
            let index = usize::from(servo.get()) - 1;
            Answer::Now(Reply::Int16(bank.health(index).map_or(0, |h| h.position.0)))
        }
        R::SetEncoders { encoders, speed } => {
            if let Some(j) = encoders.iter().position(|&e| e != clamp_steps(e)) {
                return Answer::Done(Err(AtomError::JointLimit(j)));
            }
            let angles = core::array::from_fn(|j| {
                Some(settings.angle(j, encoders.get(j).copied().unwrap_or_default()))
            });
            let target = Target::joints(angles, speed.get());
            Answer::Done(motion.submit(now_us, target, bank, settings))
        }
        R::GetEncoders => Answer::Now(Reply::Encoders(bank.present_steps())),
        R::SetEncodersDrag {
            encoders,
            speeds_steps_per_s,
        } => Answer::Done(registers::drag_to(
            bank,
            settings,
            encoders,
            speeds_steps_per_s,
        )),
        R::GetSpeed => Answer::Now(Reply::Byte(settings.speed_percent())),
        R::SetSpeed { speed } => {
            settings.set_speed_percent(speed.get());
            done()
        }
        R::GetJointMin { joint } => Answer::Now(Reply::JointLimit {
            joint,
            limit: Decideg(settings.limit(joint.index()).map_or(0, |l| l.min.0) / 10),
        }),
        R::GetJointMax { joint } => Answer::Now(Reply::JointLimit {
            joint,
            limit: Decideg(settings.limit(joint.index()).map_or(0, |l| l.max.0) / 10),
        }),
        R::SetJointMin { joint, limit } => {
            Answer::Done(settings.set_limit(joint.index(), Some(limit), None))
        }
        R::SetJointMax { joint, limit } => {
            Answer::Done(settings.set_limit(joint.index(), None, Some(limit)))
        }

        // --- servos ---
        R::IsServoEnabled { servo } => Answer::Now(Reply::ServoEnabled {
            servo,
            enabled: bank.enabled(usize::from(servo.get()) - 1),
        }),
        R::AreAllServosEnabled => byte((0..JOINTS).all(|j| bank.enabled(j))),
        R::SetServoData {
            servo,
            address,
            value,
        } => Answer::Done(access(p).write(now_us, usize::from(servo.get()) - 1, address, value)),
        R::GetServoData {
            servo,
            address,
            width,
        } => {
            let two_bytes = width == Some(DataWidth::Word);
            match access(p).read(usize::from(servo.get()) - 1, address, two_bytes, link) {
                Ok(()) => Answer::Later,
                Err(e) => Answer::Done(Err(e)),
            }
        }
        R::SetServoCalibration { servo } => {
            Answer::Done(access(p).calibrate(now_us, usize::from(servo.get()) - 1))
        }
        R::JointBrake { servo } => Answer::Done(access(p).brake(usize::from(servo.get()) - 1)),
        R::ReleaseServo { servo, .. } => {
            let index = usize::from(servo.get()) - 1;
            if index < JOINTS {
                motion.halt(now_us, bank, settings);
            }
            done_if(bank.set_torque(settings, index, false))
        }
        R::FocusServo { servo } => match servo {
            ServoSelect::All => done_if((0..SERVOS).all(|i| bank.set_torque(settings, i, true))),
            ServoSelect::One(s) => {
                done_if(bank.set_torque(settings, usize::from(s.get()) - 1, true))
            }
        },
        R::GetServoSpeeds => Answer::Now(Reply::Int16x6(per_joint(p, |h| h.speed_steps_per_s))),
        R::GetServoCurrents => Answer::Now(Reply::Int16x6(per_joint(p, |h| {
            // The STS current register counts 6.5 mA units.
            (i32::from(h.current_raw) * 65 / 10).clamp(-32_768, 32_767) as i16
        }))),
        R::GetServoVoltages => Answer::Now(Reply::Bytes6(per_joint(p, |h| h.voltage_decivolt))),
        R::GetServoStatus => Answer::Now(Reply::Bytes6(per_joint(p, |h| {
            if h.answering {
                h.fault_bits
            } else {
                NO_ANSWER_STATUS
            }
        }))),
        R::GetServoTemps => Answer::Now(Reply::Bytes6(per_joint(p, |h| h.temperature_c))),
        R::BackupServoParams { servo } | R::RestoreServoParams { servo } => {
            let restore = matches!(request, R::RestoreServoParams { .. });
            let has_store = io.param_store().is_some();
            match p
                .backups
                .start(restore, servo, link, has_store, &mut p.bank, &p.settings)
            {
                Ok(()) => Answer::Later,
                Err(e) => Answer::Done(Err(e)),
            }
        }

        // --- Atom IO, LED, gripper ---
        R::SetPinMode { pin, mode } => {
            let mode = match mode {
                WirePinMode::Input => PinMode::Input,
                WirePinMode::Output => PinMode::Output,
                WirePinMode::InputPullUp => PinMode::InputPullUp,
            };
            done_if(mode_allowed(pin.gpio(), mode) && io.set_pin_mode(pin.gpio(), mode))
        }
        R::SetDigitalOutput { pin, high } => {
            done_if(is_output_pin(pin.gpio()) && io.write_pin(pin.gpio(), high))
        }
        R::GetDigitalInput { pin } => match io.read_pin(pin.gpio()) {
            Some(high) => Answer::Now(Reply::PinLevel {
                pin: pin.gpio(),
                high,
            }),
            None => Answer::Done(Err(AtomError::Invalid)),
        },
        R::SetPwmOutput {
            pin,
            frequency_hz,
            duty,
        } => done_if(
            frequency_hz > 0
                && is_output_pin(pin.gpio())
                && io.set_pwm(pin.gpio(), frequency_hz, duty),
        ),
        R::GetGripperValue { .. } => Answer::Now(Reply::Byte(gripper.value(bank))),
        R::SetGripperStateNoSpeed { state } => {
            Answer::Done(gripper.set_state(bank, settings, state, 50))
        }
        R::SetGripperState { state, speed, .. } => {
            Answer::Done(gripper.set_state(bank, settings, state, speed.get()))
        }
        R::SetGripperValue { value, speed, .. } => {
            Answer::Done(gripper.move_to(bank, settings, value.get(), speed.get()))
        }
        R::SetGripperCalibration => Answer::Done(access(p).calibrate(now_us, GRIPPER)),
        R::IsGripperMoving => byte(bank.servo_moving(GRIPPER)),
        R::SetColor { rgb } => {
            io.set_rgb(rgb.r, rgb.g, rgb.b);
            done()
        }
        R::SetHtsGripperTorque { torque } => {
            gripper.set_torque(torque);
            Answer::Now(Reply::Byte(1))
        }
        R::GetHtsGripperTorque => Answer::Now(Reply::Int16(gripper.torque())),
        R::GetGripperProtectCurrent => Answer::Now(Reply::Int16(gripper.protect_current())),
        R::InitGripper => byte(access(p).calibrate(now_us, GRIPPER).is_ok()),
        R::SetGripperProtectCurrent { current } => {
            gripper.set_protect_current(current);
            done()
        }

        // --- drag teaching ---
        R::DragStartRecord => Answer::Now(Reply::Int16(count(drag.start(now_us)))),
        R::DragEndRecord => Answer::Now(Reply::Int16(count(drag.end()))),
        R::DragGetRecordData => Answer::Now(Reply::DragPoint(drag.next_point())),
        R::DragGetRecordLen => Answer::Now(Reply::Int16(count(drag.recorded()))),
        R::DragClearRecordData => Answer::Now(Reply::Int16(count(drag.clear()))),

        // --- coordinate frames ---
        R::SetToolReference { pose } => {
            let cart = settings.cart_mut();
            cart.tool = pose;
            cart.apply_frames();
            done()
        }
        R::GetToolReference => Answer::Now(Reply::Coords(settings.cart().tool)),
        R::SetWorldReference { pose } => {
            let cart = settings.cart_mut();
            cart.world = pose;
            cart.apply_frames();
            done()
        }
        R::GetWorldReference => Answer::Now(Reply::Coords(settings.cart().world)),
        R::SetReferenceFrame { frame } => {
            let cart = settings.cart_mut();
            cart.reference = frame;
            cart.apply_frames();
            done()
        }
        R::GetReferenceFrame => Answer::Now(Reply::Byte(settings.cart().reference as u8)),
        R::SetMovementType { mode } => {
            settings.cart_mut().movement = mode;
            done()
        }
        R::GetMovementType => Answer::Now(Reply::Byte(settings.cart().movement as u8)),
        R::SetEndType { end } => {
            let cart = settings.cart_mut();
            cart.end = end;
            cart.apply_frames();
            done()
        }
        R::GetEndType => Answer::Now(Reply::Byte(match settings.cart().end {
            EndType::Flange => 0,
            EndType::Tool => 1,
        })),

        // The Basic answers these itself; one reaching the Atom (a client on the Atom's own
        // USB) is refused.
        R::SetBasicOutput { .. }
        | R::GetBasicInput { .. }
        | R::SetSsidPwd { .. }
        | R::GetSsidPwd
        | R::SetServerPort { .. }
        | R::GetTofDistance
        | R::GetBasicVersion
        | R::SetTransponderMode { .. }
        | R::GetTransponderMode => Answer::Now(Reply::Byte(0)),
    }
}

/// The parts a single-servo access touches.
fn access(p: &mut Parts) -> ServoAccess<'_> {
    ServoAccess {
        bank: &mut p.bank,
        settings: &p.settings,
        motion: &mut p.motion,
        gripper: &mut p.gripper,
    }
}

/// True while the arm moves (a motion runs or a joint reports moving).
pub(crate) fn is_moving(p: &Parts) -> bool {
    p.motion.is_active() || p.bank.joints_moving()
}

/// The end pose the arm is going to (the present pose when idle).
fn planned_pose(p: &mut Parts) -> Pose {
    if let Some(pose) = p.motion.planned_pose() {
        return pose;
    }
    let angles = p.motion.planned_angles(&p.bank, &p.settings);
    p.settings.cart_mut().forward(&angles)
}

/// Moves the end to `pose`: joint-interpolated (mode 0) or along a straight line (mode 1).
fn move_to_pose(
    p: &mut Parts,
    now_us: u64,
    pose: Pose,
    speed_percent: u8,
    mode: MoveMode,
) -> Result<(), AtomError> {
    if !p.bank.powered() {
        return Err(AtomError::PoweredOff);
    }
    let seed = p.motion.planned_angles(&p.bank, &p.settings);
    let angles = p.settings.cart().inverse(&pose, &seed)?;
    let target = Target {
        angles: angles.map(Some),
        speed_percent,
        way: match mode {
            MoveMode::Linear => Way::Line(pose),
            MoveMode::Joint => Way::Joints,
        },
    };
    p.motion.submit(now_us, target, &mut p.bank, &p.settings)
}

/// Angles with only joint `j` given.
fn one_joint(j: usize, angle: Centideg) -> [Option<Centideg>; JOINTS] {
    let mut angles = [None; JOINTS];
    if let Some(slot) = angles.get_mut(j) {
        *slot = Some(angle);
    }
    angles
}

/// A count of drag-teaching points as the int16 the host reads (at most 1 000).
fn count(n: u16) -> i16 {
    i16::try_from(n).unwrap_or(i16::MAX)
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

fn per_joint<T: Default + Copy>(p: &Parts, f: impl Fn(&ServoHealth) -> T) -> [T; JOINTS] {
    core::array::from_fn(|j| p.bank.health(j).map(&f).unwrap_or_default())
}

/// One servo's entry of read next error (0x15, `ServoErrorCode`).
fn servo_error(health: Option<&ServoHealth>) -> ServoErrorCode {
    match health {
        Some(h) if !h.answering && h.corrupt_answers => ServoErrorCode::BadAnswer,
        Some(h) if !h.answering => ServoErrorCode::NoAnswer,
        Some(h) if h.fault_bits & ServoErrorCode::FAULT_MASK != 0 => {
            ServoErrorCode::Fault(h.fault_bits)
        }
        _ => ServoErrorCode::Ok,
    }
}
