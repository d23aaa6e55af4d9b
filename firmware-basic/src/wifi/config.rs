//! The Wi-Fi settings (network name, password, TCP port), their validation, and their wire
//! layouts: 0xB0 / 0xB1 / 0xB2 exactly as pymycobot 4.0.7 sends and parses them, and the record
//! they are kept in flash as.
//!
//! ## The wire, as pymycobot 4.0.7 uses it
//!
//! **0xB0 `set_ssid_pwd(ssid, password)`** is two writes 20 ms apart, and only the first is a
//! frame:
//!
//! 1. `FE FE 02 B0 FA`, the announcing frame (no data). pymycobot then reads for 50 ms (a
//!    reply ends the read early; what it holds is ignored) and sleeps 20 ms.
//! 2. The bare UTF-8 text `'` ssid `'(` password `)`, no header, length or footer: pymycobot's
//!    `write()` replaces the frame it built (`FE FE 04 B0 "ssid" "password" FA`, whose LEN counts
//!    the two strings as one byte each) by that text. It reads for another 50 ms and returns 1
//!    whatever came back.
//!
//! The Basic answers the announcing frame with `FE FE 03 B0 01 FA` and starts a
//! [`SetTextCapture`] on that client's link; the text ends when the link has been quiet for the
//! capture's end gap, and is answered `01` (stored) or `00` (refused, or the flash failed).
//! A client that frames the text itself, `FE FE LEN B0 'ssid'(password) FA`, gets the same
//! answer at once. The reply to the text must arrive inside pymycobot's 50 ms read: a late
//! reply stays in the serial input buffer, and a `get_ssid_pwd` straight after (which does not
//! flush the buffer first) would then fail to decode it as UTF-8.
//!
//! **0xB1 `get_ssid_pwd()`** sends `FE FE 02 B1 FA`; the answer is bare text, not a frame:
//! `ssid: ` ssid ` password: ` password. pymycobot waits 100 ms, reads what arrived, decodes it
//! as UTF-8, splits it at single spaces and returns `(parts[1], parts[-1])`; over TCP
//! (`MyCobot280Socket`) it reads until the text contains `password`. So an SSID or a password
//! with a space in it is read back cut at the space (the Basic still joins the network it
//! names); with no network set the text is `ssid:  password: ` and pymycobot returns
//! `('', '')`.
//!
//! **0xB2 `set_server_port(port)`** sends `FE FE 04 B2 hi lo FA`, the port as a big-endian
//! int16 (pymycobot packs it signed: 1..=32767 from Python; 32768..=65535 arrive as the same two
//! bytes from other clients and are taken as the unsigned port). The answer is
//! `FE FE 03 B2 01 FA`, or `00` for port 0, a wrong length or a failed flash write; pymycobot
//! returns that byte.
//!
//! ## Validation
//!
//! * SSID: 1..=32 bytes of UTF-8 text without control characters (an empty one is refused).
//! * Password: empty (an open network), or a WPA passphrase of 8..=63 printable ASCII characters,
//!   or 64 hexadecimal digits (the raw key). Anything else could never join a network.
//! * Port: 1..=65535; default [`DEFAULT_PORT`], `MyCobot280Socket`'s default.

use core::fmt;

use heapless::{String, Vec};

/// Longest SSID, bytes (IEEE 802.11).
pub const MAX_SSID_LEN: usize = 32;
/// Longest password, bytes: a 64-digit hexadecimal key (a passphrase has at most 63).
pub const MAX_PASSWORD_LEN: usize = 64;
/// Shortest WPA passphrase, characters (IEEE 802.11i).
pub const MIN_PASSPHRASE_LEN: usize = 8;
/// TCP port the Basic listens on until a client sets another: `MyCobot280Socket`'s default.
pub const DEFAULT_PORT: u16 = 9000;

/// Longest 0xB0 text: `'` + SSID + `'(` + password + `)`.
pub const MAX_SET_TEXT: usize = 1 + MAX_SSID_LEN + 2 + MAX_PASSWORD_LEN + 1;
/// Longest 0xB1 answer: `ssid: ` + SSID + ` password: ` + password.
pub const MAX_GET_TEXT: usize =
    GET_TEXT_SSID.len() + MAX_SSID_LEN + GET_TEXT_PASSWORD.len() + MAX_PASSWORD_LEN;
/// Longest flash record ([`WifiSettings::encode`]).
pub const MAX_RECORD: usize = 1 + 1 + MAX_SSID_LEN + 1 + MAX_PASSWORD_LEN + 2;

/// What the 0xB1 text starts with.
const GET_TEXT_SSID: &str = "ssid: ";
/// What separates the SSID from the password in the 0xB1 text.
const GET_TEXT_PASSWORD: &str = " password: ";
/// Format of the flash record; a record of another version is not read.
const RECORD_VERSION: u8 = 1;

/// Why settings were refused. Each refusal changes nothing.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum SettingsError {
    /// The SSID is empty.
    SsidEmpty,
    /// The SSID is longer than [`MAX_SSID_LEN`] bytes.
    SsidTooLong {
        /// Its length, bytes.
        len: usize,
    },
    /// The SSID is not UTF-8 text, or has a control character.
    SsidNotText,
    /// The password is neither empty, nor a passphrase of 8..=63 printable ASCII characters,
    /// nor 64 hexadecimal digits.
    BadPassword {
        /// Its length, bytes.
        len: usize,
    },
    /// Port 0.
    PortZero,
    /// The 0xB0 text is not `'ssid'(password)`, or the 0xB2 data is not two bytes.
    BadLayout,
    /// The 0xB0 text is longer than [`MAX_SET_TEXT`].
    TextTooLong,
    /// A flash record that is not one [`WifiSettings::encode`] wrote.
    BadRecord,
}

impl fmt::Display for SettingsError {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            Self::SsidEmpty => write!(f, "empty SSID"),
            Self::SsidTooLong { len } => write!(f, "SSID of {len} bytes (at most {MAX_SSID_LEN})"),
            Self::SsidNotText => write!(f, "SSID is not text"),
            Self::BadPassword { len } => write!(f, "password of {len} bytes is not a WPA key"),
            Self::PortZero => write!(f, "port 0"),
            Self::BadLayout => write!(f, "not the layout pymycobot sends"),
            Self::TextTooLong => write!(f, "0xB0 text over {MAX_SET_TEXT} bytes"),
            Self::BadRecord => write!(f, "unreadable settings record"),
        }
    }
}

/// A network to join: its name and password, both checked (see the [module doc](self)).
#[derive(Clone, PartialEq, Eq)]
pub struct Credentials {
    ssid: String<MAX_SSID_LEN>,
    password: String<MAX_PASSWORD_LEN>,
}

impl fmt::Debug for Credentials {
    /// The password is not printed.
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.debug_struct("Credentials")
            .field("ssid", &self.ssid.as_str())
            .field("password_len", &self.password.len())
            .finish()
    }
}

impl Credentials {
    /// Checked credentials from the raw bytes of an SSID and a password.
    pub fn new(ssid: &[u8], password: &[u8]) -> Result<Self, SettingsError> {
        Ok(Self {
            ssid: check_ssid(ssid)?,
            password: check_password(password)?,
        })
    }

    /// The network name: 1..=32 bytes of text.
    pub fn ssid(&self) -> &str {
        &self.ssid
    }

    /// The password: empty (open network), a passphrase or a 64-digit hexadecimal key.
    pub fn password(&self) -> &str {
        &self.password
    }

    /// True for an open network (no password).
    pub fn is_open(&self) -> bool {
        self.password.is_empty()
    }
}

fn check_ssid(ssid: &[u8]) -> Result<String<MAX_SSID_LEN>, SettingsError> {
    if ssid.is_empty() {
        return Err(SettingsError::SsidEmpty);
    }
    if ssid.len() > MAX_SSID_LEN {
        return Err(SettingsError::SsidTooLong { len: ssid.len() });
    }
    let text = core::str::from_utf8(ssid).map_err(|_| SettingsError::SsidNotText)?;
    if text.chars().any(char::is_control) {
        return Err(SettingsError::SsidNotText);
    }
    let mut out = String::new();
    out.push_str(text)
        .map_err(|_| SettingsError::SsidTooLong { len: ssid.len() })?;
    Ok(out)
}

fn check_password(password: &[u8]) -> Result<String<MAX_PASSWORD_LEN>, SettingsError> {
    let len = password.len();
    let bad = SettingsError::BadPassword { len };
    let ok = match len {
        0 => true,
        MIN_PASSPHRASE_LEN..=63 => password.iter().all(|b| (b' '..=b'~').contains(b)),
        MAX_PASSWORD_LEN => password.iter().all(u8::is_ascii_hexdigit),
        _ => false,
    };
    if !ok {
        return Err(bad);
    }
    let text = core::str::from_utf8(password).map_err(|_| bad)?;
    let mut out = String::new();
    out.push_str(text).map_err(|_| bad)?;
    Ok(out)
}

/// A TCP port the Basic can listen on: never 0.
fn check_port(port: u16) -> Result<u16, SettingsError> {
    if port == 0 {
        Err(SettingsError::PortZero)
    } else {
        Ok(port)
    }
}

/// Everything the Basic keeps about Wi-Fi. No credentials means Wi-Fi is off.
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct WifiSettings {
    credentials: Option<Credentials>,
    port: u16,
}

impl Default for WifiSettings {
    fn default() -> Self {
        Self::new()
    }
}

impl WifiSettings {
    /// The settings of a Basic never configured: Wi-Fi off, port [`DEFAULT_PORT`].
    pub const fn new() -> Self {
        Self {
            credentials: None,
            port: DEFAULT_PORT,
        }
    }

    /// The network to join, if one is set.
    pub fn credentials(&self) -> Option<&Credentials> {
        self.credentials.as_ref()
    }

    /// The TCP port to listen on: never 0.
    pub fn port(&self) -> u16 {
        self.port
    }

    /// These settings with `credentials` instead.
    pub fn with_credentials(self, credentials: Option<Credentials>) -> Self {
        Self {
            credentials,
            ..self
        }
    }

    /// These settings with `port` instead; port 0 is refused.
    pub fn with_port(self, port: u16) -> Result<Self, SettingsError> {
        Ok(Self {
            port: check_port(port)?,
            ..self
        })
    }

    /// The 0xB1 answer: `ssid: <ssid> password: <password>` (see the [module doc](self)).
    pub fn get_text(&self) -> Vec<u8, MAX_GET_TEXT> {
        let (ssid, password) = self
            .credentials
            .as_ref()
            .map_or(("", ""), |c| (c.ssid(), c.password()));
        let mut text = Vec::new();
        for part in [GET_TEXT_SSID, ssid, GET_TEXT_PASSWORD, password] {
            // Cannot fail: MAX_GET_TEXT is the sum of the longest parts.
            let _ = text.extend_from_slice(part.as_bytes());
        }
        text
    }

    /// The flash record: version, SSID length (0: no credentials) and bytes, password length
    /// and bytes, port big-endian.
    pub fn encode(&self) -> Vec<u8, MAX_RECORD> {
        let (ssid, password) = self
            .credentials
            .as_ref()
            .map_or(("", ""), |c| (c.ssid(), c.password()));
        let mut record = Vec::new();
        // Cannot fail: MAX_RECORD is the sum of the longest parts; the lengths fit a byte.
        let _ = record.push(RECORD_VERSION);
        for part in [ssid, password] {
            let _ = record.push(part.len() as u8);
            let _ = record.extend_from_slice(part.as_bytes());
        }
        let _ = record.extend_from_slice(&self.port.to_be_bytes());
        record
    }

    /// Settings read back from a flash record, checked like new ones.
    pub fn decode(record: &[u8]) -> Result<Self, SettingsError> {
        let mut reader = Reader(record);
        if reader.take(1)? != [RECORD_VERSION] {
            return Err(SettingsError::BadRecord);
        }
        let ssid_len = reader.byte()?;
        let ssid = reader.take(usize::from(ssid_len))?;
        let password_len = reader.byte()?;
        let password = reader.take(usize::from(password_len))?;
        let port = reader.take(2)?;
        if !reader.0.is_empty() {
            return Err(SettingsError::BadRecord);
        }
        let credentials = match (ssid, password) {
            ([], []) => None,
            _ => Some(Credentials::new(ssid, password).map_err(|_| SettingsError::BadRecord)?),
        };
        let port = u16::from_be_bytes([
            port.first().copied().unwrap_or(0),
            port.get(1).copied().unwrap_or(0),
        ]);
        Self::new()
            .with_credentials(credentials)
            .with_port(port)
            .map_err(|_| SettingsError::BadRecord)
    }
}

/// Reads a record front to back; running out is a [`SettingsError::BadRecord`].
struct Reader<'a>(&'a [u8]);

impl<'a> Reader<'a> {
    fn take(&mut self, n: usize) -> Result<&'a [u8], SettingsError> {
        if n > self.0.len() {
            return Err(SettingsError::BadRecord);
        }
        let (head, tail) = self.0.split_at(n);
        self.0 = tail;
        Ok(head)
    }

    fn byte(&mut self) -> Result<u8, SettingsError> {
        self.take(1)?
            .first()
            .copied()
            .ok_or(SettingsError::BadRecord)
    }
}

/// Credentials from the 0xB0 text `'ssid'(password)`: it must start with `'` and end with `)`;
/// the SSID ends at the first `'(` (so an SSID containing `'(` cannot be set this way, a
/// password may contain anything a passphrase may).
pub fn parse_set_text(text: &[u8]) -> Result<Credentials, SettingsError> {
    if text.len() > MAX_SET_TEXT {
        return Err(SettingsError::TextTooLong);
    }
    let inner = text
        .strip_prefix(b"'")
        .and_then(|t| t.strip_suffix(b")"))
        .ok_or(SettingsError::BadLayout)?;
    let split = inner
        .windows(2)
        .position(|w| w == b"'(")
        .ok_or(SettingsError::BadLayout)?;
    let (ssid, rest) = inner.split_at(split);
    let password = rest.get(2..).ok_or(SettingsError::BadLayout)?;
    Credentials::new(ssid, password)
}

/// The port of a 0xB2 request's data: two bytes, big-endian, not 0.
pub fn parse_port(data: &[u8]) -> Result<u16, SettingsError> {
    match data {
        [hi, lo] => check_port(u16::from_be_bytes([*hi, *lo])),
        _ => Err(SettingsError::BadLayout),
    }
}

/// How long a [`SetTextCapture`] waits for the text to begin after the announcing frame, in
/// microseconds. pymycobot sends it 20 to 150 ms later; after this the link is framed again.
pub const SET_TEXT_START_TIMEOUT_US: u64 = 1_000_000;

/// What a [`SetTextCapture`] made of a byte.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Captured {
    /// The byte is part of the text.
    Taken,
    /// The byte cannot begin the text (only `'` can): the capture is over, and the byte belongs
    /// to the link's framer.
    NotText,
}

/// How a [`SetTextCapture`] ended.
#[derive(Clone, Debug, PartialEq, Eq)]
pub enum SetTextEnd {
    /// The text, complete and not longer than [`MAX_SET_TEXT`]: parse it with
    /// [`parse_set_text`].
    Text(Vec<u8, MAX_SET_TEXT>),
    /// More than [`MAX_SET_TEXT`] bytes arrived (all of them were swallowed): refuse with `00`.
    TooLong,
    /// Nothing arrived within [`SET_TEXT_START_TIMEOUT_US`]: no answer is due.
    NoText,
}

/// One link's wait for the bare 0xB0 text after the announcing frame `FE FE 02 B0 FA`. Bounded:
/// at most [`MAX_SET_TEXT`] bytes are kept. The link's bytes go here instead of to its framer
/// until [`Self::poll`] says how it ended or [`Self::push`] returns [`Captured::NotText`].
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct SetTextCapture {
    text: Vec<u8, MAX_SET_TEXT>,
    overflowed: bool,
    started_us: u64,
    last_byte_us: u64,
    end_gap_us: u64,
}

impl SetTextCapture {
    /// A capture started at `now_us` (when the announcing frame was answered). The text is
    /// complete once its link has been quiet for `end_gap_us`: the link's frame gap (2 ms on
    /// the 115200 baud serial line; more for a network link, whose bytes come in bursts).
    pub fn new(now_us: u64, end_gap_us: u64) -> Self {
        Self {
            text: Vec::new(),
            overflowed: false,
            started_us: now_us,
            last_byte_us: now_us,
            end_gap_us,
        }
    }

    /// Takes a byte received at `now_us`.
    pub fn push(&mut self, now_us: u64, byte: u8) -> Captured {
        if self.text.is_empty() && !self.overflowed && byte != b'\'' {
            return Captured::NotText;
        }
        self.last_byte_us = now_us;
        if self.text.push(byte).is_err() {
            self.overflowed = true;
        }
        Captured::Taken
    }

    /// How the capture ended, once it has: the link was quiet long enough after the text, or
    /// the text never began.
    pub fn poll(&mut self, now_us: u64) -> Option<SetTextEnd> {
        let begun = self.overflowed || !self.text.is_empty();
        if !begun {
            let waited = now_us.saturating_sub(self.started_us);
            return (waited >= SET_TEXT_START_TIMEOUT_US).then_some(SetTextEnd::NoText);
        }
        if now_us.saturating_sub(self.last_byte_us) < self.end_gap_us {
            return None;
        }
        Some(if self.overflowed {
            SetTextEnd::TooLong
        } else {
            SetTextEnd::Text(core::mem::take(&mut self.text))
        })
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn creds(ssid: &str, password: &str) -> Credentials {
        Credentials::new(ssid.as_bytes(), password.as_bytes()).unwrap()
    }

    /// What pymycobot's `_process_received` makes of a 0xB1 answer.
    fn pymycobot_reads(text: &[u8]) -> (std::string::String, std::string::String) {
        let text = std::str::from_utf8(text).unwrap();
        let parts: std::vec::Vec<&str> = text.split(' ').collect();
        (parts[1].to_owned(), parts[parts.len() - 1].to_owned())
    }

    #[test]
    fn pymycobots_set_text_is_parsed() {
        // set_ssid_pwd("robots", "12345678") writes exactly these bytes after FE FE 02 B0 FA.
        let c = parse_set_text(b"'robots'(12345678)").unwrap();
        assert_eq!((c.ssid(), c.password()), ("robots", "12345678"));
        let c = parse_set_text("'Café Wi-Fi'(pa'(ss) ()')".as_bytes()).unwrap();
        assert_eq!((c.ssid(), c.password()), ("Café Wi-Fi", "pa'(ss) ()'"));
        let c = parse_set_text(b"'open'()").unwrap();
        assert!(c.is_open());
    }

    #[test]
    fn a_set_text_in_another_shape_is_refused() {
        for text in [
            &b"robots(12345678)"[..],
            b"'robots'12345678",
            b"'robots'(12345678",
            b"'robots(12345678)",
            b"",
            b"')",
            b"\xFE\xFE\x02\xB0\xFA",
        ] {
            assert_eq!(
                parse_set_text(text),
                Err(SettingsError::BadLayout),
                "{text:?}"
            );
        }
    }

    #[test]
    fn bad_credentials_are_refused() {
        assert_eq!(
            parse_set_text(b"''(12345678)"),
            Err(SettingsError::SsidEmpty)
        );
        let long = format!("'{}'(12345678)", "s".repeat(33));
        assert_eq!(
            parse_set_text(long.as_bytes()),
            Err(SettingsError::SsidTooLong { len: 33 })
        );
        let longest = format!("'{}'({})", "s".repeat(32), "a".repeat(64));
        assert!(parse_set_text(longest.as_bytes()).is_ok());
        let too_long = format!("'{}'({})", "s".repeat(32), "a".repeat(65));
        assert_eq!(
            parse_set_text(too_long.as_bytes()),
            Err(SettingsError::TextTooLong)
        );
        assert_eq!(
            Credentials::new(b"net", &[b'a'; 65]),
            Err(SettingsError::BadPassword { len: 65 })
        );
        assert_eq!(
            Credentials::new(b"net", b"short"),
            Err(SettingsError::BadPassword { len: 5 })
        );
        // 64 characters must be a hexadecimal key.
        assert_eq!(
            Credentials::new(b"net", &[b'g'; 64]),
            Err(SettingsError::BadPassword { len: 64 })
        );
        assert!(Credentials::new(b"net", &[b'F'; 64]).is_ok());
        assert_eq!(
            Credentials::new(b"net", "pässwort1".as_bytes()),
            Err(SettingsError::BadPassword { len: 10 })
        );
        assert_eq!(
            Credentials::new(b"a\nb", b"12345678"),
            Err(SettingsError::SsidNotText)
        );
        assert_eq!(
            Credentials::new(b"\xFF\xFE", b"12345678"),
            Err(SettingsError::SsidNotText)
        );
    }

    #[test]
    fn get_text_is_what_pymycobot_splits() {
        let none = WifiSettings::new();
        assert_eq!(none.get_text().as_slice(), b"ssid:  password: ");
        assert_eq!(pymycobot_reads(&none.get_text()), ("".into(), "".into()));
        let set = WifiSettings::new().with_credentials(Some(creds("robots", "12345678")));
        assert_eq!(
            set.get_text().as_slice(),
            b"ssid: robots password: 12345678"
        );
        assert_eq!(
            pymycobot_reads(&set.get_text()),
            ("robots".into(), "12345678".into())
        );
        let longest = creds(&"s".repeat(32), &"A".repeat(64));
        let text = WifiSettings::new()
            .with_credentials(Some(longest))
            .get_text();
        assert_eq!(text.len(), MAX_GET_TEXT);
    }

    #[test]
    fn the_port_is_big_endian_and_never_zero() {
        // set_server_port(9000): FE FE 04 B2 23 28 FA.
        assert_eq!(parse_port(&[0x23, 0x28]), Ok(9000));
        assert_eq!(parse_port(&[0xFF, 0xFF]), Ok(65535));
        assert_eq!(parse_port(&[0, 0]), Err(SettingsError::PortZero));
        assert_eq!(parse_port(&[0x23]), Err(SettingsError::BadLayout));
        assert_eq!(parse_port(&[0, 0x23, 0x28]), Err(SettingsError::BadLayout));
        assert_eq!(
            WifiSettings::new().with_port(0),
            Err(SettingsError::PortZero)
        );
        assert_eq!(WifiSettings::new().port(), DEFAULT_PORT);
    }

    #[test]
    fn records_round_trip_and_bad_ones_are_refused() {
        for settings in [
            WifiSettings::new(),
            WifiSettings::new().with_port(1).unwrap(),
            WifiSettings::new().with_credentials(Some(creds("robots", "12345678"))),
            WifiSettings::new()
                .with_credentials(Some(creds(&"s".repeat(32), &"a".repeat(64))))
                .with_port(65535)
                .unwrap(),
        ] {
            let record = settings.encode();
            assert_eq!(WifiSettings::decode(&record), Ok(settings));
        }
        let good = WifiSettings::new()
            .with_credentials(Some(creds("robots", "12345678")))
            .encode();
        // Every truncation, a trailing byte, another version, port 0, a bad password.
        for len in 0..good.len() {
            assert_eq!(
                WifiSettings::decode(&good[..len]),
                Err(SettingsError::BadRecord)
            );
        }
        let mut longer = good.clone();
        longer.push(0).unwrap();
        assert_eq!(WifiSettings::decode(&longer), Err(SettingsError::BadRecord));
        let mut other = good.clone();
        other[0] = 2;
        assert_eq!(WifiSettings::decode(&other), Err(SettingsError::BadRecord));
        assert_eq!(
            WifiSettings::decode(&[1, 0, 0, 0, 0]),
            Err(SettingsError::BadRecord)
        );
        assert_eq!(
            WifiSettings::decode(&[1, 1, b'n', 3, b'a', b'b', b'c', 0x23, 0x28]),
            Err(SettingsError::BadRecord)
        );
    }

    #[test]
    fn the_password_is_not_in_debug_output() {
        let text = format!("{:?}", creds("robots", "secret-pass"));
        assert!(text.contains("robots") && !text.contains("secret"));
    }

    #[test]
    fn a_capture_takes_the_text_until_the_link_is_quiet() {
        let mut capture = SetTextCapture::new(0, 2_000);
        assert_eq!(capture.poll(20_000), None);
        for (i, &b) in b"'robots'(12345678)".iter().enumerate() {
            assert_eq!(capture.push(20_000 + 87 * i as u64, b), Captured::Taken);
        }
        assert_eq!(capture.poll(22_000), None);
        let Some(SetTextEnd::Text(text)) = capture.poll(24_000) else {
            panic!("no text");
        };
        assert_eq!(text.as_slice(), b"'robots'(12345678)");
    }

    #[test]
    fn a_capture_gives_a_frame_back_swallows_an_overlong_text_and_times_out() {
        let mut capture = SetTextCapture::new(0, 2_000);
        assert_eq!(capture.push(10, 0xFE), Captured::NotText);

        let mut capture = SetTextCapture::new(0, 2_000);
        for i in 0..MAX_SET_TEXT as u64 + 10 {
            assert_eq!(capture.push(10 + i, b'\''), Captured::Taken);
        }
        assert_eq!(capture.poll(5_000), Some(SetTextEnd::TooLong));

        let mut capture = SetTextCapture::new(0, 2_000);
        assert_eq!(capture.poll(SET_TEXT_START_TIMEOUT_US - 1), None);
        assert_eq!(
            capture.poll(SET_TEXT_START_TIMEOUT_US),
            Some(SetTextEnd::NoText)
        );
    }
}
