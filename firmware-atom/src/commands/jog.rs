//! Jogs: a joint or an axis until jog stop, and increments.

use protocol_core::command::{MoveMode, Request};
use protocol_core::units::Centideg;

use crate::context::Context;
use crate::error::AtomError;
use crate::io::AtomIo;
use crate::link::Link;
use crate::motion::{Command, Target};
use crate::parts::Parts;

use super::answer::{Answer, dir};

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
                return Some(Answer::Done(Err(AtomError::JointLimit(j))));
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
                return Some(Answer::Done(Err(AtomError::Unreachable)));
            };
            let to_pose = Command::ToPose {
                pose: base.with(protocol_core::command::AxisValue::new(axis, goal)),
                speed_percent: speed.get(),
                mode: MoveMode::Joint,
            };
            Answer::Done(motion.command(cx, to_pose))
        }
        _ => return None,
    })
}
