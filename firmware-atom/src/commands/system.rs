//! System status, power, errors and modes.

use protocol_core::command::{Reply, Request, ServoErrorCode};

use crate::config::SERVOS;
use crate::context::Context;
use crate::health::ServoHealth;
use crate::io::AtomIo;
use crate::link::Link;
use crate::parts::Parts;

use super::answer::{Answer, byte, done, done_if};

/// Reported by get system version (0x02): 7.0, the vendor's 280 M5 generation.
const SYSTEM_VERSION_X10: u8 = 70;
/// Reported by get modify version (0x01).
const MODIFY_VERSION: u8 = 0;

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
        errors,
        ..
    } = p;
    Some(match *request {
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
                return Some(done_if(bank.focus_released(settings)));
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
        _ => return None,
    })
}
