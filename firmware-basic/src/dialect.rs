//! The dialect the Basic's clients speak ([`protocol_core::dialect`]): the setting, where it is
//! kept across power cycles, and button C, which switches it.
//!
//! The Basic is where a client's dialect ends: it reads every host link in the dialect in
//! force, translates each request into pymycobot's dialect (the only one the Atom speaks) and
//! each reply back, or drops it where the client expects none. So the setting lives on the
//! Basic alone. It changes three ways: the 0xC5 command (both dialects), holding button C for
//! [`SWITCH_HOLD_US`], and the virtual robot's `--dialect` at start. A change applies from each
//! link's next frame on (a frame already begun is read whole in the dialect it began in, and a
//! request already queued is answered in the dialect it was sent in); it is written to flash
//! once the bus is quiet (a flash write stalls the CPU), and a board without a settings store
//! keeps it until power-off.

use flash_store::StoreError;
use protocol_core::dialect::Dialect;

/// How long button C is held down to switch the dialect: long enough that no brush against
/// it switches.
pub const SWITCH_HOLD_US: u64 = 2_000_000;

/// The `flash_store` key of the dialect record (`'D'`), beside the Wi-Fi settings.
pub const DIALECT_KEY: u8 = b'D';

/// Where the dialect is kept across power cycles (the board's flash, the virtual robot's file).
pub trait DialectStore {
    /// The stored dialect; `None` if none was ever stored.
    fn load_dialect(&mut self) -> Result<Option<Dialect>, StoreError>;
    /// Stores `dialect`, replacing what was stored. All or nothing.
    fn save_dialect(&mut self, dialect: Dialect) -> Result<(), StoreError>;
}

/// The dialect in force, whether flash has it yet, and button C's hold.
#[derive(Debug)]
pub(crate) struct DialectSetting {
    dialect: Dialect,
    /// Changed since it was last written (or read).
    unsaved: bool,
    /// Since when button C has been held, counting toward a switch.
    held_since_us: Option<u64>,
    /// Button C has been released since boot or since its last switch: a hold counts.
    armed: bool,
}

impl DialectSetting {
    /// pymycobot's dialect, until [`Self::boot`] reads the store.
    pub(crate) const fn new() -> Self {
        Self {
            dialect: Dialect::Pymycobot,
            unsaved: false,
            held_since_us: None,
            armed: false,
        }
    }

    /// At boot: `wanted` if given (then kept in the store too), else what the store holds,
    /// else pymycobot's.
    pub(crate) fn boot(&mut self, wanted: Option<Dialect>, store: Option<&mut dyn DialectStore>) {
        let stored = store.and_then(|s| s.load_dialect().ok().flatten());
        self.dialect = wanted.or(stored).unwrap_or_default();
        self.unsaved = wanted.is_some_and(|w| stored != Some(w));
    }

    /// The dialect in force.
    pub(crate) fn get(&self) -> Dialect {
        self.dialect
    }

    /// Switches to `dialect`; true if that is a change.
    pub(crate) fn set(&mut self, dialect: Dialect) -> bool {
        let changed = dialect != self.dialect;
        if changed {
            self.dialect = dialect;
            self.unsaved = true;
        }
        changed
    }

    /// Button C at `now_us`: held for [`SWITCH_HOLD_US`] it switches to the other dialect, once
    /// per press (a button held since boot counts only after a release). True if it switched.
    pub(crate) fn on_button(&mut self, now_us: u64, pressed: bool) -> bool {
        if !pressed {
            self.armed = true;
            self.held_since_us = None;
            return false;
        }
        if !self.armed {
            return false;
        }
        let since = *self.held_since_us.get_or_insert(now_us);
        if now_us.saturating_sub(since) < SWITCH_HOLD_US {
            return false;
        }
        self.armed = false;
        self.held_since_us = None;
        self.set(match self.dialect {
            Dialect::Pymycobot => Dialect::Seed,
            Dialect::Seed => Dialect::Pymycobot,
        })
    }

    /// Writes a change not yet in `store` while the bus is `quiet`; what the write did, if it
    /// was made. Without a store the change stays in RAM.
    pub(crate) fn save_when_quiet(
        &mut self,
        quiet: bool,
        store: Option<&mut dyn DialectStore>,
    ) -> Option<Result<(), StoreError>> {
        if !self.unsaved || !quiet {
            return None;
        }
        self.unsaved = false;
        store.map(|s| s.save_dialect(self.dialect))
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[derive(Default)]
    struct Store {
        held: Option<Dialect>,
        writes: u32,
    }

    impl DialectStore for Store {
        fn load_dialect(&mut self) -> Result<Option<Dialect>, StoreError> {
            Ok(self.held)
        }

        fn save_dialect(&mut self, dialect: Dialect) -> Result<(), StoreError> {
            self.held = Some(dialect);
            self.writes += 1;
            Ok(())
        }
    }

    #[test]
    fn boot_takes_the_wanted_dialect_then_the_stored_one_then_pymycobot() {
        let mut setting = DialectSetting::new();
        setting.boot(None, None);
        assert_eq!(setting.get(), Dialect::Pymycobot);
        let mut store = Store {
            held: Some(Dialect::Seed),
            writes: 0,
        };
        setting.boot(None, Some(&mut store));
        assert_eq!(setting.get(), Dialect::Seed);
        assert_eq!(setting.save_when_quiet(true, Some(&mut store)), None);
        setting.boot(Some(Dialect::Pymycobot), Some(&mut store));
        assert_eq!(setting.get(), Dialect::Pymycobot);
        assert_eq!(
            setting.save_when_quiet(true, Some(&mut store)),
            Some(Ok(()))
        );
        assert_eq!(store.held, Some(Dialect::Pymycobot));
    }

    #[test]
    fn a_change_is_written_once_and_only_on_a_quiet_bus() {
        let mut setting = DialectSetting::new();
        let mut store = Store::default();
        setting.boot(None, Some(&mut store));
        assert!(setting.set(Dialect::Seed));
        assert!(!setting.set(Dialect::Seed));
        assert_eq!(setting.save_when_quiet(false, Some(&mut store)), None);
        assert_eq!(
            setting.save_when_quiet(true, Some(&mut store)),
            Some(Ok(()))
        );
        assert_eq!(setting.save_when_quiet(true, Some(&mut store)), None);
        assert_eq!((store.held, store.writes), (Some(Dialect::Seed), 1));
    }

    #[test]
    fn button_c_switches_after_a_two_second_hold_once_per_press() {
        let mut setting = DialectSetting::new();
        // Held since boot: does not count until released.
        assert!(!setting.on_button(0, true));
        assert!(!setting.on_button(3_000_000, true));
        assert!(!setting.on_button(3_100_000, false));
        // A short press does nothing.
        assert!(!setting.on_button(4_000_000, true));
        assert!(!setting.on_button(5_900_000, true));
        assert!(!setting.on_button(5_950_000, false));
        assert_eq!(setting.get(), Dialect::Pymycobot);
        // Two seconds: one switch, however long it is held after.
        assert!(!setting.on_button(6_000_000, true));
        assert!(setting.on_button(8_000_000, true));
        assert!(!setting.on_button(12_000_000, true));
        assert_eq!(setting.get(), Dialect::Seed);
        assert!(!setting.on_button(12_100_000, false));
        assert!(!setting.on_button(13_000_000, true));
        assert!(setting.on_button(15_000_000, true));
        assert_eq!(setting.get(), Dialect::Pymycobot);
    }
}
