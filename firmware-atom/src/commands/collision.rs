//! Collision protection: on or off, and each joint's threshold.

use protocol_core::command::{Reply, Request};

use crate::error::AtomError;
use crate::io::AtomIo;
use crate::link::Link;
use crate::parts::Parts;

use super::answer::{Answer, as_store, byte};

/// Answers `request` if it is one of these; `None` if not.
pub(super) fn execute<I: AtomIo>(
    p: &mut Parts,
    _now_us: u64,
    request: &Request,
    _link: Link,
    io: &mut I,
) -> Option<Answer> {
    use Request as R;
    let Parts {
        settings,
        flash_writes,
        ..
    } = p;
    Some(match *request {
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
                return Some(Answer::Done(Err(AtomError::Invalid)));
            }
            let kept = settings.collision_mut().replace_kept(
                changed,
                flash_writes.over(io.param_store()).as_mut().map(as_store),
            );
            Answer::Done(kept.map_err(|_| AtomError::Invalid))
        }
        R::GetCollisionThresholds => Answer::Now(Reply::Bytes6(settings.collision().thresholds())),
        _ => return None,
    })
}
