//! The Wi-Fi commands the Basic answers (0xB0..0xB2) and the status the LCD shows: [`Wifi`]
//! keeps the settings in effect ([`WifiConfig`]) and the [`Station`] in step, writing a change
//! to the store before it takes effect.

use core::net::Ipv4Addr;

use flash_store::StoreError;
use heapless::{String, Vec};
use protocol_core::Frame;
use protocol_core::command::{Reply, cmd};

use super::config::{self, MAX_GET_TEXT, MAX_SSID_LEN, SetTextEnd, SettingsError, WifiSettings};
use super::connection::{Action, Failure, LinkEvent, Station, StationState};
use super::store::{ChangeError, WifiConfig, WifiStore};

/// The reply to a Wi-Fi command.
#[derive(Clone, Debug, PartialEq, Eq)]
pub enum WifiReply {
    /// A reply frame (`01` / `00`).
    Frame(Frame),
    /// Bare text: the 0xB1 answer.
    Text(Vec<u8, MAX_GET_TEXT>),
}

/// What went wrong with a Wi-Fi command, for the display. The client got `00`.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum WifiError {
    /// The request was refused: nothing changed.
    Refused(SettingsError),
    /// The flash write failed: nothing changed.
    Flash(StoreError),
}

/// The Basic's answer to a Wi-Fi command.
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct WifiAnswer {
    /// What goes back to the client that asked.
    pub reply: WifiReply,
    /// The request was 0xB0's announcing frame: catch that link's next bytes with a
    /// [`SetTextCapture`](super::SetTextCapture) and answer them with [`Wifi::answer_set_text`].
    pub capture_text: bool,
    /// What went wrong, if anything.
    pub error: Option<WifiError>,
}

impl WifiAnswer {
    fn status(code: u8, result: Result<(), WifiError>) -> Self {
        Self {
            reply: WifiReply::Frame(Reply::Byte(u8::from(result.is_ok())).to_frame(code)),
            capture_text: false,
            error: result.err(),
        }
    }
}

/// What the LCD shows about Wi-Fi.
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct WifiStatus {
    /// The network set; `None`: Wi-Fi off.
    pub ssid: Option<String<MAX_SSID_LEN>>,
    /// Where the station is.
    pub state: StationState,
    /// The TCP port clients connect to.
    pub port: u16,
    /// TCP clients connected now.
    pub clients: u8,
    /// Why the station last failed, until it is online again.
    pub last_failure: Option<Failure>,
    /// The stored settings could not be read at start (the defaults are in effect).
    pub settings_unreadable: bool,
}

impl WifiStatus {
    /// The station's address while online.
    pub fn address(&self) -> Option<Ipv4Addr> {
        match self.state {
            StationState::Online { address } => Some(address),
            _ => None,
        }
    }
}

/// The Basic's Wi-Fi: its settings and its station. The flash store is lent to the calls that
/// need it. See the [module doc](super).
#[derive(Clone, Debug)]
pub struct Wifi {
    config: WifiConfig,
    station: Station,
}

impl Wifi {
    /// Wi-Fi at boot (`now_us`): the settings loaded from `store`, the station joining the
    /// network they name (or off).
    pub fn start<S: WifiStore + ?Sized>(now_us: u64, store: &mut S) -> Self {
        let config = WifiConfig::load(store);
        let mut station = Station::new();
        station.set_credentials(now_us, config.settings().credentials());
        Self { config, station }
    }

    /// The settings in effect (the TCP listener follows [`WifiSettings::port`]).
    pub fn settings(&self) -> &WifiSettings {
        self.config.settings()
    }

    /// The station.
    pub fn station(&self) -> &Station {
        &self.station
    }

    /// Answers `frame` at `now_us` if it is a Wi-Fi command (0xB0, 0xB1, 0xB2); `None`
    /// otherwise. A change is written to `store` before it takes effect.
    pub fn answer<S: WifiStore + ?Sized>(
        &mut self,
        now_us: u64,
        frame: &Frame,
        store: &mut S,
    ) -> Option<WifiAnswer> {
        let code = frame.cmd();
        let data = frame.data();
        let answer = match code {
            // The announcing frame: the text follows bare.
            cmd::SET_SSID_PWD if data.is_empty() => WifiAnswer {
                capture_text: true,
                ..WifiAnswer::status(code, Ok(()))
            },
            // A client that frames the text itself.
            cmd::SET_SSID_PWD => WifiAnswer::status(code, self.set_text(now_us, data, store)),
            cmd::GET_SSID_PWD if data.is_empty() => WifiAnswer {
                reply: WifiReply::Text(self.settings().get_text()),
                capture_text: false,
                error: None,
            },
            cmd::GET_SSID_PWD => {
                WifiAnswer::status(code, Err(WifiError::Refused(SettingsError::BadLayout)))
            }
            cmd::SET_SERVER_PORT => {
                let result = config::parse_port(data)
                    .map_err(WifiError::Refused)
                    .and_then(|port| {
                        self.config
                            .set_port(store, port)
                            .map(drop)
                            .map_err(change_error)
                    });
                WifiAnswer::status(code, result)
            }
            _ => return None,
        };
        Some(answer)
    }

    /// Answers the end of a link's [`SetTextCapture`](super::SetTextCapture) at `now_us`: `01`
    /// once the credentials are stored (and being joined), `00` if refused or the flash failed;
    /// `None` if no text came (nothing is due).
    pub fn answer_set_text<S: WifiStore + ?Sized>(
        &mut self,
        now_us: u64,
        end: SetTextEnd,
        store: &mut S,
    ) -> Option<WifiAnswer> {
        let result = match end {
            SetTextEnd::Text(text) => self.set_text(now_us, &text, store),
            SetTextEnd::TooLong => Err(WifiError::Refused(SettingsError::TextTooLong)),
            SetTextEnd::NoText => return None,
        };
        Some(WifiAnswer::status(cmd::SET_SSID_PWD, result))
    }

    fn set_text<S: WifiStore + ?Sized>(
        &mut self,
        now_us: u64,
        text: &[u8],
        store: &mut S,
    ) -> Result<(), WifiError> {
        let credentials = config::parse_set_text(text).map_err(WifiError::Refused)?;
        self.config
            .set_credentials(store, credentials)
            .map_err(change_error)?;
        self.station
            .set_credentials(now_us, self.config.settings().credentials());
        Ok(())
    }

    /// Takes an event from the driver or the DHCP client, received at `now_us`.
    pub fn on_event(&mut self, now_us: u64, event: LinkEvent) {
        self.station.on_event(now_us, event);
    }

    /// The next action for the driver at `now_us`, if any; call until `None`.
    pub fn poll(&mut self, now_us: u64) -> Option<Action> {
        self.station.poll(now_us)
    }

    /// What the LCD shows, with `clients` TCP clients connected.
    pub fn status(&self, clients: u8) -> WifiStatus {
        let settings = self.settings();
        let ssid = settings.credentials().map(|c| {
            let mut ssid = String::new();
            // Cannot fail: an SSID fits MAX_SSID_LEN.
            let _ = ssid.push_str(c.ssid());
            ssid
        });
        WifiStatus {
            ssid,
            state: self.station.state(),
            port: settings.port(),
            clients,
            last_failure: self.station.last_failure(),
            settings_unreadable: self.config.load_error().is_some(),
        }
    }
}

/// True for a Wi-Fi command that may write the settings to flash: 0xB0 with its text framed,
/// 0xB2. (0xB0's announcing frame and 0xB1 only read; the bare text after the announcing frame
/// writes too, see [`Wifi::answer_set_text`].) The Basic runs these when the bus is quiet: a
/// flash erase stalls the CPU for tens of milliseconds.
pub fn writes_settings(frame: &Frame) -> bool {
    match frame.cmd() {
        cmd::SET_SSID_PWD => !frame.data().is_empty(),
        cmd::SET_SERVER_PORT => true,
        _ => false,
    }
}

fn change_error(e: ChangeError) -> WifiError {
    match e {
        ChangeError::Invalid(e) => WifiError::Refused(e),
        ChangeError::Store(e) => WifiError::Flash(e),
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use core::ops::Range;
    use flash_store::MemFlash;

    use crate::wifi::config::SetTextCapture;
    use crate::wifi::store::FlashWifiStore;

    const RANGE: Range<u32> = 0..4 * 4096;
    type Store = FlashWifiStore<MemFlash<{ 4 * 4096 }>>;

    fn store() -> Store {
        FlashWifiStore::new(MemFlash::new(), RANGE)
    }

    fn frame(code: u8, data: &[u8]) -> Frame {
        Frame::new(code, data).unwrap()
    }

    fn bytes(answer: &WifiAnswer) -> std::vec::Vec<u8> {
        match &answer.reply {
            WifiReply::Frame(f) => f.to_bytes().to_vec(),
            WifiReply::Text(t) => t.to_vec(),
        }
    }

    /// What a capture of `text` ends with, as the link would deliver it.
    fn captured(text: &[u8]) -> SetTextEnd {
        let mut capture = SetTextCapture::new(0, 2_000);
        for &b in text {
            assert_eq!(capture.push(100, b), config::Captured::Taken);
        }
        capture.poll(10_000).unwrap()
    }

    const ACK: [u8; 6] = [0xFE, 0xFE, 0x03, 0xB0, 0x01, 0xFA];
    const NAK: [u8; 6] = [0xFE, 0xFE, 0x03, 0xB0, 0x00, 0xFA];

    #[test]
    fn pymycobots_set_ssid_pwd_then_get_ssid_pwd() {
        let mut store = store();
        let mut wifi = Wifi::start(0, &mut store);
        assert_eq!(wifi.poll(0), None);
        // FE FE 02 B0 FA: acknowledged, the text follows.
        let a = wifi.answer(0, &frame(0xB0, &[]), &mut store).unwrap();
        assert_eq!((bytes(&a), a.capture_text), (ACK.to_vec(), true));
        let a = wifi
            .answer_set_text(30_000, captured(b"'robots'(12345678)"), &mut store)
            .unwrap();
        assert_eq!((bytes(&a), a.error), (ACK.to_vec(), None));
        assert!(matches!(wifi.poll(30_000), Some(Action::Join { .. })));
        // FE FE 02 B1 FA: the bare text.
        let a = wifi.answer(0, &frame(0xB1, &[]), &mut store).unwrap();
        assert_eq!(bytes(&a), b"ssid: robots password: 12345678");
        // It survives a restart, and the station joins at boot.
        let mut wifi = Wifi::start(0, &mut store);
        assert!(matches!(wifi.poll(0), Some(Action::Join { .. })));
        assert_eq!(wifi.status(0).ssid.as_deref(), Some("robots"));
    }

    #[test]
    fn a_framed_text_is_answered_at_once() {
        let mut store = store();
        let mut wifi = Wifi::start(0, &mut store);
        let a = wifi
            .answer(0, &frame(0xB0, b"'lab'(abcdefgh)"), &mut store)
            .unwrap();
        assert_eq!((bytes(&a), a.capture_text), (ACK.to_vec(), false));
        assert_eq!(wifi.settings().credentials().unwrap().ssid(), "lab");
    }

    #[test]
    fn bad_input_is_refused_with_00_and_changes_nothing() {
        let mut store = store();
        let mut wifi = Wifi::start(0, &mut store);
        wifi.answer(0, &frame(0xB0, b"'lab'(abcdefgh)"), &mut store);
        let before = (wifi.settings().clone(), store.clone());
        let long_ssid = format!("'{}'(abcdefgh)", "s".repeat(33));
        let long_password = format!("'lab'({})", "p".repeat(64));
        for text in [
            &b"''(abcdefgh)"[..],
            long_ssid.as_bytes(),
            long_password.as_bytes(),
            b"'lab' (abcdefgh)",
        ] {
            let a = wifi.answer_set_text(0, captured(text), &mut store).unwrap();
            assert_eq!(bytes(&a), NAK, "{text:?}");
            assert!(matches!(a.error, Some(WifiError::Refused(_))));
        }
        let a = wifi
            .answer_set_text(0, SetTextEnd::TooLong, &mut store)
            .unwrap();
        assert_eq!(bytes(&a), NAK);
        let a = wifi.answer(0, &frame(0xB2, &[0, 0]), &mut store).unwrap();
        assert_eq!(bytes(&a), [0xFE, 0xFE, 0x03, 0xB2, 0x00, 0xFA]);
        let a = wifi.answer(0, &frame(0xB2, &[0x23]), &mut store).unwrap();
        assert_eq!(bytes(&a), [0xFE, 0xFE, 0x03, 0xB2, 0x00, 0xFA]);
        let a = wifi.answer(0, &frame(0xB1, &[1]), &mut store).unwrap();
        assert_eq!(bytes(&a), [0xFE, 0xFE, 0x03, 0xB1, 0x00, 0xFA]);
        assert_eq!(
            wifi.answer_set_text(0, SetTextEnd::NoText, &mut store),
            None
        );
        assert_eq!((wifi.settings().clone(), store), before);
    }

    #[test]
    fn a_failed_flash_write_answers_00_and_keeps_the_old_settings() {
        let mut store = store();
        let mut wifi = Wifi::start(0, &mut store);
        wifi.answer(0, &frame(0xB0, b"'lab'(abcdefgh)"), &mut store);
        while wifi.poll(0).is_some() {}
        let mut flash = store.into_flash().unwrap();
        flash.fail_writes(true);
        let mut store = FlashWifiStore::new(flash, RANGE);
        let a = wifi
            .answer(0, &frame(0xB0, b"'other'(abcdefgh)"), &mut store)
            .unwrap();
        assert_eq!(bytes(&a), NAK);
        assert!(matches!(a.error, Some(WifiError::Flash(_))));
        let a = wifi
            .answer(0, &frame(0xB2, &[0x23, 0x29]), &mut store)
            .unwrap();
        assert_eq!(bytes(&a), [0xFE, 0xFE, 0x03, 0xB2, 0x00, 0xFA]);
        assert_eq!(wifi.settings().credentials().unwrap().ssid(), "lab");
        assert_eq!(wifi.settings().port(), 9000);
        // The station was not told to join anything new.
        assert_eq!(wifi.poll(0), None);
    }

    #[test]
    fn set_server_port_is_stored_and_shown() {
        let mut store = store();
        let mut wifi = Wifi::start(0, &mut store);
        let a = wifi
            .answer(0, &frame(0xB2, &[0x23, 0x29]), &mut store)
            .unwrap();
        assert_eq!(bytes(&a), [0xFE, 0xFE, 0x03, 0xB2, 0x01, 0xFA]);
        let status = Wifi::start(0, &mut store).status(2);
        assert_eq!(
            (status.port, status.clients, status.ssid, status.state),
            (9001, 2, None, StationState::Off)
        );
    }

    #[test]
    fn other_commands_are_not_wifis() {
        let mut store = store();
        let mut wifi = Wifi::start(0, &mut store);
        for code in [0xA0, 0xB3, 0xC1, 0x20] {
            assert_eq!(wifi.answer(0, &frame(code, &[]), &mut store), None);
        }
    }
}
