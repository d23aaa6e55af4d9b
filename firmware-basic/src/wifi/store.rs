//! Where the Wi-Fi settings live across power cycles, and the one place they are changed.
//!
//! * [`WifiStore`]: the tiny storage trait (load, save the whole [`WifiSettings`]).
//! * [`FlashWifiStore`]: the settings as one record ([`WifiSettings::encode`]) under
//!   [`SETTINGS_KEY`] in a `flash_store::FlashStore` (through a `flash_store::FlashRange`) (sequential-storage's wear-levelling map)
//!   over any embedded-storage NOR flash: esp-storage on the board, `flash_store::MemFlash` in
//!   the tests and the virtual robot. A write is all or nothing: an interrupted or failed one
//!   leaves the previous record readable.
//! * [`WifiConfig`]: the settings in RAM plus their store. A change is written first and taken
//!   into RAM only once the write succeeded, so a failed write changes nothing, and a change
//!   to what is already set writes nothing (the flash is not worn by clients that set the same
//!   network at every start).
//!
//! A write costs one flash page program, and now and then (once the store's current page is
//! full: every few dozen writes) a 4 KiB erase, which blocks the CPU for tens of milliseconds
//! on the ESP32; settings change only when a client asks.

use core::ops::Range;

use embedded_storage::nor_flash::NorFlash;
use flash_store::{FlashRange, StoreError};

use super::config::{Credentials, MAX_RECORD, SettingsError, WifiSettings};

/// The `flash_store` key of the Wi-Fi settings record (`'W'`).
pub const SETTINGS_KEY: u8 = b'W';

/// Where the Wi-Fi settings are kept.
pub trait WifiStore {
    /// The stored settings; `None` if none were ever stored.
    fn load(&mut self) -> Result<Option<WifiSettings>, LoadError>;
    /// Stores `settings`, replacing what was stored. All or nothing.
    fn save(&mut self, settings: &WifiSettings) -> Result<(), StoreError>;
}

/// Why stored settings could not be read.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum LoadError {
    /// The flash store failed.
    Store(StoreError),
    /// The record is there but unreadable ([`SettingsError::BadRecord`]).
    Record(SettingsError),
}

/// The Wi-Fi settings in a range of NOR flash, through [`flash_store::FlashStore`]. See the
/// [module doc](self).
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct FlashWifiStore<F> {
    region: FlashRange<F>,
}

impl<F: NorFlash> FlashWifiStore<F> {
    /// Settings kept in `range` of `flash` (whole erase pages, at least two).
    pub fn new(flash: F, range: Range<u32>) -> Self {
        Self {
            region: FlashRange::new(flash, range),
        }
    }

    /// The flash behind the store (tests; the virtual robot saves it to a file).
    pub fn flash(&self) -> Option<&F> {
        self.region.flash()
    }

    /// The flash, to change it behind the store (tests: a failing flash).
    pub fn flash_mut(&mut self) -> Option<&mut F> {
        self.region.flash_mut()
    }

    /// The flash, given back.
    pub fn into_flash(self) -> Option<F> {
        self.region.into_flash()
    }
}

impl From<StoreError> for LoadError {
    fn from(e: StoreError) -> Self {
        Self::Store(e)
    }
}

impl<F: NorFlash> WifiStore for FlashWifiStore<F> {
    fn load(&mut self) -> Result<Option<WifiSettings>, LoadError> {
        self.region.with_store(|store| {
            let mut record = [0u8; MAX_RECORD];
            match store.fetch(SETTINGS_KEY, &mut record) {
                Ok(Some(len)) => {
                    let record = record
                        .get(..len)
                        .ok_or(LoadError::Store(StoreError::Invalid))?;
                    WifiSettings::decode(record)
                        .map(Some)
                        .map_err(LoadError::Record)
                }
                Ok(None) => Ok(None),
                // A record longer than any we write does not fit `record`.
                Err(StoreError::Invalid) => Err(LoadError::Record(SettingsError::BadRecord)),
                Err(e) => Err(LoadError::Store(e)),
            }
        })
    }

    fn save(&mut self, settings: &WifiSettings) -> Result<(), StoreError> {
        self.region
            .with_store(|store| store.store(SETTINGS_KEY, &settings.encode()))
    }
}

impl<F: NorFlash> crate::dialect::DialectStore for FlashWifiStore<F> {
    fn load_dialect(&mut self) -> Result<Option<protocol_core::dialect::Dialect>, StoreError> {
        self.region.with_store(|store| {
            let mut record = [0u8; 1];
            match store.fetch(crate::dialect::DIALECT_KEY, &mut record)? {
                Some(1) => Ok(protocol_core::dialect::Dialect::from_u8(record[0])),
                _ => Ok(None),
            }
        })
    }

    fn save_dialect(&mut self, dialect: protocol_core::dialect::Dialect) -> Result<(), StoreError> {
        self.region
            .with_store(|store| store.store(crate::dialect::DIALECT_KEY, &[dialect as u8]))
    }
}

/// Why a change of the settings was not made. Either way nothing changed.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum ChangeError {
    /// The new value was refused.
    Invalid(SettingsError),
    /// Writing it to flash failed.
    Store(StoreError),
}

/// What a change did.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Changed {
    /// The value was already set: nothing was written.
    Nothing,
    /// The value was stored and is now in effect.
    Stored,
}

/// The Wi-Fi settings in effect. The store is lent to each call that reads or writes it (on
/// the board it is part of the board's IO, like the Atom's parameter store). See the
/// [module doc](self).
#[derive(Clone, Debug, Default, PartialEq, Eq)]
pub struct WifiConfig {
    settings: WifiSettings,
    load_error: Option<LoadError>,
}

impl WifiConfig {
    /// The settings found in `store`; the defaults (Wi-Fi off, port 9000) if there are none or
    /// they cannot be read ([`Self::load_error`] says why).
    pub fn load<S: WifiStore + ?Sized>(store: &mut S) -> Self {
        match store.load() {
            Ok(found) => Self {
                settings: found.unwrap_or_default(),
                load_error: None,
            },
            Err(e) => Self {
                settings: WifiSettings::new(),
                load_error: Some(e),
            },
        }
    }

    /// The settings in effect.
    pub fn settings(&self) -> &WifiSettings {
        &self.settings
    }

    /// Why the stored settings could not be read at start, if they could not.
    pub fn load_error(&self) -> Option<LoadError> {
        self.load_error
    }

    /// Joins the network `credentials` names from now on, stored in `store` first.
    pub fn set_credentials<S: WifiStore + ?Sized>(
        &mut self,
        store: &mut S,
        credentials: Credentials,
    ) -> Result<Changed, ChangeError> {
        let new = self.settings.clone().with_credentials(Some(credentials));
        self.change(store, new)
    }

    /// Listens on `port` from now on, stored in `store` first; port 0 is refused.
    pub fn set_port<S: WifiStore + ?Sized>(
        &mut self,
        store: &mut S,
        port: u16,
    ) -> Result<Changed, ChangeError> {
        let new = self
            .settings
            .clone()
            .with_port(port)
            .map_err(ChangeError::Invalid)?;
        self.change(store, new)
    }

    fn change<S: WifiStore + ?Sized>(
        &mut self,
        store: &mut S,
        new: WifiSettings,
    ) -> Result<Changed, ChangeError> {
        // Written even when equal if the stored record could not be read: that repairs it.
        if new == self.settings && self.load_error.is_none() {
            return Ok(Changed::Nothing);
        }
        store.save(&new).map_err(ChangeError::Store)?;
        self.settings = new;
        self.load_error = None;
        Ok(Changed::Stored)
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use flash_store::MemFlash;

    const PAGES: usize = 4;
    const RANGE: Range<u32> = 0..(PAGES * 4096) as u32;
    type Flash = MemFlash<{ PAGES * 4096 }>;
    type Store = FlashWifiStore<Flash>;

    fn creds(ssid: &str, password: &str) -> Credentials {
        Credentials::new(ssid.as_bytes(), password.as_bytes()).unwrap()
    }

    /// A Basic with a fresh flash: its store and the settings loaded from it.
    fn fresh() -> (Store, WifiConfig) {
        let mut store = FlashWifiStore::new(Flash::new(), RANGE);
        let config = WifiConfig::load(&mut store);
        (store, config)
    }

    /// A power cycle: a new store over the same flash, and the settings loaded from it.
    fn restart(store: Store) -> (Store, WifiConfig) {
        let mut store = FlashWifiStore::new(store.into_flash().unwrap(), RANGE);
        let config = WifiConfig::load(&mut store);
        (store, config)
    }

    fn flash_mut(store: &mut Store) -> &mut Flash {
        store.flash_mut().unwrap()
    }

    #[test]
    fn a_fresh_flash_means_wifi_off_on_port_9000() {
        let (_, config) = fresh();
        assert_eq!(config.settings(), &WifiSettings::new());
        assert_eq!(config.load_error(), None);
    }

    #[test]
    fn settings_survive_a_power_cycle() {
        let (mut store, mut config) = fresh();
        assert_eq!(
            config.set_credentials(&mut store, creds("robots", "12345678")),
            Ok(Changed::Stored)
        );
        assert_eq!(config.set_port(&mut store, 9100), Ok(Changed::Stored));
        let (_, config) = restart(store);
        let settings = config.settings();
        assert_eq!(settings.credentials(), Some(&creds("robots", "12345678")));
        assert_eq!(settings.port(), 9100);
    }

    #[test]
    fn setting_what_is_set_writes_nothing() {
        let (mut store, mut config) = fresh();
        config
            .set_credentials(&mut store, creds("robots", "12345678"))
            .unwrap();
        let before = store.flash().unwrap().clone();
        assert_eq!(
            config.set_credentials(&mut store, creds("robots", "12345678")),
            Ok(Changed::Nothing)
        );
        assert_eq!(config.set_port(&mut store, 9000), Ok(Changed::Nothing));
        assert_eq!(store.flash().unwrap(), &before);
    }

    #[test]
    fn a_failed_write_is_reported_and_changes_nothing() {
        let (mut store, mut config) = fresh();
        config
            .set_credentials(&mut store, creds("robots", "12345678"))
            .unwrap();
        flash_mut(&mut store).fail_writes(true);
        assert!(matches!(
            config.set_credentials(&mut store, creds("other", "87654321")),
            Err(ChangeError::Store(_))
        ));
        assert!(matches!(
            config.set_port(&mut store, 1234),
            Err(ChangeError::Store(_))
        ));
        let expect = WifiSettings::new().with_credentials(Some(creds("robots", "12345678")));
        assert_eq!(config.settings(), &expect);
        flash_mut(&mut store).fail_writes(false);
        let (_, config) = restart(store);
        assert_eq!(config.settings(), &expect);
    }

    #[test]
    fn port_zero_is_refused_without_a_write() {
        let (mut store, mut config) = fresh();
        let before = store.flash().unwrap().clone();
        assert_eq!(
            config.set_port(&mut store, 0),
            Err(ChangeError::Invalid(SettingsError::PortZero))
        );
        assert_eq!(store.flash().unwrap(), &before);
        assert_eq!(config.settings().port(), 9000);
    }

    #[test]
    fn many_changes_wear_the_pages_evenly_and_keep_the_last() {
        let (mut store, mut config) = fresh();
        for i in 0..1_000u16 {
            let ssid = format!("net{i}");
            config
                .set_credentials(&mut store, creds(&ssid, "12345678"))
                .unwrap();
        }
        let (store, config) = restart(store);
        assert_eq!(
            config.settings().credentials(),
            Some(&creds("net999", "12345678"))
        );
        let erases = store.flash().unwrap().erase_counts();
        let (min, max) = (erases.iter().min().unwrap(), erases.iter().max().unwrap());
        assert!(max - min <= 1, "erases per page: {erases:?}");
    }

    #[test]
    fn an_unreadable_record_means_defaults_until_the_next_change_repairs_it() {
        let mut flash_store = flash_store::FlashStore::new(Flash::new(), RANGE).unwrap();
        flash_store.store(SETTINGS_KEY, &[9, 9, 9]).unwrap();
        let mut store = FlashWifiStore::new(flash_store.into_flash(), RANGE);
        let mut config = WifiConfig::load(&mut store);
        assert_eq!(config.settings(), &WifiSettings::new());
        assert_eq!(
            config.load_error(),
            Some(LoadError::Record(SettingsError::BadRecord))
        );
        // Setting the default port again still writes: the record is repaired.
        assert_eq!(config.set_port(&mut store, 9000), Ok(Changed::Stored));
        let (_, config) = restart(store);
        assert_eq!(config.load_error(), None);
    }

    #[test]
    fn a_flash_range_that_cannot_hold_a_store_is_reported_and_keeps_the_flash() {
        let mut store = FlashWifiStore::new(Flash::new(), 100..200);
        assert_eq!(store.load(), Err(LoadError::Store(StoreError::Invalid)));
        assert_eq!(store.save(&WifiSettings::new()), Err(StoreError::Invalid));
        assert!(store.flash().is_some());
    }

    #[test]
    fn the_store_works_as_a_trait_object() {
        let mut store = FlashWifiStore::new(Flash::new(), RANGE);
        let store: &mut dyn WifiStore = &mut store;
        let mut config = WifiConfig::load(store);
        assert_eq!(config.set_port(store, 1), Ok(Changed::Stored));
        assert_eq!(WifiConfig::load(store).settings().port(), 1);
    }
}
