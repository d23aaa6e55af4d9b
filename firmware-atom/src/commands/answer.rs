//! What the command families share: the [`Answer`] a request produces and its small makers.

use protocol_core::command::{Direction, Reply};

use crate::error::AtomError;
use crate::flash_writes::Queued;
use crate::motion::JogDirection;
use crate::store::ParamStore;

/// What a request produced.
pub(super) enum Answer {
    /// This reply.
    Now(Reply),
    /// The reply follows when a servo transaction finishes.
    Later,
    /// A set command: ack or refusal.
    Done(Result<(), AtomError>),
}

pub(super) fn byte(v: bool) -> Answer {
    Answer::Now(Reply::Byte(u8::from(v)))
}

pub(super) fn done_if(ok: bool) -> Answer {
    Answer::Done(if ok { Ok(()) } else { Err(AtomError::Invalid) })
}

pub(super) fn done() -> Answer {
    Answer::Done(Ok(()))
}

/// The flash seen through the records waiting for it, as the parts take a store.
pub(super) fn as_store<'a>(queued: &'a mut Queued<'_>) -> &'a mut dyn ParamStore {
    queued
}

/// A request whose reply waits for servo reads: later if they were queued, refused if not.
pub(super) fn later(queued: Result<(), AtomError>) -> Answer {
    match queued {
        Ok(()) => Answer::Later,
        Err(e) => Answer::Done(Err(e)),
    }
}

/// A count of drag-teaching points as the int16 the host reads (at most 1 000).
pub(super) fn count(n: u16) -> i16 {
    i16::try_from(n).unwrap_or(i16::MAX)
}

pub(super) fn dir(d: Direction) -> JogDirection {
    match d {
        Direction::Negative => JogDirection::Negative,
        Direction::Positive => JogDirection::Positive,
    }
}
