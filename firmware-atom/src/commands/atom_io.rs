//! The Atom's pins, its LEDs and the gripper.

use protocol_core::command::{PinMode as WirePinMode, Reply, Request};

use crate::config::GRIPPER;
use crate::context::Context;
use crate::error::AtomError;
use crate::io::{AtomIo, PinMode, is_output_pin, mode_allowed};
use crate::link::Link;
use crate::parts::Parts;
use crate::registers;

use super::answer::{Answer, byte, done, done_if};

/// Answers `request` if it is one of these; `None` if not.
pub(super) fn execute<I: AtomIo>(
    p: &mut Parts,
    now_us: u64,
    request: &Request,
    _link: Link,
    io: &mut I,
) -> Option<Answer> {
    use Request as R;
    let Parts {
        settings,
        bank,
        motion,
        gripper,
        ..
    } = p;
    Some(match *request {
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
        _ => return None,
    })
}
