//! The two dialects of the host protocol, and the one place they differ.
//!
//! The same frames (`FE FE LEN CMD DATA FA`) have been spoken two ways (`docs/protocol.md`,
//! "Dialects"):
//!
//! * [`Dialect::Pymycobot`], the default: pymycobot's protocol, the one every other module
//!   of this crate implements and the Atom speaks. Every command is answered.
//! * [`Dialect::Seed`]: the protocol of the vendor's manual ("Basic development guide",
//!   section 3). A command with no return value is not answered; joints, servos and axes
//!   are numbered from 0 where the manual numbers them from 0; 0x26/0x27/0x28 are pause,
//!   continue, stop; 0x55 sets a servo's zero and 0x56 brakes it; 0x50 checks the connection;
//!   0x4A/0x4B and 0x62 answer the value alone; the manual's miscounted LENs are read
//!   ([`FrameLengths`](crate::frame::FrameLengths), with the `seed-dialect` feature).
//!
//! A dialect is a codec in front of the pymycobot one: [`Dialect::translate`] turns a
//! request as the client sent it into the pymycobot request that means the same, with the
//! [`Answer`] that turns the pymycobot reply into what the client expects (or into nothing).
//! [`Dialect::encode`] goes the other way, for a client: the frame of its dialect that
//! translates into a given request.
//! Whatever is not protocol (limits, safety, motion, several clients) is the same in both.
//! Commands the manual does not list keep their pymycobot layout and numbering in the seed
//! dialect, and are answered only if they return a value.

pub use crate::command::Dialect;
use crate::command::{Reply, ReplyKind, Request};
use crate::frame::Frame;
#[cfg(feature = "seed-dialect")]
use crate::frame::FrameLengths;

/// What becomes of the pymycobot reply to a translated request.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub enum Answer {
    /// Sent to the client as it is.
    AsIs,
    /// Not sent: the command has no return value in the client's dialect.
    Silent,
    /// Seed 0x50, check connection, asked as pymycobot's 0x14: the reply under 0x50, and
    /// `00` (not connected) when the Atom does not answer ([`Answer::unanswered`]).
    Connection,
    /// Sent without its first data byte, the number of what was asked (seed 0x4A/0x4B: the
    /// limit without the joint; 0x62: the level without the pin). A refusal (one byte) is sent
    /// as it is.
    ValueOnly,
}

/// A request translated into pymycobot's dialect, and what to do with its reply.
#[derive(Clone, Debug, PartialEq, Eq, Hash)]
pub struct Translated {
    /// The request as the Atom (and the rest of this crate) reads it.
    pub frame: Frame,
    /// What the client gets back.
    pub answer: Answer,
}

impl Dialect {
    /// How a decoder reads LEN for a client of this dialect.
    #[cfg(feature = "seed-dialect")]
    pub const fn frame_lengths(self) -> FrameLengths {
        match self {
            Self::Pymycobot => FrameLengths::Counted,
            Self::Seed => FrameLengths::SeedManual,
        }
    }

    /// `request` as this dialect's client meant it, in pymycobot's dialect, and what to do
    /// with the reply. Never fails: a request that means nothing stays one the parser
    /// refuses.
    pub fn translate(self, request: &Frame) -> Translated {
        match self {
            Self::Pymycobot => Translated {
                frame: request.clone(),
                answer: Answer::AsIs,
            },
            Self::Seed => seed::translate(request),
        }
    }

    /// The frame a client of this dialect sends to mean `request`: the inverse of
    /// [`Dialect::translate`], so `translate(&encode(r)?).frame` parses as `r`. In
    /// [`Dialect::Pymycobot`] always [`Request::to_frame`]; in [`Dialect::Seed`] the frame the
    /// manual prints (joints, servos and axes numbered from 0 where it numbers them so, 0x27
    /// continue, 0x28 stop, 0x55 zero, 0x56 brake, 0x2A a pose), or `None` for the three
    /// requests the seed dialect has no frame for: is paused (its 0x27 continues), release
    /// servo (its 0x56 brakes) and is in position with angles (its 0x2A compares a pose).
    pub fn encode(self, request: &Request) -> Option<Frame> {
        match self {
            Self::Pymycobot => Some(request.to_frame()),
            Self::Seed => seed::encode(request),
        }
    }
}

impl Answer {
    /// What the client gets when the Atom does not answer its request in time: nothing, but
    /// for the seed dialect's check connection, whose answer is then "not connected".
    pub fn unanswered(self) -> Option<Frame> {
        match self {
            Self::Connection => Some(Reply::Byte(0).to_frame(seed::CHECK_CONNECTION)),
            Self::AsIs | Self::Silent | Self::ValueOnly => None,
        }
    }

    /// What the client gets for `reply`, the pymycobot reply to its translated request.
    pub fn reply(self, reply: &Frame) -> Option<Frame> {
        match self {
            Self::AsIs => Some(reply.clone()),
            Self::Silent => None,
            Self::Connection => Frame::new(seed::CHECK_CONNECTION, reply.data()),
            Self::ValueOnly => match reply.data() {
                [_, value @ ..] if !value.is_empty() => Frame::new(reply.cmd(), value),
                _ => Some(reply.clone()),
            },
        }
    }
}

/// True if the pymycobot `request` returns a value: it parses and its reply is more than the
/// status of a set command. A request that does not parse is refused, which is no value.
fn returns_value(request: &Frame) -> bool {
    Request::parse(request).is_ok_and(|r| r.reply_kind() != ReplyKind::Ack)
}

/// The refusal a [`Dialect::Pymycobot`] client gets; a seed client gets nothing.
pub fn refusal(dialect: Dialect, cmd: u8) -> Option<Frame> {
    match dialect {
        Dialect::Pymycobot => Some(Reply::Byte(0).to_frame(cmd)),
        Dialect::Seed => None,
    }
}

/// The seed manual's protocol, as translations into pymycobot's.
mod seed {
    use heapless::Vec;

    use super::{Answer, Translated, returns_value};
    use crate::command::{PositionTarget, Request, cmd};
    use crate::frame::{Frame, MAX_DATA};

    /// The manual's "check connection" (pymycobot's is-servo-enabled code, without data).
    pub(super) const CHECK_CONNECTION: u8 = cmd::IS_SERVO_ENABLED;

    /// A number no command accepts: where a seed number has no pymycobot equivalent.
    const NONE: u8 = 0xFF;

    /// Seed joint `n` (0..=5) as pymycobot numbers it (1..=6).
    fn joint(n: u8) -> u8 {
        if n <= 5 { n + 1 } else { NONE }
    }

    /// Seed servo `n` (0..=5 the joints, 6 the gripper) as pymycobot numbers it (1..=7).
    fn servo(n: u8) -> u8 {
        if n <= 6 { n + 1 } else { NONE }
    }

    /// Seed axis `n` (0..=5: x, y, z, rx, ry, rz) as pymycobot numbers it (1..=6).
    fn axis(n: u8) -> u8 {
        joint(n)
    }

    /// `data` with its first byte renumbered by `renumber`.
    fn first(data: &[u8], renumber: fn(u8) -> u8) -> Vec<u8, MAX_DATA> {
        let mut out = Vec::new();
        for (i, &b) in data.iter().enumerate() {
            let _ = out.push(if i == 0 { renumber(b) } else { b });
        }
        out
    }

    /// Seed number `n` (numbered from 0) of pymycobot's `n` (numbered from 1).
    fn from_0(n: u8) -> u8 {
        n.checked_sub(1).unwrap_or(NONE)
    }

    pub(super) fn encode(request: &Request) -> Option<Frame> {
        let frame = request.to_frame();
        let data = frame.data();
        match request {
            Request::SendAngle { .. }
            | Request::GetJointMin { .. }
            | Request::GetJointMax { .. }
            | Request::SetJointMin { .. }
            | Request::SetJointMax { .. }
            | Request::SendCoord { .. }
            | Request::SetEncoder { .. }
            | Request::GetEncoder { .. }
            | Request::SetServoData { .. }
            | Request::GetServoData { .. } => Frame::new(frame.cmd(), &first(data, from_0)),
            Request::SetServoCalibration { .. } => Frame::new(0x55, &first(data, from_0)),
            Request::JointBrake { .. } => Frame::new(0x56, &first(data, from_0)),
            Request::Resume => Frame::new(0x27, &[]),
            Request::Stop => Frame::new(0x28, &[]),
            Request::IsPaused
            | Request::ReleaseServo { .. }
            | Request::IsInPosition {
                target: PositionTarget::Angles(_),
            } => None,
            _ => Some(frame),
        }
    }

    pub(super) fn translate(request: &Frame) -> Translated {
        let data = request.data();
        let code = request.cmd();
        let (new_code, new_data): (u8, Vec<u8, MAX_DATA>) = match code {
            // Numbered from 0 in the manual: joints...
            cmd::SEND_ANGLE
            | cmd::GET_JOINT_MIN
            | cmd::GET_JOINT_MAX
            | cmd::SET_JOINT_MIN
            | cmd::SET_JOINT_MAX => (code, first(data, joint)),
            // ...axes...
            cmd::SEND_COORD => (code, first(data, axis)),
            // ...and servos.
            cmd::SET_ENCODER | cmd::GET_ENCODER | cmd::SET_SERVO_DATA | cmd::GET_SERVO_DATA => {
                (code, first(data, servo))
            }
            // 0x55 sets a servo's zero, 0x56 brakes it.
            0x55 => (cmd::SET_SERVO_CALIBRATION, first(data, servo)),
            0x56 => (cmd::JOINT_BRAKE, first(data, servo)),
            // 0x26 pause, 0x27 continue, 0x28 stop.
            0x27 if data.is_empty() => (cmd::RESUME, Vec::new()),
            0x28 if data.is_empty() => (cmd::STOP, Vec::new()),
            // Is in position compares a pose; the manual's last byte is unused, or absent.
            cmd::IS_IN_POSITION if data.len() == 12 || data.len() == 13 => {
                let mut pose: Vec<u8, MAX_DATA> =
                    Vec::from_slice(data.get(..12).unwrap_or_default()).unwrap_or_default();
                let _ = pose.push(1);
                (code, pose)
            }
            // Check connection: is the Atom there (pymycobot's "is controller connected").
            cmd::IS_SERVO_ENABLED if data.is_empty() => {
                let frame = Frame::new(cmd::IS_CONTROLLER_CONNECTED, &[]).unwrap_or_default();
                return Translated {
                    frame,
                    answer: Answer::Connection,
                };
            }
            _ => (code, Vec::from_slice(data).unwrap_or_default()),
        };
        let frame = Frame::new(new_code, &new_data).unwrap_or_default();
        let answer = if !returns_value(&frame) {
            Answer::Silent
        } else if matches!(
            new_code,
            cmd::GET_JOINT_MIN | cmd::GET_JOINT_MAX | cmd::GET_DIGITAL_INPUT
        ) {
            Answer::ValueOnly
        } else {
            Answer::AsIs
        };
        Translated { frame, answer }
    }
}

#[cfg(test)]
mod tests {
    #![allow(clippy::unwrap_used, clippy::indexing_slicing)]

    use super::*;
    use crate::FrameDecoder;
    use crate::command::{AxisValue, JointId, ServoId};
    use crate::units::Centideg;

    fn frame(cmd: u8, data: &[u8]) -> Frame {
        Frame::new(cmd, data).unwrap()
    }

    fn seed(cmd: u8, data: &[u8]) -> (Request, Answer) {
        let t = Dialect::Seed.translate(&frame(cmd, data));
        (Request::parse(&t.frame).unwrap(), t.answer)
    }

    #[test]
    fn pymycobot_is_the_identity() {
        for code in crate::command::cmd::ALL {
            let f = frame(code, &[1, 2, 3]);
            let t = Dialect::Pymycobot.translate(&f);
            assert_eq!((t.frame, t.answer), (f, Answer::AsIs));
        }
    }

    #[test]
    fn seed_numbers_joints_axes_and_servos_from_0() {
        let (r, a) = seed(0x21, &[0, 0, 0, 0x20]);
        assert!(
            matches!(r, Request::SendAngle { joint, angle: Centideg(0), .. } if joint == JointId::new(1).unwrap())
        );
        assert_eq!(a, Answer::Silent);
        let (r, _) = seed(0x24, &[5, 0, 100, 20]);
        assert!(
            matches!(
                r,
                Request::SendCoord {
                    target: AxisValue::Rz(_),
                    ..
                }
            ),
            "{r:?}"
        );
        let (r, _) = seed(0x3A, &[1, 0x08, 0xC9]);
        assert!(
            matches!(r, Request::SetEncoder { servo, .. } if servo == ServoId::new(2).unwrap())
        );
        let (r, a) = seed(0x3B, &[0]);
        assert!(matches!(r, Request::GetEncoder { servo } if servo == ServoId::new(1).unwrap()));
        assert_eq!(a, Answer::AsIs);
    }

    #[test]
    fn seed_numbers_past_the_last_joint_mean_nothing() {
        for (code, data) in [(0x21, [6, 0, 0, 10]), (0x24, [6, 0, 0, 10])] {
            let t = Dialect::Seed.translate(&frame(code, &data));
            assert!(Request::parse(&t.frame).is_err(), "{code:#x}");
            assert_eq!(t.answer, Answer::Silent);
        }
    }

    /// Every request the recorded pymycobot frames and a sweep of layouts give: its seed frame
    /// translates back into it, or it is one of the three the seed dialect cannot say.
    #[test]
    fn seed_encode_is_the_inverse_of_translate() {
        let recorded = include_str!("../tests/data/pymycobot_requests.txt")
            .lines()
            .filter(|l| !l.starts_with('#'))
            .filter_map(|l| l.split('|').next())
            .map(|hex| {
                hex.split_whitespace()
                    .map(|b| u8::from_str_radix(b, 16).unwrap())
                    .collect::<std::vec::Vec<u8>>()
            })
            .filter(|b| b.len() >= 5)
            .map(|b| frame(b[3], &b[4..b.len() - 1]));
        let swept = crate::command::cmd::ALL.into_iter().flat_map(|code| {
            (0..=36usize).flat_map(move |len| {
                [0u8, 1, 2, 5, 6, 7, 19, 100, 254]
                    .into_iter()
                    .map(move |fill| frame(code, &std::vec![fill; len]))
            })
        });
        let mut checked = 0;
        for f in recorded.chain(swept) {
            let Ok(request) = Request::parse(&f) else {
                continue;
            };
            assert_eq!(Dialect::Pymycobot.encode(&request), Some(f.clone()));
            match Dialect::Seed.encode(&request) {
                Some(seed) => {
                    let back = Dialect::Seed.translate(&seed).frame;
                    assert_eq!(Request::parse(&back), Ok(request.clone()), "{seed:?}");
                }
                None => assert!(
                    matches!(
                        request,
                        Request::IsPaused
                            | Request::ReleaseServo { .. }
                            | Request::IsInPosition {
                                target: crate::command::PositionTarget::Angles(_)
                            }
                    ),
                    "{request:?}"
                ),
            }
            checked += 1;
        }
        assert!(checked > 300, "{checked}");
    }

    #[test]
    fn seed_encode_prints_the_manuals_frames() {
        let enc = |r: Request| Dialect::Seed.encode(&r).unwrap();
        let j1 = JointId::new(1).unwrap();
        assert_eq!(enc(Request::GetJointMin { joint: j1 }), frame(0x4A, &[0]));
        assert_eq!(enc(Request::Resume), frame(0x27, &[]));
        assert_eq!(enc(Request::Stop), frame(0x28, &[]));
        let s2 = ServoId::new(2).unwrap();
        assert_eq!(
            enc(Request::SetServoCalibration { servo: s2 }),
            frame(0x55, &[1])
        );
        assert_eq!(enc(Request::JointBrake { servo: s2 }), frame(0x56, &[1]));
        assert_eq!(Dialect::Seed.encode(&Request::IsPaused), None);
    }

    #[test]
    fn seed_pause_continue_stop() {
        assert_eq!(seed(0x26, &[]), (Request::Pause, Answer::Silent));
        assert_eq!(seed(0x27, &[]), (Request::Resume, Answer::Silent));
        assert_eq!(seed(0x28, &[]), (Request::Stop, Answer::Silent));
        // pymycobot's stop, which the manual does not list, still stops.
        assert_eq!(seed(0x29, &[]), (Request::Stop, Answer::Silent));
    }

    #[test]
    fn seed_zero_and_brake() {
        let (r, _) = seed(0x55, &[0]);
        assert!(matches!(r, Request::SetServoCalibration { servo } if servo.get() == 1));
        let (r, _) = seed(0x56, &[2]);
        assert!(matches!(r, Request::JointBrake { servo } if servo.get() == 3));
    }

    #[test]
    fn seed_check_connection_and_joint_limits_answer_as_the_manual_prints() {
        let t = Dialect::Seed.translate(&frame(0x50, &[]));
        assert_eq!(t.frame, frame(0x14, &[]));
        assert_eq!(t.answer.reply(&frame(0x14, &[1])), Some(frame(0x50, &[1])));
        assert_eq!(
            t.answer.unanswered(),
            Some(frame(0x50, &[0])),
            "a silent Atom"
        );
        assert_eq!(Answer::Silent.unanswered(), None);
        let (_, a) = seed(0x4A, &[0]);
        assert_eq!(
            a.reply(&frame(0x4A, &[1, 0x01, 0x44])),
            Some(frame(0x4A, &[0x01, 0x44]))
        );
        // A refusal is not cut.
        assert_eq!(a.reply(&frame(0x4A, &[0])), Some(frame(0x4A, &[0])));
        // MyCobotBasic's getDigitalInput reads the level alone, as that generation answered.
        let (_, a) = seed(0x62, &[19]);
        assert_eq!(a.reply(&frame(0x62, &[19, 1])), Some(frame(0x62, &[1])));
    }

    #[test]
    fn seed_is_in_position_compares_a_pose() {
        let pose = [
            0xFF, 0x74, 0xFE, 0xEE, 0x0A, 0xC1, 0xDD, 0x05, 0x00, 0x48, 0xDC, 0x95,
        ];
        let (r, a) = seed(0x2A, &pose);
        assert!(matches!(r, Request::IsInPosition { .. }));
        assert_eq!(a, Answer::AsIs);
        let mut with_type = pose.to_vec();
        with_type.push(0);
        assert_eq!(seed(0x2A, &with_type).0, r);
    }

    #[test]
    fn seed_answers_only_what_returns_a_value() {
        assert_eq!(seed(0x10, &[]).1, Answer::Silent);
        assert_eq!(seed(0x12, &[]).1, Answer::AsIs);
        assert_eq!(seed(0x20, &[]).1, Answer::AsIs);
        assert_eq!(seed(0x6A, &[0, 0, 0xFF]).1, Answer::Silent);
        // A command pymycobot knows and the manual does not: its own layout.
        assert_eq!(seed(0x07, &[]).1, Answer::AsIs);
        // Garbage is refused, silently.
        let t = Dialect::Seed.translate(&frame(0x9F, &[1]));
        assert_eq!(t.answer, Answer::Silent);
        // The dialect command returns the dialect in force.
        assert_eq!(seed(0xC5, &[1]).1, Answer::AsIs);
        assert_eq!(refusal(Dialect::Seed, 0x21), None);
        assert_eq!(refusal(Dialect::Pymycobot, 0x21), Some(frame(0x21, &[0])));
    }

    /// The manual's examples with miscounted LENs, as printed.
    #[cfg(feature = "seed-dialect")]
    #[test]
    fn seed_lengths_read_the_manuals_miscounted_examples() {
        let examples: [&[u8]; 6] = [
            &[
                0xFE, 0xFE, 0x15, 0x2A, 0xFF, 0x74, 0xFE, 0xEE, 0x0A, 0xC1, 0xDD, 0x05, 0x00, 0x48,
                0xDC, 0x95, 0xFA,
            ],
            &[
                0xFE, 0xFE, 0x15, 0x3C, 0, 0, 0, 0, 0, 0, 0, 0, 0, 0, 0, 0, 0x20, 0xFA,
            ],
            &[
                0xFE, 0xFE, 0x14, 0x81, 0xFF, 0x74, 0xFE, 0xEE, 0x0A, 0xC1, 0xDD, 0x05, 0x00, 0x48,
                0xDC, 0x95, 0xFA,
            ],
            &[
                0xFE, 0xFE, 0x14, 0x83, 0xFF, 0x74, 0xFE, 0xEE, 0x0A, 0xC1, 0xDD, 0x05, 0x00, 0x48,
                0xDC, 0x95, 0xFA,
            ],
            &[0xFE, 0xFE, 0x02, 0x41, 0x32, 0xFA],
            &[0xFE, 0xFE, 0x03, 0x50, 0xFA],
        ];
        for bytes in examples {
            let mut counted = FrameDecoder::new();
            let mut seed = FrameDecoder::new();
            seed.set_lengths(Dialect::Seed.frame_lengths());
            let next = frame(0x20, &[]).to_bytes();
            let mut heard = (std::vec::Vec::new(), std::vec::Vec::new());
            counted.feed(bytes, |f| heard.0.push(f));
            counted.feed(&next, |f| heard.0.push(f));
            seed.feed(bytes, |f| heard.1.push(f));
            seed.feed(&next, |f| heard.1.push(f));
            assert_eq!(heard.1.len(), 2, "{bytes:02x?}");
            assert_eq!(heard.1[0].cmd(), bytes[3]);
            assert_eq!(heard.1[0].encoded_len(), bytes.len());
            assert!(
                heard.0.len() < 2,
                "a counting decoder cannot read {bytes:02x?}"
            );
        }
    }

    #[cfg(feature = "seed-dialect")]
    #[test]
    fn seed_lengths_still_read_the_counted_layouts() {
        let mut d = FrameDecoder::new();
        d.set_lengths(FrameLengths::SeedManual);
        let frames = [
            frame(0x50, &[3]),
            frame(0x41, &[]),
            frame(0x2A, &[0; 13]),
            frame(0x3C, &[0; 13]),
            frame(0x22, &[0xFA; 13]),
        ];
        let mut heard = std::vec::Vec::new();
        for f in &frames {
            d.feed(&f.to_bytes(), |f| heard.push(f));
        }
        assert_eq!(heard, frames);
    }
}
