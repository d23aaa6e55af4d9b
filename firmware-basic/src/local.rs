//! The commands the Basic answers itself (`protocol.md` section 5, "Answered by the Basic
//! itself"); they never reach the bus.
//!
//! | code | reply |
//! |---|---|
//! | 0xA0 set output (pin 2 or 5, level 0/1) | `01` done, `00` refused (bad pin or level) |
//! | 0xA1 get input (pin 35 or 36) | pin, level; level `FF` (pymycobot: 255) for a bad pin |
//! | 0xB0 set Wi-Fi SSID/password, 0xB2 set server port | `01` stored, `00` refused or the flash write failed ([`crate::wifi`]); `00` on a board without Wi-Fi |
//! | 0xB1 get Wi-Fi SSID/password | the text `ssid: <ssid> password: <password>`; `ssid:  password: ` (pymycobot: `('', '')`) without Wi-Fi |
//! | 0xC0 ToF distance | int16 mm; -1 without a sensor |
//! | 0xC1 Basic version | version x 10 |
//! | 0xC2 set transponder mode (0 framed, 1 transparent) | `01`, or `00` for another mode |
//! | 0xC3 get transponder mode | mode |
//!
//! 0xB1 answers raw text, not a frame, because that is what pymycobot reads: it decodes the
//! bytes as UTF-8 and splits them at spaces (a frame would make it raise). The Wi-Fi commands
//! go to the Basic's [`Wifi`] with the flash store the board lends ([`BasicIo::wifi_store`]); a
//! board that lends none has no Wi-Fi. A request that
//! `protocol_core::command::Request::parse` rejects (wrong length, bad level or mode) is
//! refused with `00`.

use heapless::Vec;
use protocol_core::Frame;
use protocol_core::command::{CommandError, Reply, Request, cmd, is_basic_local};
use protocol_core::dialect::{Answer, Dialect};

use crate::io::BasicIo;
use crate::status::{BasicError, TransponderMode};
use crate::wifi::{MAX_GET_TEXT, SetTextEnd, Wifi, WifiAnswer, WifiReply};

/// What 0xB1 answers on a board without Wi-Fi: no network configured, in the text form
/// pymycobot parses.
pub const NO_WIFI_TEXT: &[u8] = b"ssid:  password: ";

/// Level byte of 0xA1 for a pin that cannot be read: neither 0 nor 1 (pymycobot returns 255).
/// A shorter reply would make pymycobot raise, no reply would cost it 1.5 s of retries.
const NO_LEVEL: u8 = 0xFF;

/// The Basic's answer to one of its own commands.
#[derive(Debug, PartialEq, Eq)]
pub(crate) struct LocalAnswer {
    /// The reply for the host.
    pub(crate) body: AnswerBody,
    /// The transponder mode to switch to after the reply.
    pub(crate) new_mode: Option<TransponderMode>,
    /// The dialect switched to (0xC5): the reply already names it.
    pub(crate) new_dialect: Option<Dialect>,
    /// What went wrong, for the display.
    pub(crate) error: Option<BasicError>,
    /// The request was 0xB0's announcing frame, acknowledged: the link's next bytes are the
    /// bare text (a `SetTextCapture`).
    pub(crate) capture_text: bool,
}

/// What goes back to the host: a frame, or bare text.
#[derive(Debug, PartialEq, Eq)]
pub(crate) enum AnswerBody {
    /// A reply frame.
    Frame(Frame),
    /// Bare text (0xB1).
    Text(Vec<u8, MAX_GET_TEXT>),
    /// Nothing: the client's dialect expects no reply.
    Nothing,
}

impl LocalAnswer {
    fn frame(cmd: u8, data: Reply) -> Self {
        Self {
            body: AnswerBody::Frame(data.to_frame(cmd)),
            new_mode: None,
            new_dialect: None,
            error: None,
            capture_text: false,
        }
    }

    fn from_wifi(answer: WifiAnswer) -> Self {
        Self {
            body: match answer.reply {
                WifiReply::Frame(frame) => AnswerBody::Frame(frame),
                WifiReply::Text(text) => AnswerBody::Text(text),
            },
            new_mode: None,
            new_dialect: None,
            error: answer.error.map(BasicError::Wifi),
            capture_text: answer.capture_text,
        }
    }

    /// This answer as a client of a dialect gets it (`answer`, from its request's
    /// translation): a frame changed or dropped, text as it is.
    pub(crate) fn in_dialect(mut self, answer: Answer) -> Self {
        if let AnswerBody::Frame(reply) = &self.body {
            self.body = answer
                .reply(reply)
                .map_or(AnswerBody::Nothing, AnswerBody::Frame);
        }
        self
    }

    /// The status reply: `01` done, `00` refused.
    fn status(cmd: u8, done: bool) -> Self {
        Self::frame(cmd, Reply::Byte(u8::from(done)))
    }

    fn with_error(mut self, error: BasicError) -> Self {
        self.error = Some(error);
        self
    }
}

/// The Basic's state its own commands read or change.
pub(crate) struct Context<'a> {
    /// Version x 10 (0xC1).
    pub(crate) version_x10: u8,
    /// The transponder mode (0xC3).
    pub(crate) mode: TransponderMode,
    /// The dialect in force (0xC5).
    pub(crate) dialect: Dialect,
    /// The Wi-Fi (0xB0..0xB2), if the board has it.
    pub(crate) wifi: Option<&'a mut Wifi>,
    /// The time, microseconds.
    pub(crate) now_us: u64,
}

/// Answers `frame` if it is one of the Basic's own commands; `None` if it is for the Atom.
pub(crate) fn answer<I: BasicIo>(
    frame: &Frame,
    io: &mut I,
    cx: Context<'_>,
) -> Option<LocalAnswer> {
    let code = frame.cmd();
    if !is_basic_local(code) {
        return None;
    }
    if let Some(wifi) = cx.wifi
        && let Some(store) = io.wifi_store()
        && let Some(answer) = wifi.answer(cx.now_us, frame, store)
    {
        return Some(LocalAnswer::from_wifi(answer));
    }
    let (version_x10, mode) = (cx.version_x10, cx.mode);
    let answer = match Request::parse(frame) {
        Ok(Request::SetBasicOutput { pin, high }) => {
            LocalAnswer::status(code, io.set_output(pin.gpio(), high))
        }
        Ok(Request::GetBasicInput { pin }) => match io.read_input(pin.gpio()) {
            Some(high) => LocalAnswer::frame(
                code,
                Reply::PinLevel {
                    pin: pin.gpio(),
                    high,
                },
            ),
            None => pin_unreadable(code, pin.gpio()),
        },
        Ok(Request::GetSsidPwd) => {
            let mut text = Vec::new();
            // Cannot fail: the text is shorter than any 0xB1 answer may be.
            let _ = text.extend_from_slice(NO_WIFI_TEXT);
            LocalAnswer {
                body: AnswerBody::Text(text),
                new_mode: None,
                new_dialect: None,
                error: None,
                capture_text: false,
            }
        }
        Ok(Request::GetTofDistance) => {
            let mm = io
                .tof_distance_mm()
                .map_or(-1, |mm| i16::try_from(mm).unwrap_or(i16::MAX));
            LocalAnswer::frame(code, Reply::Int16(mm))
        }
        Ok(Request::GetBasicVersion) => LocalAnswer::frame(code, Reply::Byte(version_x10)),
        Ok(Request::SetTransponderMode { mode }) => LocalAnswer {
            new_mode: Some(mode),
            ..LocalAnswer::status(code, true)
        },
        Ok(Request::GetTransponderMode) => LocalAnswer::frame(code, Reply::Byte(mode as u8)),
        Ok(Request::Dialect { set }) => LocalAnswer {
            new_dialect: set,
            ..LocalAnswer::frame(code, Reply::Byte(set.unwrap_or(cx.dialect) as u8))
        },
        Err(CommandError::BadPin(pin)) if code == cmd::GET_BASIC_INPUT => {
            pin_unreadable(code, pin).with_error(BasicError::InvalidPin { pin })
        }
        Err(CommandError::BadPin(pin)) => {
            LocalAnswer::status(code, false).with_error(BasicError::InvalidPin { pin })
        }
        // No Wi-Fi (0xB0, 0xB2), a bad level or mode, a wrong length: refused.
        _ => LocalAnswer::status(code, false),
    };
    Some(answer)
}

/// Answers the end of a link's 0xB0 text capture at `now_us`: `01` stored, `00` refused or the
/// flash failed; `None` if nothing is due (no text came, or the board has no Wi-Fi any more).
pub(crate) fn answer_set_text<I: BasicIo>(
    end: SetTextEnd,
    io: &mut I,
    wifi: Option<&mut Wifi>,
    now_us: u64,
) -> Option<LocalAnswer> {
    let store = io.wifi_store()?;
    wifi?
        .answer_set_text(now_us, end, store)
        .map(LocalAnswer::from_wifi)
}

/// 0xA1's answer for a pin that cannot be read: the pin, level `FF`.
fn pin_unreadable(code: u8, pin: u8) -> LocalAnswer {
    let mut data = heapless::Vec::new();
    // Cannot fail: two bytes fit.
    let _ = data.extend_from_slice(&[pin, NO_LEVEL]);
    LocalAnswer::frame(code, Reply::Raw(data))
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::io::Buttons;

    /// A board whose outputs and inputs are plain memory.
    #[derive(Default)]
    struct FakeIo {
        outputs: std::vec::Vec<(u8, bool)>,
        input_35: bool,
        tof_mm: Option<u16>,
    }

    impl BasicIo for FakeIo {
        fn set_output(&mut self, pin: u8, high: bool) -> bool {
            self.outputs.push((pin, high));
            true
        }
        fn read_input(&mut self, pin: u8) -> Option<bool> {
            (pin == 35).then_some(self.input_35)
        }
        fn tof_distance_mm(&mut self) -> Option<u16> {
            self.tof_mm
        }
        fn buttons(&mut self) -> Buttons {
            Buttons::default()
        }
    }

    fn ask(io: &mut FakeIo, cmd: u8, data: &[u8]) -> Option<LocalAnswer> {
        let cx = Context {
            version_x10: 12,
            mode: TransponderMode::Framed,
            dialect: Dialect::Pymycobot,
            wifi: None,
            now_us: 0,
        };
        answer(&Frame::new(cmd, data).unwrap(), io, cx)
    }

    fn reply_bytes(answer: &LocalAnswer) -> std::vec::Vec<u8> {
        match &answer.body {
            AnswerBody::Frame(f) => f.to_bytes().to_vec(),
            AnswerBody::Text(bytes) => bytes.to_vec(),
            AnswerBody::Nothing => std::vec::Vec::new(),
        }
    }

    #[test]
    fn the_dialect_command_names_the_dialect_in_force_after_it() {
        let mut io = FakeIo::default();
        let asked = ask(&mut io, cmd::DIALECT, &[]).unwrap();
        assert_eq!(reply_bytes(&asked), [0xFE, 0xFE, 0x03, 0xC5, 0x01, 0xFA]);
        assert_eq!(asked.new_dialect, None);
        let set = ask(&mut io, cmd::DIALECT, &[2]).unwrap();
        assert_eq!(reply_bytes(&set), [0xFE, 0xFE, 0x03, 0xC5, 0x02, 0xFA]);
        assert_eq!(set.new_dialect, Some(Dialect::Seed));
        let refused = ask(&mut io, cmd::DIALECT, &[7]).unwrap();
        assert_eq!(reply_bytes(&refused), [0xFE, 0xFE, 0x03, 0xC5, 0x00, 0xFA]);
        assert_eq!(refused.new_dialect, None);
    }

    #[test]
    fn a_seed_client_gets_no_answer_to_a_set_command_and_the_value_of_a_query() {
        let mut io = FakeIo::default();
        let set = ask(&mut io, 0xA0, &[5, 1])
            .unwrap()
            .in_dialect(Answer::Silent);
        assert_eq!(set.body, AnswerBody::Nothing);
        assert_eq!(io.outputs, [(5, true)], "done all the same");
        let query = ask(&mut io, cmd::DIALECT, &[])
            .unwrap()
            .in_dialect(Answer::AsIs);
        assert_eq!(reply_bytes(&query), [0xFE, 0xFE, 0x03, 0xC5, 0x01, 0xFA]);
    }

    #[test]
    fn set_output_drives_the_valve_pin_and_acks() {
        let mut io = FakeIo::default();
        let a = ask(&mut io, 0xA0, &[5, 1]).unwrap();
        assert_eq!(reply_bytes(&a), [0xFE, 0xFE, 0x03, 0xA0, 0x01, 0xFA]);
        assert_eq!(io.outputs, [(5, true)]);
    }

    #[test]
    fn set_output_refuses_a_pin_the_basic_does_not_have() {
        let mut io = FakeIo::default();
        let a = ask(&mut io, 0xA0, &[4, 1]).unwrap();
        assert_eq!(reply_bytes(&a), [0xFE, 0xFE, 0x03, 0xA0, 0x00, 0xFA]);
        assert_eq!(a.error, Some(BasicError::InvalidPin { pin: 4 }));
        assert!(io.outputs.is_empty());
        let a = ask(&mut io, 0xA0, &[2, 7]).unwrap();
        assert_eq!(reply_bytes(&a), [0xFE, 0xFE, 0x03, 0xA0, 0x00, 0xFA]);
        assert!(io.outputs.is_empty());
    }

    #[test]
    fn get_input_returns_pin_and_level() {
        let mut io = FakeIo {
            input_35: true,
            ..FakeIo::default()
        };
        let a = ask(&mut io, 0xA1, &[35]).unwrap();
        assert_eq!(reply_bytes(&a), [0xFE, 0xFE, 0x04, 0xA1, 35, 1, 0xFA]);
        let a = ask(&mut io, 0xA1, &[2]).unwrap();
        assert_eq!(reply_bytes(&a), [0xFE, 0xFE, 0x04, 0xA1, 2, 0xFF, 0xFA]);
        assert_eq!(a.error, Some(BasicError::InvalidPin { pin: 2 }));
    }

    #[test]
    fn tof_distance_is_big_endian_mm_or_minus_one() {
        let mut io = FakeIo {
            tof_mm: Some(300),
            ..FakeIo::default()
        };
        let a = ask(&mut io, 0xC0, &[]).unwrap();
        assert_eq!(reply_bytes(&a), [0xFE, 0xFE, 0x04, 0xC0, 0x01, 0x2C, 0xFA]);
        io.tof_mm = None;
        let a = ask(&mut io, 0xC0, &[]).unwrap();
        assert_eq!(reply_bytes(&a), [0xFE, 0xFE, 0x04, 0xC0, 0xFF, 0xFF, 0xFA]);
    }

    #[test]
    fn version_and_mode_queries() {
        let mut io = FakeIo::default();
        let a = ask(&mut io, 0xC1, &[]).unwrap();
        assert_eq!(reply_bytes(&a), [0xFE, 0xFE, 0x03, 0xC1, 12, 0xFA]);
        let a = ask(&mut io, 0xC3, &[]).unwrap();
        assert_eq!(reply_bytes(&a), [0xFE, 0xFE, 0x03, 0xC3, 0, 0xFA]);
        let a = ask(&mut io, 0xC2, &[1]).unwrap();
        assert_eq!(a.new_mode, Some(TransponderMode::Transparent));
        assert_eq!(reply_bytes(&a), [0xFE, 0xFE, 0x03, 0xC2, 1, 0xFA]);
        let a = ask(&mut io, 0xC2, &[9]).unwrap();
        assert_eq!(a.new_mode, None);
        assert_eq!(reply_bytes(&a), [0xFE, 0xFE, 0x03, 0xC2, 0, 0xFA]);
    }

    #[test]
    fn wifi_commands_answer_without_wifi() {
        let mut io = FakeIo::default();
        let a = ask(&mut io, 0xB0, &[]).unwrap();
        assert_eq!(reply_bytes(&a), [0xFE, 0xFE, 0x03, 0xB0, 0, 0xFA]);
        let a = ask(&mut io, 0xB2, &[0x23, 0x28]).unwrap();
        assert_eq!(reply_bytes(&a), [0xFE, 0xFE, 0x03, 0xB2, 0, 0xFA]);
        let a = ask(&mut io, 0xB1, &[]).unwrap();
        // pymycobot: data.decode("utf-8").split(" ") -> [1] and [-1].
        let text = std::str::from_utf8(&reply_bytes(&a)).unwrap().to_owned();
        let parts: std::vec::Vec<&str> = text.split(' ').collect();
        assert_eq!((parts[1], parts[parts.len() - 1]), ("", ""));
    }

    #[test]
    fn wrong_length_is_refused_and_atom_commands_are_not_local() {
        let mut io = FakeIo::default();
        let a = ask(&mut io, 0xA0, &[5]).unwrap();
        assert_eq!(reply_bytes(&a), [0xFE, 0xFE, 0x03, 0xA0, 0x00, 0xFA]);
        assert!(io.outputs.is_empty());
        assert!(ask(&mut io, 0x20, &[]).is_none());
        assert!(ask(&mut io, 0x10, &[]).is_none());
    }
}
