//! One servo at a time: torque, brake, calibration, registers, health, backups.

use protocol_core::command::{DataWidth, Reply, Request, ServoSelect};

use crate::config::{JOINTS, SERVOS};
use crate::context::Context;
use crate::health::ServoHealth;
use crate::io::AtomIo;
use crate::link::Link;
use crate::parts::Parts;
use crate::waiting::WaitingRead;
use crate::{backup, registers};

use super::answer::{Answer, byte, done_if, later};

/// Answers `request` if it is one of these; `None` if not.
pub(super) fn execute<I: AtomIo>(
    p: &mut Parts,
    now_us: u64,
    request: &Request,
    link: Link,
    io: &mut I,
) -> Option<Answer> {
    use Request as R;
    let Parts {
        settings,
        bank,
        motion,
        gripper,
        waiting,
        ..
    } = p;
    Some(match *request {
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
        _ => return None,
    })
}
