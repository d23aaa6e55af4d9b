//! Every call against a scripted port: its request byte for byte in both dialects
//! (`docs/protocol.md` sections 5 and 21), its value from a canned reply, and what each call
//! does with no reply, a refusal, garbage, a reply for another command, a stale reply and a
//! malformed one.
#![allow(clippy::unwrap_used, clippy::expect_used, clippy::indexing_slicing)]

use std::cell::Cell;
use std::collections::VecDeque;
use std::rc::Rc;
use std::string::{String, ToString};
use std::vec::Vec;

use protocol_core::command::{
    AtomPin, Axis, AxisValue, Direction, EndType, ErrorCode, GripperSpeed, GripperState,
    GripperValue, JointId, MoveMode, PinMode, Pose, PositionTarget, ReferenceFrame, Rgb, ServoId,
    ServoValue,
};
use protocol_core::dialect::Dialect;
use protocol_core::port::BytePort;
use protocol_core::units::{Centideg, Decideg, SpeedPercent, Steps};

use crate::convert::{angles, deg, limit_deg, mm, pose};
use crate::{Error, MyCobot};

/// Microseconds the fake clock moves on every reading.
const TICK_US: u64 = 50;

/// A port that records what is written and, for each write, receives the next scripted
/// answer (bytes, possibly none).
#[derive(Default)]
struct Port {
    written: Vec<Vec<u8>>,
    answers: VecDeque<Vec<u8>>,
    rx: VecDeque<u8>,
}

impl BytePort for Port {
    fn read_byte(&mut self) -> Option<u8> {
        self.rx.pop_front()
    }

    fn write(&mut self, bytes: &[u8]) {
        self.written.push(bytes.to_vec());
        if let Some(answer) = self.answers.pop_front() {
            self.rx.extend(answer);
        }
    }

    fn tx_idle(&self) -> bool {
        true
    }
}

/// A clock that advances [`TICK_US`] every time it is read.
struct Clock(Rc<Cell<u64>>);

impl crate::Clock for Clock {
    fn now_us(&mut self) -> u64 {
        self.0.set(self.0.get() + TICK_US);
        self.0.get()
    }
}

type Bot = MyCobot<Port, Clock>;

/// An arm in `dialect` that answers its writes with `answers`, and its clock.
fn bot(dialect: Dialect, answers: Vec<Vec<u8>>) -> (Bot, Rc<Cell<u64>>) {
    let now = Rc::new(Cell::new(0));
    let port = Port {
        answers: answers.into(),
        ..Port::default()
    };
    (MyCobot::new(port, Clock(now.clone()), dialect), now)
}

fn hex(s: &str) -> Vec<u8> {
    s.split_whitespace()
        .map(|b| u8::from_str_radix(b, 16).unwrap())
        .collect()
}

/// The wire bytes of frame `cmd` `data`.
fn frame(cmd: u8, data: &[u8]) -> Vec<u8> {
    let mut out = std::vec![0xFE, 0xFE, data.len() as u8 + 2, cmd];
    out.extend_from_slice(data);
    out.push(0xFA);
    out
}

/// A call, its value printed with `{:?}`.
type Call = fn(&mut Bot) -> Result<String, Error>;

fn shown<T: core::fmt::Debug>(r: Result<T, Error>) -> Result<String, Error> {
    r.map(|v| std::format!("{v:?}"))
}

/// One call of the API.
#[derive(Clone, Copy)]
struct Case {
    call: Call,
    /// The request in the pymycobot dialect, hex.
    py: &'static str,
    /// The reply data the pymycobot dialect gets (`01` for a command without a value).
    py_reply: &'static str,
    /// The request in the seed dialect; `None`: the call has no seed frame.
    seed: Option<&'static str>,
    /// The reply data in the seed dialect; `None`: nothing comes back.
    seed_reply: Option<&'static str>,
    /// The call's value, `{:?}`.
    value: &'static str,
}

impl Case {
    fn cmd(&self) -> u8 {
        hex(self.py)[3]
    }

    /// True if the call's reply is more than one byte, or the status of a set command: a
    /// `00` then is a refusal, not a value.
    fn refusable(&self) -> bool {
        self.value == "Ok(\"()\")" || hex(self.py_reply).len() > 1
    }

    /// What the call sends and gets in `dialect`: request, reply data (`None`: silent).
    fn in_dialect(&self, dialect: Dialect) -> Option<(Vec<u8>, Option<Vec<u8>>)> {
        match dialect {
            Dialect::Pymycobot => Some((hex(self.py), Some(hex(self.py_reply)))),
            Dialect::Seed => Some((hex(self.seed?), self.seed_reply.map(hex))),
        }
    }
}

fn j(n: u8) -> JointId {
    JointId::new(n).unwrap()
}

fn s(n: u8) -> ServoId {
    ServoId::new(n).unwrap()
}

fn speed(n: u8) -> SpeedPercent {
    SpeedPercent::new(n).unwrap()
}

/// The pose of the examples: (150, -20.5, 200) mm, (-180, 0.5, 90) deg.
fn a_pose() -> Pose {
    pose([150.0, -20.5, 200.0, -180.0, 0.5, 90.0])
}

/// [`a_pose`] on the wire.
const POSE: &str = "05 DC FF 33 07 D0 B9 B0 00 32 23 28";
/// (10, 20, -30, 15, -25, 40) deg on the wire.
const ANGLES: &str = "03 E8 07 D0 F4 48 05 DC F6 3C 0F A0";
const POSE_DEBUG: &str = "Pose { x: DeciMm(1500), y: DeciMm(-205), z: DeciMm(2000), \
    rx: Centideg(-18000), ry: Centideg(50), rz: Centideg(9000) }";

fn cases() -> Vec<Case> {
    // The long frames, put together once.
    let leak = |s: String| -> &'static str { Box::leak(s.into_boxed_str()) };
    let angles_reply = ANGLES;
    let write_angles = leak(std::format!("FE FE 0F 22 {ANGLES} 64 FA"));
    let in_position = leak(std::format!("FE FE 0F 2A {POSE} 01 FA"));
    let in_position_angles = leak(std::format!("FE FE 0F 2A {ANGLES} 00 FA"));
    let write_coords = leak(std::format!("FE FE 10 25 {POSE} 32 01 FA"));
    let set_tool = leak(std::format!("FE FE 0E 81 {POSE} FA"));
    let set_world = leak(std::format!("FE FE 0E 83 {POSE} FA"));
    let encoders = "FE FE 0F 3C 08 00 08 00 08 00 08 00 08 00 08 00 14 FA";
    let pose_debug = leak(std::format!("Ok({POSE_DEBUG:?})"));
    let set = |call: Call, py: &'static str, seed: &'static str| Case {
        call,
        py,
        py_reply: "01",
        seed: Some(seed),
        seed_reply: None,
        value: "Ok(\"()\")",
    };
    let same = |call: Call, py: &'static str| set(call, py, py);
    let get = |call: Call,
               py: &'static str,
               py_reply: &'static str,
               seed: &'static str,
               seed_reply: &'static str,
               value: &'static str| Case {
        call,
        py,
        py_reply,
        seed: Some(seed),
        seed_reply: Some(seed_reply),
        value,
    };
    // A query the same in both dialects.
    let ask = |call: Call, request: &'static str, reply: &'static str, value: &'static str| {
        get(call, request, reply, request, reply, value)
    };
    std::vec![
        // 2.2
        same(|a| shown(a.power_on()), "FE FE 02 10 FA"),
        same(|a| shown(a.power_off()), "FE FE 02 11 FA"),
        ask(
            |a| shown(a.is_powered_on()),
            "FE FE 02 12 FA",
            "01",
            "Ok(\"true\")"
        ),
        same(|a| shown(a.set_free_move()), "FE FE 02 13 FA"),
        // 2.3
        ask(
            |a| shown(a.get_angles().map(|v| v.map(crate::convert::to_deg))),
            "FE FE 02 20 FA",
            angles_reply,
            "Ok(\"[10.0, 20.0, -30.0, 15.0, -25.0, 40.0]\")"
        ),
        // pymycobot's send_angle(2, -0.02, 50), as recorded.
        set(
            |a| shown(a.write_angle(j(2), Centideg(-2), speed(50))),
            "FE FE 06 21 02 FF FE 32 FA",
            "FE FE 06 21 01 FF FE 32 FA"
        ),
        same(
            |a| {
                let v = angles([10.0, 20.0, -30.0, 15.0, -25.0, 40.0]);
                shown(a.write_angles(v, SpeedPercent::MAX))
            },
            write_angles
        ),
        ask(
            |a| shown(a.get_coords()),
            "FE FE 02 23 FA",
            POSE,
            pose_debug
        ),
        ask(
            |a| shown(a.is_in_position(PositionTarget::Coords(a_pose()))),
            in_position,
            "00",
            "Ok(\"false\")"
        ),
        Case {
            call: |a| {
                let v = angles([10.0, 20.0, -30.0, 15.0, -25.0, 40.0]);
                shown(a.is_in_position(PositionTarget::Angles(v)))
            },
            py: in_position_angles,
            py_reply: "01",
            seed: None,
            seed_reply: None,
            value: "Ok(\"true\")",
        },
        set(
            |a| shown(a.write_coord(AxisValue::Z(mm(180.0)), SpeedPercent::MAX)),
            "FE FE 06 24 03 07 08 64 FA",
            "FE FE 06 24 02 07 08 64 FA"
        ),
        same(
            |a| shown(a.write_coords(a_pose(), speed(50), MoveMode::Linear)),
            write_coords
        ),
        ask(
            |a| shown(a.check_running()),
            "FE FE 02 2B FA",
            "01",
            "Ok(\"true\")"
        ),
        set(
            |a| shown(a.set_encoder(s(2), Steps(2048))),
            "FE FE 05 3A 02 08 00 FA",
            "FE FE 05 3A 01 08 00 FA"
        ),
        get(
            |a| shown(a.get_encoder(s(7))),
            "FE FE 03 3B 07 FA",
            "07 FF",
            "FE FE 03 3B 06 FA",
            "07 FF",
            "Ok(\"Steps(2047)\")"
        ),
        same(
            |a| shown(a.set_encoders([Steps(2048); 6], speed(20))),
            encoders
        ),
        // 2.4
        same(
            |a| shown(a.jog_angle(j(1), Direction::Positive, speed(30))),
            "FE FE 05 30 01 01 1E FA"
        ),
        same(
            |a| shown(a.jog_coord(Axis::X, Direction::Negative, speed(30))),
            "FE FE 05 32 01 00 1E FA"
        ),
        same(|a| shown(a.jog_stop()), "FE FE 02 34 FA"),
        same(|a| shown(a.pause()), "FE FE 02 26 FA"),
        set(|a| shown(a.resume()), "FE FE 02 28 FA", "FE FE 02 27 FA"),
        set(|a| shown(a.stop()), "FE FE 02 29 FA", "FE FE 02 28 FA"),
        // 2.5
        ask(
            |a| shown(a.get_speed()),
            "FE FE 02 40 FA",
            "32",
            "Ok(\"SpeedPercent(50)\")"
        ),
        same(|a| shown(a.set_speed(speed(50))), "FE FE 03 41 32 FA"),
        get(
            |a| shown(a.get_joint_min(j(1))),
            "FE FE 03 4A 01 FA",
            "01 F9 70",
            "FE FE 03 4A 00 FA",
            "F9 70",
            "Ok(\"Decideg(-1680)\")"
        ),
        get(
            |a| shown(a.get_joint_max(j(6))),
            "FE FE 03 4B 06 FA",
            "06 06 90",
            "FE FE 03 4B 05 FA",
            "06 90",
            "Ok(\"Decideg(1680)\")"
        ),
        set(
            |a| shown(a.set_joint_min(j(1), limit_deg(-90.0))),
            "FE FE 05 4C 01 FC 7C FA",
            "FE FE 05 4C 00 FC 7C FA"
        ),
        set(
            |a| shown(a.set_joint_max(j(2), Decideg(900))),
            "FE FE 05 4D 02 03 84 FA",
            "FE FE 05 4D 01 03 84 FA"
        ),
        // 2.6
        ask(
            |a| shown(a.is_servo_enabled(s(7))),
            "FE FE 03 50 07 FA",
            "07 01",
            "Ok(\"true\")"
        ),
        ask(
            |a| shown(a.is_all_servo_enabled()),
            "FE FE 02 51 FA",
            "00",
            "Ok(\"false\")"
        ),
        get(
            |a| shown(a.get_servo_data(s(1), 21)),
            "FE FE 04 53 01 15 FA",
            "08",
            "FE FE 04 53 00 15 FA",
            "08",
            "Ok(\"8\")"
        ),
        get(
            |a| shown(a.get_servo_data_word(s(1), 24)),
            "FE FE 05 53 01 18 01 FA",
            "03 E8",
            "FE FE 05 53 00 18 01 FA",
            "03 E8",
            "Ok(\"1000\")"
        ),
        set(
            |a| shown(a.set_servo_data(s(1), 21, ServoValue::Byte(10))),
            "FE FE 05 52 01 15 0A FA",
            "FE FE 05 52 00 15 0A FA"
        ),
        set(
            |a| shown(a.set_servo_calibration(s(2))),
            "FE FE 03 54 02 FA",
            "FE FE 03 55 01 FA"
        ),
        set(
            |a| shown(a.joint_brake(s(2))),
            "FE FE 03 55 02 FA",
            "FE FE 03 56 01 FA"
        ),
        same(
            |a| shown(a.set_pin_mode(AtomPin::new(23).unwrap(), PinMode::Output)),
            "FE FE 04 60 17 01 FA"
        ),
        // 2.7
        same(
            |a| shown(a.set_led_rgb(Rgb { r: 0, g: 250, b: 0 })),
            "FE FE 05 6A 00 FA 00 FA"
        ),
        same(
            |a| shown(a.set_gripper(GripperState::Close)),
            "FE FE 03 66 01 FA"
        ),
        same(
            |a| {
                let speed = GripperSpeed::new(70).unwrap();
                shown(a.set_gripper_state(GripperState::Open, speed))
            },
            "FE FE 04 66 00 46 FA"
        ),
        same(
            |a| {
                let (value, speed) = (GripperValue::new(50), GripperSpeed::new(80));
                shown(a.set_gripper_value(value.unwrap(), speed.unwrap()))
            },
            "FE FE 04 67 32 50 FA"
        ),
        ask(
            |a| shown(a.get_gripper_value()),
            "FE FE 02 65 FA",
            "32",
            "Ok(\"GripperValue(50)\")"
        ),
        same(|a| shown(a.set_gripper_ini()), "FE FE 02 68 FA"),
        ask(
            |a| shown(a.is_gripper_moving()),
            "FE FE 02 69 FA",
            "00",
            "Ok(\"false\")"
        ),
        // 2.8
        same(|a| shown(a.set_tool_reference(a_pose())), set_tool),
        ask(
            |a| shown(a.get_tool_reference()),
            "FE FE 02 82 FA",
            POSE,
            pose_debug
        ),
        same(|a| shown(a.set_world_reference(a_pose())), set_world),
        ask(
            |a| shown(a.get_world_reference()),
            "FE FE 02 84 FA",
            POSE,
            pose_debug
        ),
        same(
            |a| shown(a.set_reference_frame(ReferenceFrame::World)),
            "FE FE 03 85 01 FA"
        ),
        ask(
            |a| shown(a.get_reference_frame()),
            "FE FE 02 86 FA",
            "01",
            "Ok(\"World\")"
        ),
        same(
            |a| shown(a.set_end_type(EndType::Tool)),
            "FE FE 03 89 01 FA"
        ),
        ask(
            |a| shown(a.get_end_type()),
            "FE FE 02 8A FA",
            "00",
            "Ok(\"Flange\")"
        ),
        // Beyond the manual's list.
        ask(
            |a| shown(a.get_error_information()),
            "FE FE 02 07 FA",
            "20",
            "Ok(\"Some(IkNoSolution)\")"
        ),
    ]
}

/// A call in a dialect where its reply comes.
struct Answered {
    case: Case,
    dialect: Dialect,
    /// The request on the wire.
    request: Vec<u8>,
    /// The reply data.
    reply: Vec<u8>,
}

/// Every call in every dialect where its reply comes.
fn answered() -> Vec<Answered> {
    let mut out = Vec::new();
    for case in cases() {
        for dialect in Dialect::ALL {
            if let Some((request, Some(reply))) = case.in_dialect(dialect) {
                out.push(Answered {
                    case,
                    dialect,
                    request,
                    reply,
                });
            }
        }
    }
    out
}

/// The value as the table prints it.
fn printed(r: &Result<String, Error>) -> String {
    std::format!("{r:?}")
}

#[test]
fn every_call_sends_its_frame_and_reads_its_value_in_both_dialects() {
    let cases = cases();
    assert_eq!(cases.len(), 52);
    for case in &cases {
        for dialect in Dialect::ALL {
            let Some((request, reply)) = case.in_dialect(dialect) else {
                let (mut arm, _) = bot(dialect, std::vec![]);
                let got = (case.call)(&mut arm);
                assert_eq!(got, Err(Error::NotInDialect { cmd: case.cmd() }));
                assert!(arm.port().written.is_empty());
                continue;
            };
            let answer = reply.as_ref().map(|d| frame(request[3], d));
            let (mut arm, now) = bot(dialect, answer.into_iter().collect());
            let got = (case.call)(&mut arm);
            assert_eq!(printed(&got), case.value, "{} {dialect:?}", case.py);
            assert_eq!(arm.port().written, [request], "{} {dialect:?}", case.py);
            if reply.is_none() {
                // Silent in seed: returns once written, without waiting.
                assert!(
                    now.get() < 10 * TICK_US,
                    "{} waited {} us",
                    case.py,
                    now.get()
                );
            }
        }
    }
}

#[test]
fn no_reply_is_a_timeout_after_the_deadline() {
    for Answered {
        case,
        dialect,
        request: _,
        reply: _,
    } in answered()
    {
        let (mut arm, now) = bot(dialect, std::vec![]);
        let got = (case.call)(&mut arm);
        assert_eq!(got, Err(Error::Timeout { cmd: case.cmd() }), "{}", case.py);
        let waited = now.get();
        assert!(
            (500_000..=500_000 + 10 * TICK_US).contains(&waited),
            "{} waited {waited} us",
            case.py
        );
    }
    // The deadline is settable.
    let (mut arm, now) = bot(Dialect::Pymycobot, std::vec![]);
    arm.set_reply_timeout_us(20_000);
    assert_eq!(arm.get_angles(), Err(Error::Timeout { cmd: 0x20 }));
    assert!((20_000..21_000).contains(&now.get()));
}

#[test]
fn a_refusal_asks_for_the_error_code() {
    for Answered {
        case,
        dialect,
        request,
        reply: _,
    } in answered()
    {
        if !case.refusable() {
            continue;
        }
        let answers = std::vec![frame(request[3], &[0]), frame(0x07, &[32])];
        let (mut arm, _) = bot(dialect, answers);
        let got = (case.call)(&mut arm);
        let refused = Error::Refused {
            cmd: case.cmd(),
            code: Some(ErrorCode::IkNoSolution),
        };
        assert_eq!(got, Err(refused), "{} {dialect:?}", case.py);
        assert_eq!(
            arm.port().written,
            [request, hex("FE FE 02 07 FA")],
            "{}",
            case.py
        );
    }
}

#[test]
fn a_refusal_without_a_code() {
    // 0x07 says "no error": no code.
    let answers = std::vec![frame(0x10, &[0]), frame(0x07, &[0])];
    let (mut arm, _) = bot(Dialect::Pymycobot, answers);
    let refused = Error::Refused {
        cmd: 0x10,
        code: None,
    };
    assert_eq!(arm.power_on(), Err(refused));
    assert_eq!(refused.to_string(), "command 0x10 refused");
    // 0x07 does not answer: the refusal still comes, after its own deadline.
    let (mut arm, now) = bot(Dialect::Pymycobot, std::vec![frame(0x21, &[0])]);
    assert_eq!(
        arm.write_angle(j(1), deg(200.0), SpeedPercent::MAX),
        Err(Error::Refused {
            cmd: 0x21,
            code: None
        })
    );
    assert!((500_000..=501_000).contains(&now.get()), "{}", now.get());
    // A code from a joint.
    let answers = std::vec![frame(0x21, &[0]), frame(0x07, &[1])];
    let (mut arm, _) = bot(Dialect::Pymycobot, answers);
    let got = arm.write_angle(j(1), deg(200.0), SpeedPercent::MAX);
    assert_eq!(
        got.map_err(|e| e.to_string()),
        Err("command 0x21 refused: joint 1 is at or beyond its limit".to_string())
    );
}

#[test]
fn garbage_and_a_false_start_before_the_reply_are_skipped() {
    // Noise, a servo packet's start, and a frame header whose LEN (0x30) runs past the
    // reply: the reply is found once the line has been quiet for the reply frame gap.
    let garbage = hex("00 FA FE 13 FF FF 01 02 FE FE 30 20");
    for Answered {
        case,
        dialect,
        request,
        reply,
    } in answered()
    {
        let mut answer = garbage.clone();
        answer.extend(frame(request[3], &reply));
        let (mut arm, now) = bot(dialect, std::vec![answer]);
        assert_eq!(printed(&(case.call)(&mut arm)), case.value, "{}", case.py);
        assert!(now.get() < 100_000, "{}: {} us", case.py, now.get());
    }
}

#[test]
fn a_reply_for_another_command_is_ignored() {
    for Answered {
        case,
        dialect,
        request,
        reply,
    } in answered()
    {
        // Another command's reply with the same data, then the right one.
        let mut answer = frame(request[3] ^ 0x80, &reply);
        answer.extend(frame(request[3], &reply));
        let (mut arm, _) = bot(dialect, std::vec![answer]);
        assert_eq!(printed(&(case.call)(&mut arm)), case.value, "{}", case.py);
        // Only another command's reply: no reply in time.
        let (mut arm, _) = bot(dialect, std::vec![frame(request[3] ^ 0x80, &reply)]);
        let got = (case.call)(&mut arm);
        assert_eq!(got, Err(Error::Timeout { cmd: case.cmd() }), "{}", case.py);
    }
}

#[test]
fn a_stale_reply_received_before_the_request_is_dropped() {
    for Answered {
        case,
        dialect,
        request,
        reply,
    } in answered()
    {
        let (mut arm, _) = bot(dialect, std::vec![frame(request[3], &reply)]);
        // A refusal of an earlier request with the same CMD, already in the port.
        arm.port_mut().rx.extend(frame(request[3], &[0]));
        assert_eq!(printed(&(case.call)(&mut arm)), case.value, "{}", case.py);
    }
}

#[test]
fn a_malformed_reply_is_an_error_not_a_panic() {
    for Answered {
        case,
        dialect,
        request,
        reply,
    } in answered()
    {
        // One byte too many, and one too few.
        let mut long = reply.clone();
        long.push(0x55);
        let mut answers = std::vec![frame(request[3], &long)];
        if reply.len() > 1 {
            answers = std::vec![frame(request[3], &reply[1..])];
        }
        let (mut arm, _) = bot(dialect, answers);
        let got = (case.call)(&mut arm);
        assert_eq!(got, Err(Error::BadReply { cmd: case.cmd() }), "{}", case.py);
    }
    // Values out of range.
    for (cmd, data, call) in [
        (0x12, &[7u8][..], (|a| shown(a.is_powered_on())) as Call),
        (0x86, &[5], |a| shown(a.get_reference_frame())),
        (0x8A, &[2], |a| shown(a.get_end_type())),
        (0x40, &[0], |a| shown(a.get_speed())),
        (0x65, &[101], |a| shown(a.get_gripper_value())),
        (0x07, &[7], |a| shown(a.get_error_information())),
        (0x50, &[6, 1], |a| shown(a.is_servo_enabled(s(7)))),
        (0x10, &[2], |a| shown(a.power_on())),
    ] {
        let (mut arm, _) = bot(Dialect::Pymycobot, std::vec![frame(cmd, data)]);
        assert_eq!((call)(&mut arm), Err(Error::BadReply { cmd }), "{cmd:#x}");
    }
}

#[test]
fn seed_joint_limits_and_errors_over_the_seed_dialect() {
    // A seed query refused: the 0x07 that follows is the seed dialect's too.
    let answers = std::vec![frame(0x4A, &[0]), frame(0x07, &[21])];
    let (mut arm, _) = bot(Dialect::Seed, answers);
    assert_eq!(
        arm.get_joint_min(j(1)),
        Err(Error::Refused {
            cmd: 0x4A,
            code: Some(ErrorCode::StateLost(j(1)))
        })
    );
    assert_eq!(arm.port().written[0], hex("FE FE 03 4A 00 FA"));
    // Switching the dialect changes the next frame.
    arm.set_dialect(Dialect::Pymycobot);
    arm.port_mut().answers.push_back(frame(0x29, &[1]));
    assert_eq!(arm.stop(), Ok(()));
    assert_eq!(arm.port().written[2], hex("FE FE 02 29 FA"));
}

#[test]
fn degrees_and_millimetres_round_to_the_nearest_unit() {
    assert_eq!(deg(-30.504), Centideg(-3050));
    assert_eq!(deg(0.005), Centideg(1));
    assert_eq!(deg(1e9), Centideg(i16::MAX));
    assert_eq!(deg(f32::NAN), Centideg(0));
    assert_eq!(mm(-0.04), protocol_core::units::DeciMm(0));
    assert_eq!(limit_deg(-168.0), Decideg(-1680));
    assert_eq!(
        crate::convert::pose_to_mm_deg(&a_pose()),
        [150.0, -20.5, 200.0, -180.0, 0.5, 90.0]
    );
    assert_eq!(AxisValue::Z(mm(180.0)).raw(), 1800);
}

#[test]
fn the_error_lines_name_the_command_and_the_reason() {
    assert_eq!(
        Error::Timeout { cmd: 0x20 }.to_string(),
        "no reply to command 0x20 in time"
    );
    let refused = Error::Refused {
        cmd: 0x25,
        code: Some(ErrorCode::IkNoSolution),
    };
    assert_eq!(
        refused.to_string(),
        "command 0x25 refused: no inverse-kinematics solution for the pose"
    );
    assert_eq!(refused.cmd(), 0x25);
}

#[test]
fn any_request_goes_through_request() {
    use protocol_core::command::{Reply, Request};
    let pin = AtomPin::new(19).unwrap();
    let level = Request::GetDigitalInput { pin };
    // The seed dialect answers the level alone; the reply names the pin again.
    let (mut arm, _) = bot(Dialect::Seed, std::vec![frame(0x62, &[1])]);
    let high = Reply::PinLevel {
        pin: 19,
        high: true,
    };
    assert_eq!(arm.request(&level), Ok(Some(high.clone())));
    assert_eq!(arm.port().written, [hex("FE FE 03 62 13 FA")]);
    let (mut arm, _) = bot(Dialect::Seed, std::vec![frame(0x62, &[5])]);
    assert_eq!(arm.request(&level), Err(Error::BadReply { cmd: 0x62 }));
    let (mut arm, _) = bot(Dialect::Pymycobot, std::vec![frame(0x62, &[19, 1])]);
    assert_eq!(arm.request(&level), Ok(Some(high)));
    // A command the typed calls do not cover, and one without a value in seed.
    let (mut arm, _) = bot(Dialect::Pymycobot, std::vec![frame(0x17, &[1])]);
    assert_eq!(
        arm.request(&Request::GetFreshMode),
        Ok(Some(Reply::Byte(1)))
    );
    let (mut arm, _) = bot(Dialect::Seed, std::vec![]);
    let fresh = Request::SetFreshMode { fresh: false };
    assert_eq!(arm.request(&fresh), Ok(None));
    assert_eq!(arm.port().written, [hex("FE FE 03 16 00 FA")]);
    assert_eq!(
        arm.request(&Request::IsPaused),
        Err(Error::NotInDialect { cmd: 0x27 })
    );
}

#[test]
fn a_started_call_ends_when_its_reply_arrives_and_never_blocks_before() {
    use protocol_core::command::{Reply, Request};
    // Nothing answers at first: every poll returns at once, without an outcome.
    let (mut arm, now) = bot(Dialect::Pymycobot, std::vec![std::vec![]]);
    let mut call = arm.start(&Request::IsPowerOn).unwrap();
    for _ in 0..10 {
        assert_eq!(arm.poll(&mut call), None);
    }
    assert!(now.get() < 1_000, "polls read the clock once each");
    // Then the reply comes, with a reply to something else before it.
    arm.port_mut().rx.extend(frame(0x20, &[0; 12]));
    arm.port_mut().rx.extend(frame(0x12, &[1]));
    assert_eq!(arm.poll(&mut call), Some(Ok(Some(Reply::Byte(1)))));
    // An ended call stays ended.
    assert_eq!(arm.poll(&mut call), Some(Err(Error::Timeout { cmd: 0x12 })));
    assert_eq!(call.request(), &Request::IsPowerOn);
}

#[test]
fn a_started_call_that_is_refused_asks_for_the_reason_without_blocking() {
    use protocol_core::command::Request;
    let (mut arm, _) = bot(Dialect::Pymycobot, std::vec![std::vec![], std::vec![]]);
    let request = Request::SendAngle {
        joint: j(2),
        angle: Centideg(20000),
        speed: SpeedPercent::MAX,
    };
    let mut call = arm.start(&request).unwrap();
    arm.port_mut().rx.extend(frame(0x21, &[0]));
    assert_eq!(arm.poll(&mut call), None, "the reason is asked");
    assert_eq!(arm.port().written.last().unwrap(), &hex("FE FE 02 07 FA"));
    assert_eq!(arm.poll(&mut call), None);
    arm.port_mut().rx.extend(frame(0x07, &[2]));
    assert_eq!(
        arm.poll(&mut call),
        Some(Err(Error::Refused {
            cmd: 0x21,
            code: Some(ErrorCode::JointLimit(j(2)))
        }))
    );
}

#[test]
fn a_started_seed_set_command_ends_at_once() {
    use protocol_core::command::Request;
    let (mut arm, _) = bot(Dialect::Seed, std::vec![]);
    let mut call = arm.start(&Request::PowerOn).unwrap();
    assert_eq!(arm.poll(&mut call), Some(Ok(None)));
}
