//! Coordinate frames: tool, world, reference, movement type, end.

use protocol_core::command::{EndType, Reply, Request};

use crate::io::AtomIo;
use crate::link::Link;
use crate::parts::Parts;

use super::answer::{Answer, done};

/// Answers `request` if it is one of these; `None` if not.
pub(super) fn execute<I: AtomIo>(
    p: &mut Parts,
    _now_us: u64,
    request: &Request,
    _link: Link,
    _io: &mut I,
) -> Option<Answer> {
    use Request as R;
    let Parts { settings, .. } = p;
    Some(match *request {
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
        _ => return None,
    })
}
