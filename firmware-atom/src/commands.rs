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
    DataWidth, Direction, EndType, MoveMode, PinMode as WirePinMode, Reply, Request,
    ServoErrorCode, ServoSelect, cmd,
};
use protocol_core::units::{Centideg, Decideg};

use crate::cartesian::for_client;
use crate::config::{GRIPPER, JOINTS, SERVOS, in_encoder_range};
use crate::context::Context;
use crate::error::AtomError;
use crate::flash_writes::Queued;
use crate::health::ServoHealth;
use crate::io::{AtomIo, PinMode, is_output_pin, mode_allowed};
use crate::link::Link;
use crate::motion::{Command, JogDirection, Target};
use crate::parts::Parts;
use crate::store::ParamStore;
use crate::waiting::WaitingRead;
use crate::{backup, gains, gripper, registers};

/// Reported by get system version (0x02): 7.0, the vendor's 280 M5 generation.
const SYSTEM_VERSION_X10: u8 = 70;
/// Reported by get modify version (0x01).
const MODIFY_VERSION: u8 = 0;

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

/// The flash seen through the records waiting for it, as the parts take a store.
fn as_store<'a>(queued: &'a mut Queued<'_>) -> &'a mut dyn ParamStore {
    queued
}

fn execute<I: AtomIo>(
    p: &mut Parts,
    now_us: u64,
    request: Request,
    link: Link,
    io: &mut I,
) -> Answer {
    use Request as R;
    if matches!(request, R::ClearErrorInfo | R::PowerOn) {
        // Both end a collision's refusal of motion (docs/protocol.md section 7).
        p.clear_collision();
    }
    let Parts {
        settings,
        bank,
        motion,
        gripper,
        drag,
        dispenser,
        errors,
        waiting,
        collision: _,
        flash_writes,
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
                // Already on (the Basic says so at its boot): a running move goes on.
                return done_if(bank.focus_released(settings));
            }
            let ok = bank.power(settings, true);
            // Hold where the arm is now instead of jumping to an old goal.
            motion.stop(&mut Context::new(now_us, bank, settings));
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
            bank.health(i)
                .map_or(ServoErrorCode::Ok, ServoHealth::error_code)
                .code()
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
        R::GetAngles => Answer::Now(Reply::Angles(bank.present_angles(now_us, settings))),
        R::SendAngle {
            joint,
            angle,
            speed,
        } => {
            let target = Target::joint(joint.index(), angle, speed.get());
            let cx = &mut Context::new(now_us, bank, settings);
            Answer::Done(motion.command(cx, Command::Move(target)))
        }
        R::SendAngles { angles, speed } => {
            let target = Target::joints(angles.map(Some), speed.get());
            let cx = &mut Context::new(now_us, bank, settings);
            Answer::Done(motion.command(cx, Command::Move(target)))
        }
        R::GetCoords => {
            let present = bank.present_angles(now_us, settings);
            Answer::Now(Reply::Coords(for_client(settings.cart().forward(&present))))
        }
        R::AnglesToCoords { angles } => {
            Answer::Now(Reply::Coords(for_client(settings.cart().forward(&angles))))
        }
        R::SendCoord { target, speed } => {
            let mode = settings.cart().movement();
            let cx = &mut Context::new(now_us, bank, settings);
            let pose = motion.planned_pose(cx).with(target);
            let to_pose = Command::ToPose {
                pose,
                speed_percent: speed.get(),
                mode,
            };
            Answer::Done(motion.command(cx, to_pose))
        }
        R::SendCoords { pose, speed, mode } => {
            let mode = mode.unwrap_or(settings.cart().movement());
            let cx = &mut Context::new(now_us, bank, settings);
            let to_pose = Command::ToPose {
                pose,
                speed_percent: speed.get(),
                mode,
            };
            Answer::Done(motion.command(cx, to_pose))
        }
        R::Pause => {
            motion.pause(&mut Context::new(now_us, bank, settings));
            done()
        }
        R::IsPaused => byte(motion.is_paused()),
        R::Resume => Answer::Done(motion.resume(&mut Context::new(now_us, bank, settings))),
        R::Stop | R::JogStop => {
            motion.stop(&mut Context::new(now_us, bank, settings));
            done()
        }
        R::IsInPosition { target } => {
            let cx = &Context::new(now_us, bank, settings);
            byte(motion.in_position(cx, &target))
        }
        R::IsMoving => byte(motion.is_moving(bank, now_us)),
        // No solution: `00` (pymycobot then returns 0, never a list of angles) and error 32.
        R::SolveIk { target, current } => match settings.cart().inverse(&target, &current) {
            Ok(q) => Answer::Now(Reply::Angles(q)),
            Err(e) => Answer::Done(Err(e.into())),
        },
        R::GetAnglesCoords => {
            let angles = bank.present_angles(now_us, settings);
            let coords = for_client(settings.cart().forward(&angles));
            Answer::Now(Reply::AnglesAndCoords { angles, coords })
        }
        R::GetPlannedAngles => {
            let cx = &Context::new(now_us, bank, settings);
            Answer::Now(Reply::Angles(motion.planned_angles(cx)))
        }
        R::GetPlannedCoords => {
            let cx = &Context::new(now_us, bank, settings);
            Answer::Now(Reply::Coords(for_client(motion.planned_pose(cx))))
        }
        R::MoveCCoords { begin, middle, end } => {
            let arc = Command::Arc {
                begin: Some(begin),
                via: middle,
                end,
                speed_percent: settings.speed_percent(),
            };
            Answer::Done(motion.command(&mut Context::new(now_us, bank, settings), arc))
        }
        R::MoveCCoordsFromHere { middle, end } => {
            let arc = Command::Arc {
                begin: None,
                via: middle,
                end,
                speed_percent: settings.speed_percent(),
            };
            Answer::Done(motion.command(&mut Context::new(now_us, bank, settings), arc))
        }
        R::SetPid { gains: values } => Answer::Done(gains::set(bank, settings, values)),
        R::GetPid => later(gains::reads(settings).and_then(|(ids, ops)| {
            let pid = WaitingRead::Pid {
                ids,
                got: [None; 2],
            };
            waiting.start(bank, link, pid, &ops)
        })),
        R::MoveRound => Answer::Done(dispenser.turn(now_us, io)),
        R::SetFourPiecesZero => byte(dispenser.zero(io)),

        // --- jog ---
        R::JogAngle {
            joint,
            direction,
            speed,
        } => {
            let jog = Command::JogJoint {
                joint: joint.index(),
                direction: dir(direction),
                speed_percent: speed.get(),
            };
            Answer::Done(motion.command(&mut Context::new(now_us, bank, settings), jog))
        }
        R::JogRpy {
            axis,
            direction,
            speed,
        } => {
            let jog = Command::JogPose {
                axis: 3 + axis as usize - 1,
                direction: dir(direction),
                speed_percent: speed.get(),
            };
            Answer::Done(motion.command(&mut Context::new(now_us, bank, settings), jog))
        }
        R::JogCoord {
            axis,
            direction,
            speed,
        } => {
            let jog = Command::JogPose {
                axis: axis.index(),
                direction: dir(direction),
                speed_percent: speed.get(),
            };
            Answer::Done(motion.command(&mut Context::new(now_us, bank, settings), jog))
        }
        R::JogIncrementAngle {
            joint,
            increment,
            speed,
        } => {
            let j = joint.index();
            let cx = &mut Context::new(now_us, bank, settings);
            let from = motion
                .planned_angles(cx)
                .get(j)
                .copied()
                .unwrap_or_default();
            let Ok(goal) = i16::try_from(i32::from(from.0) + i32::from(increment.0)) else {
                return Answer::Done(Err(AtomError::JointLimit(j)));
            };
            let target = Target::joint(j, Centideg(goal), speed.get());
            Answer::Done(motion.command(cx, Command::Move(target)))
        }
        R::JogIncrementCoord { increment, speed } => {
            let cx = &mut Context::new(now_us, bank, settings);
            let base = motion.planned_pose(cx);
            let axis = increment.axis();
            let goal = i32::from(base.get(axis).raw()) + i32::from(increment.raw());
            let Ok(goal) = i16::try_from(goal) else {
                return Answer::Done(Err(AtomError::Unreachable));
            };
            let to_pose = Command::ToPose {
                pose: base.with(protocol_core::command::AxisValue::new(axis, goal)),
                speed_percent: speed.get(),
                mode: MoveMode::Joint,
            };
            Answer::Done(motion.command(cx, to_pose))
        }

        // --- encoders, speed, limits ---
        R::SetEncoder {
            servo,
            encoder,
            speed,
        } => {
            let speed = speed.map_or(settings.speed_percent(), |s| s.get());
            let index = servo.index();
            let cx = &mut Context::new(now_us, bank, settings);
            if index == GRIPPER {
                return Answer::Done(gripper::move_steps(cx, encoder, speed));
            }
            if !in_encoder_range(encoder) {
                return Answer::Done(Err(AtomError::JointLimit(index)));
            }
            let target = Target::joint(index, settings.angle(index, encoder), speed);
            Answer::Done(motion.command(cx, Command::Move(target)))
        }
        R::GetEncoder { servo } => {
            let index = servo.index();
            Answer::Now(Reply::Int16(bank.health(index).map_or(0, |h| h.position.0)))
        }
        R::SetEncoders { encoders, speed } => {
            if let Some(j) = encoders.iter().position(|&e| !in_encoder_range(e)) {
                return Answer::Done(Err(AtomError::JointLimit(j)));
            }
            let angles = core::array::from_fn(|j| {
                Some(settings.angle(j, encoders.get(j).copied().unwrap_or_default()))
            });
            let target = Target::joints(angles, speed.get());
            let cx = &mut Context::new(now_us, bank, settings);
            Answer::Done(motion.command(cx, Command::Move(target)))
        }
        R::GetEncoders => Answer::Now(Reply::Encoders(bank.present_steps())),
        R::SetEncodersDrag {
            encoders,
            speeds_steps_per_s,
        } => {
            let cx = &mut Context::new(now_us, bank, settings);
            Answer::Done(registers::drag_to(cx, motion, encoders, speeds_steps_per_s))
        }
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
            enabled: bank.enabled(servo.index()),
        }),
        R::AreAllServosEnabled => byte((0..JOINTS).all(|j| bank.enabled(j))),
        R::SetServoData {
            servo,
            address,
            value,
        } => {
            let index = servo.index();
            let cx = &mut Context::new(now_us, bank, settings);
            Answer::Done(registers::write(cx, motion, gripper, index, address, value))
        }
        R::GetServoData {
            servo,
            address,
            width,
        } => {
            let two_bytes = width == Some(DataWidth::Word);
            let index = servo.index();
            later(
                registers::read(settings, index, address, two_bytes).and_then(|op| {
                    let read = WaitingRead::ServoData { two_bytes };
                    waiting.start(bank, link, read, &[op])
                }),
            )
        }
        R::SetServoCalibration { servo } => {
            let index = servo.index();
            let cx = &mut Context::new(now_us, bank, settings);
            Answer::Done(registers::calibrate(cx, motion, gripper, index))
        }
        R::JointBrake { servo } => {
            let cx = &mut Context::new(now_us, bank, settings);
            Answer::Done(registers::brake(cx, servo.index()))
        }
        R::ReleaseServo { servo, .. } => {
            let index = servo.index();
            if index < JOINTS {
                motion.halt(&mut Context::new(now_us, bank, settings));
            }
            done_if(bank.set_torque(settings, index, false))
        }
        R::FocusServo { servo } => match servo {
            ServoSelect::All => done_if((0..SERVOS).all(|i| bank.set_torque(settings, i, true))),
            ServoSelect::One(s) => done_if(bank.set_torque(settings, s.index(), true)),
        },
        R::GetServoSpeeds => Answer::Now(Reply::Int16x6(bank.per_joint(|h| h.speed_steps_per_s))),
        R::GetServoCurrents => Answer::Now(Reply::Int16x6(
            bank.per_joint(ServoHealth::current_milliamps),
        )),
        R::GetServoVoltages => Answer::Now(Reply::Bytes6(bank.per_joint(|h| h.voltage_decivolt))),
        R::GetServoStatus => Answer::Now(Reply::Bytes6(bank.per_joint(ServoHealth::status_byte))),
        R::GetServoTemps => Answer::Now(Reply::Bytes6(bank.per_joint(|h| h.temperature_c))),
        R::BackupServoParams { servo } | R::RestoreServoParams { servo } => {
            let restore = matches!(request, R::RestoreServoParams { .. });
            let has_store = io.param_store().is_some();
            let cx = &Context::new(now_us, bank, settings);
            later(
                backup::reads(cx, servo, has_store).and_then(|(ops, servos)| {
                    let params = WaitingRead::Params {
                        restore,
                        waiting: servos,
                        ok: true,
                    };
                    waiting.start(bank, link, params, &ops)
                }),
            )
        }

        // --- collision protection ---
        R::SetCollisionMode { on } => {
            let mut changed = *settings.collision();
            changed.set_enabled(on);
            let kept = settings.collision_mut().replace_kept(
                changed,
                flash_writes.over(io.param_store()).as_mut().map(as_store),
            );
            Answer::Done(kept.map_err(|_| AtomError::Invalid))
        }
        R::GetCollisionMode => byte(settings.collision().enabled()),
        R::SetCollisionThreshold { joint, threshold } => {
            let mut changed = *settings.collision();
            if changed.set_threshold(joint.get(), threshold.get()).is_err() {
                return Answer::Done(Err(AtomError::Invalid));
            }
            let kept = settings.collision_mut().replace_kept(
                changed,
                flash_writes.over(io.param_store()).as_mut().map(as_store),
            );
            Answer::Done(kept.map_err(|_| AtomError::Invalid))
        }
        R::GetCollisionThresholds => Answer::Now(Reply::Bytes6(settings.collision().thresholds())),

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
            let cx = &mut Context::new(now_us, bank, settings);
            Answer::Done(gripper.set_state(cx, state, 50))
        }
        R::SetGripperState { state, speed, .. } => {
            let cx = &mut Context::new(now_us, bank, settings);
            Answer::Done(gripper.set_state(cx, state, speed.get()))
        }
        R::SetGripperValue { value, speed, .. } => {
            let cx = &mut Context::new(now_us, bank, settings);
            Answer::Done(gripper.move_to(cx, value.get(), speed.get()))
        }
        R::SetGripperCalibration => {
            let cx = &mut Context::new(now_us, bank, settings);
            Answer::Done(registers::calibrate(cx, motion, gripper, GRIPPER))
        }
        R::IsGripperMoving => byte(bank.servo_moving(now_us, GRIPPER)),
        R::SetColor { rgb } => done_if(io.set_rgb(rgb.r, rgb.g, rgb.b)),
        R::SetHtsGripperTorque { torque } => {
            gripper.set_torque(torque);
            Answer::Now(Reply::Byte(1))
        }
        R::GetHtsGripperTorque => Answer::Now(Reply::Int16(gripper.torque())),
        R::GetGripperProtectCurrent => Answer::Now(Reply::Int16(gripper.protect_current())),
        R::InitGripper => {
            let cx = &mut Context::new(now_us, bank, settings);
            byte(registers::calibrate(cx, motion, gripper, GRIPPER).is_ok())
        }
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
            settings.set_tool(pose);
            done()
        }
        R::GetToolReference => Answer::Now(Reply::Coords(settings.cart().tool())),
        R::SetWorldReference { pose } => {
            settings.set_world(pose);
            done()
        }
        R::GetWorldReference => Answer::Now(Reply::Coords(settings.cart().world())),
        R::SetReferenceFrame { frame } => {
            settings.set_reference(frame);
            done()
        }
        R::GetReferenceFrame => Answer::Now(Reply::Byte(settings.cart().reference() as u8)),
        R::SetMovementType { mode } => {
            settings.set_movement(mode);
            done()
        }
        R::GetMovementType => Answer::Now(Reply::Byte(settings.cart().movement() as u8)),
        R::SetEndType { end } => {
            settings.set_end(end);
            done()
        }
        R::GetEndType => Answer::Now(Reply::Byte(match settings.cart().end() {
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
        | R::GetTransponderMode
        | R::Dialect { .. } => Answer::Now(Reply::Byte(0)),
    }
}

/// A request whose reply waits for servo reads: later if they were queued, refused if not.
fn later(queued: Result<(), AtomError>) -> Answer {
    match queued {
        Ok(()) => Answer::Later,
        Err(e) => Answer::Done(Err(e)),
    }
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

#[cfg(test)]
mod tests {
    use super::*;
    use crate::bank::test_support::{at_rest, powered};
    use crate::config::AtomConfig;
    use crate::io::RecordingIo;
    use crate::settings::Settings;

    fn ask(parts: &mut Parts, code: u8, data: &[u8]) -> Option<std::vec::Vec<u8>> {
        let frame = Frame::new(code, data).unwrap();
        let reply = handle(parts, 0, &frame, Link::Usb, &mut RecordingIo::default())?;
        assert_eq!(reply.cmd(), code, "a reply carries its request's CMD byte");
        Some(reply.data().to_vec())
    }

    /// Send angle (0x21): joint 1 to `degrees` at 50 %.
    fn send_angle_1(parts: &mut Parts, degrees: i16) -> Option<std::vec::Vec<u8>> {
        let mut data = std::vec![1];
        data.extend_from_slice(&(degrees * 100).to_be_bytes());
        data.push(50);
        ask(parts, cmd::SEND_ANGLE, &data)
    }

    /// The parts of a powered arm whose servos were all read at time 0, at rest at 0 deg.
    fn read_arm() -> Parts {
        let (settings, bank) = at_rest();
        let mut parts = Parts::new(settings);
        parts.bank = bank;
        parts
    }

    #[test]
    fn a_refused_motion_answers_00_and_records_its_code_for_0x07() {
        let mut parts = read_arm();
        assert_eq!(
            send_angle_1(&mut parts, 170),
            Some(std::vec![0]),
            "J1 ends at 168 deg"
        );
        assert_eq!(
            ask(&mut parts, cmd::GET_ERROR_INFO, &[]),
            Some(std::vec![1])
        );
        assert!(!parts.motion.is_active(), "nothing moves");
    }

    #[test]
    fn a_motion_while_powered_off_is_refused_without_an_error_code() {
        let mut parts = Parts::new(Settings::new(AtomConfig::default()));
        assert_eq!(send_angle_1(&mut parts, 10), Some(std::vec![0]));
        assert_eq!(
            ask(&mut parts, cmd::GET_ERROR_INFO, &[]),
            Some(std::vec![0])
        );
    }

    #[test]
    fn an_accepted_motion_becomes_goals_for_the_servos() {
        let mut parts = read_arm();
        assert_eq!(send_angle_1(&mut parts, 10), Some(std::vec![1]));
        assert!(parts.motion.is_active());
        assert!(parts.bank.take_goal_write(0, &parts.settings).is_some());
    }

    #[test]
    fn a_frame_setting_reads_back_as_set() {
        let mut parts = Parts::new(powered());
        let tool: std::vec::Vec<u8> = [100i16, 0, 500, 0, 0, 9_000]
            .iter()
            .flat_map(|v| v.to_be_bytes())
            .collect();
        assert_eq!(
            ask(&mut parts, cmd::SET_TOOL_REFERENCE, &tool),
            Some(std::vec![1])
        );
        assert_eq!(ask(&mut parts, cmd::GET_TOOL_REFERENCE, &[]), Some(tool));
        assert_eq!(ask(&mut parts, cmd::SET_END_TYPE, &[1]), Some(std::vec![1]));
        assert_eq!(ask(&mut parts, cmd::GET_END_TYPE, &[]), Some(std::vec![1]));
    }

    #[test]
    fn a_servo_data_read_answers_later_through_the_bank() {
        let mut parts = Parts::new(powered());
        assert_eq!(ask(&mut parts, cmd::GET_SERVO_DATA, &[2, 56]), None);
        assert_eq!(
            parts.bank.due_job(),
            Some(crate::driver::Op::Read {
                id: 2,
                addr: 56,
                count: 1
            })
        );
    }

    #[test]
    fn a_frame_that_is_no_valid_command_answers_00() {
        let mut parts = Parts::new(powered());
        assert_eq!(ask(&mut parts, 0xEE, &[]), Some(std::vec![0]));
        assert_eq!(ask(&mut parts, cmd::SEND_ANGLE, &[1]), Some(std::vec![0]));
    }
}
