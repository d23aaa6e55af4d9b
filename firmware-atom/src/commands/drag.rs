//! Drag teaching: recording the arm moved by hand, and reading it back.

use protocol_core::command::{Reply, Request};

use crate::io::AtomIo;
use crate::link::Link;
use crate::parts::Parts;

use super::answer::{Answer, count};

/// Answers `request` if it is one of these; `None` if not.
pub(super) fn execute<I: AtomIo>(
    p: &mut Parts,
    now_us: u64,
    request: &Request,
    _link: Link,
    _io: &mut I,
) -> Option<Answer> {
    use Request as R;
    let Parts { drag, .. } = p;
    Some(match *request {
        R::DragStartRecord => Answer::Now(Reply::Int16(count(drag.start(now_us)))),
        R::DragEndRecord => Answer::Now(Reply::Int16(count(drag.end()))),
        R::DragGetRecordData => Answer::Now(Reply::DragPoint(drag.next_point())),
        R::DragGetRecordLen => Answer::Now(Reply::Int16(count(drag.recorded()))),
        R::DragClearRecordData => Answer::Now(Reply::Int16(count(drag.clear()))),
        _ => return None,
    })
}
