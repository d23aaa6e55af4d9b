//! Encoder goals and reads, the default speed, joint limits.

use protocol_core::command::{Reply, Request};
use protocol_core::units::Decideg;

use crate::config::{GRIPPER, in_encoder_range};
use crate::context::Context;
use crate::error::AtomError;
use crate::io::AtomIo;
use crate::link::Link;
use crate::motion::{Command, Target};
use crate::parts::Parts;
use crate::{gripper, registers};

use super::answer::{Answer, done};

/// Answers `request` if it is one of these; `None` if not.
pub(super) fn execute<I: AtomIo>(
    p: &mut Parts,
    now_us: u64,
    request: &Request,
    _link: Link,
    _io: &mut I,
) -> Option<Answer> {
    use Request as R;
    let Parts {
        settings,
        bank,
        motion,
        ..
    } = p;
    Some(match *request {
        R::SetEncoder {
            servo,
            encoder,
            speed,
        } => {
            let speed = speed.map_or(settings.speed_percent(), |s| s.get());
            let index = servo.index();
            let cx = &mut Context::new(now_us, bank, settings);
            if index == GRIPPER {
                return Some(Answer::Done(gripper::move_steps(cx, encoder, speed)));
            }
            if !in_encoder_range(encoder) {
                return Some(Answer::Done(Err(AtomError::JointLimit(index))));
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
                return Some(Answer::Done(Err(AtomError::JointLimit(j))));
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
        _ => return None,
    })
}
