//! Moves: angles, poses, lines, arcs, pause, stop, and the questions about them.

use protocol_core::command::{Reply, Request};

use crate::cartesian::for_client;
use crate::context::Context;
use crate::gains;
use crate::io::AtomIo;
use crate::link::Link;
use crate::motion::{Command, Target};
use crate::parts::Parts;
use crate::waiting::WaitingRead;

use super::answer::{Answer, byte, done, later};

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
        dispenser,
        waiting,
        ..
    } = p;
    Some(match *request {
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
        _ => return None,
    })
}
