//! Host commands: every request gets exactly one reply carrying its CMD byte.
//!
//! This module only translates: a [`Request`] becomes calls on the Atom's parts and a
//! [`Reply`]. Replies come from cached state (present positions refreshed from the servos), so
//! they leave at once; the reply to a motion command means "accepted", not "arrived". A set
//! command answers `01` when accepted and `00` when refused (out-of-limit joint, unreachable
//! pose, powered off, queue full); a refusal changes nothing and records its error code for
//! 0x07. A frame that is not a valid command (unknown code, wrong length, field out of range)
//! answers `00` too, so the client never waits for a reply that will not come.
//!
//! The commands come in families, a module each, readable one at a time (what they share, the
//! [`answer`] a request produces, in its own): [`system`] (status,
//! power, errors, modes), [`motion`], [`jog`], [`encoders`] (with speed and limits),
//! [`servos`], [`collision`], [`atom_io`] (pins, LEDs, gripper), [`drag`] (teaching) and
//! [`frames`] (coordinate frames).

use protocol_core::Frame;
use protocol_core::command::{Reply, Request, cmd};

use crate::io::AtomIo;
use crate::link::Link;
use crate::parts::Parts;

use answer::Answer;

mod answer;
mod atom_io;
mod collision;
mod drag;
mod encoders;
mod frames;
mod jog;
mod motion;
mod servos;
mod system;

/// Handles one request; returns the reply (none only when the reply waits for the bus).
pub(crate) fn handle<I: AtomIo>(
    parts: &mut Parts,
    now_us: u64,
    frame: &Frame,
    link: Link,
    io: &mut I,
) -> Option<Frame> {
    let code = frame.cmd();
    // The Basic's own liveness probe (is powered on, every second while the wire is idle)
    // says nothing about the client, so it does not keep a jog alive.
    if code != cmd::IS_POWER_ON {
        parts.motion.note_host_command(now_us);
    }
    let Ok(request) = Request::parse(frame) else {
        return Some(Reply::Byte(0).to_frame(code));
    };
    let reply = match execute(parts, now_us, request, link, io) {
        Answer::Now(reply) => reply,
        Answer::Later => return None,
        Answer::Done(Ok(())) => Reply::Ack,
        Answer::Done(Err(e)) => {
            parts.errors.record(e);
            Reply::Byte(0)
        }
    };
    Some(reply.to_frame(code))
}

/// Hands `request` to its family's handler, one module each in `protocol.md` section 5's
/// order: each answers its own commands and nothing else. A new command goes into
/// its family's `match`.
fn execute<I: AtomIo>(
    p: &mut Parts,
    now_us: u64,
    request: Request,
    link: Link,
    io: &mut I,
) -> Answer {
    use Request as R;
    if matches!(request, R::ClearErrorInfo | R::PowerOn) {
        // Both end a collision's refusal of motion (docs/protocol.md section 7).
        p.clear_collision();
    }
    system::execute(p, now_us, &request, link, io)
        .or_else(|| motion::execute(p, now_us, &request, link, io))
        .or_else(|| jog::execute(p, now_us, &request, link, io))
        .or_else(|| encoders::execute(p, now_us, &request, link, io))
        .or_else(|| servos::execute(p, now_us, &request, link, io))
        .or_else(|| collision::execute(p, now_us, &request, link, io))
        .or_else(|| atom_io::execute(p, now_us, &request, link, io))
        .or_else(|| drag::execute(p, now_us, &request, link, io))
        .or_else(|| frames::execute(p, now_us, &request, link, io))
        // What no family takes is the Basic's own (0xA0, 0xA1, 0xB0..0xB2, 0xC0..0xC3, 0xC5),
        // reaching the Atom from a client on its own USB: refused.
        .unwrap_or(Answer::Now(Reply::Byte(0)))
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::bank::test_support::{at_rest, powered};
    use crate::config::AtomConfig;
    use crate::io::RecordingIo;
    use crate::settings::Settings;

    fn ask(parts: &mut Parts, code: u8, data: &[u8]) -> Option<std::vec::Vec<u8>> {
        let frame = Frame::new(code, data).unwrap();
        let reply = handle(parts, 0, &frame, Link::Usb, &mut RecordingIo::default())?;
        assert_eq!(reply.cmd(), code, "a reply carries its request's CMD byte");
        Some(reply.data().to_vec())
    }

    /// Send angle (0x21): joint 1 to `degrees` at 50 %.
    fn send_angle_1(parts: &mut Parts, degrees: i16) -> Option<std::vec::Vec<u8>> {
        let mut data = std::vec![1];
        data.extend_from_slice(&(degrees * 100).to_be_bytes());
        data.push(50);
        ask(parts, cmd::SEND_ANGLE, &data)
    }

    /// The parts of a powered arm whose servos were all read at time 0, at rest at 0 deg.
    fn read_arm() -> Parts {
        let (settings, bank) = at_rest();
        let mut parts = Parts::new(settings);
        parts.bank = bank;
        parts
    }

    #[test]
    fn a_refused_motion_answers_00_and_records_its_code_for_0x07() {
        let mut parts = read_arm();
        assert_eq!(
            send_angle_1(&mut parts, 170),
            Some(std::vec![0]),
            "J1 ends at 168 deg"
        );
        assert_eq!(
            ask(&mut parts, cmd::GET_ERROR_INFO, &[]),
            Some(std::vec![1])
        );
        assert!(!parts.motion.is_active(), "nothing moves");
    }

    #[test]
    fn a_motion_while_powered_off_is_refused_without_an_error_code() {
        let mut parts = Parts::new(Settings::new(AtomConfig::default()));
        assert_eq!(send_angle_1(&mut parts, 10), Some(std::vec![0]));
        assert_eq!(
            ask(&mut parts, cmd::GET_ERROR_INFO, &[]),
            Some(std::vec![0])
        );
    }

    #[test]
    fn an_accepted_motion_becomes_goals_for_the_servos() {
        let mut parts = read_arm();
        assert_eq!(send_angle_1(&mut parts, 10), Some(std::vec![1]));
        assert!(parts.motion.is_active());
        assert!(parts.bank.take_goal_write(0, &parts.settings).is_some());
    }

    #[test]
    fn a_frame_setting_reads_back_as_set() {
        let mut parts = Parts::new(powered());
        let tool: std::vec::Vec<u8> = [100i16, 0, 500, 0, 0, 9_000]
            .iter()
            .flat_map(|v| v.to_be_bytes())
            .collect();
        assert_eq!(
            ask(&mut parts, cmd::SET_TOOL_REFERENCE, &tool),
            Some(std::vec![1])
        );
        assert_eq!(ask(&mut parts, cmd::GET_TOOL_REFERENCE, &[]), Some(tool));
        assert_eq!(ask(&mut parts, cmd::SET_END_TYPE, &[1]), Some(std::vec![1]));
        assert_eq!(ask(&mut parts, cmd::GET_END_TYPE, &[]), Some(std::vec![1]));
    }

    #[test]
    fn a_servo_data_read_answers_later_through_the_bank() {
        let mut parts = Parts::new(powered());
        assert_eq!(ask(&mut parts, cmd::GET_SERVO_DATA, &[2, 56]), None);
        assert_eq!(
            parts.bank.due_job(),
            Some(crate::driver::Op::Read {
                id: 2,
                addr: 56,
                count: 1
            })
        );
    }

    #[test]
    fn a_frame_that_is_no_valid_command_answers_00() {
        let mut parts = Parts::new(powered());
        assert_eq!(ask(&mut parts, 0xEE, &[]), Some(std::vec![0]));
        assert_eq!(ask(&mut parts, cmd::SEND_ANGLE, &[1]), Some(std::vec![0]));
    }
}
