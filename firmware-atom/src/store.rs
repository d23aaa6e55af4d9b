//! The Atom's flash: small records under one-byte keys that survive a power cycle, kept by
//! `flash_store` (wear-levelled, an interrupted write leaves the previous record readable).
//!
//! Keys: a servo's bus id (1..=253) holds its parameter backup ([`crate::backup`]);
//! [`COLLISION_SETTINGS_KEY`] holds the collision settings ([`crate::collision`]).

use core::ops::Range;

use embedded_storage::nor_flash::NorFlash;
use flash_store::{FlashRange, StoreError};

/// The key of the collision settings: 255, never a servo's id.
pub const COLLISION_SETTINGS_KEY: u8 = 0xFF;

/// Where the Atom keeps records; the board lends one through
/// [`crate::AtomIo::param_store`].
pub trait ParamStore {
    /// Reads the record under `key` into `into`: its length, or `None` if there is none.
    fn fetch(&mut self, key: u8, into: &mut [u8]) -> Result<Option<usize>, StoreError>;
    /// Stores `bytes` under `key`, replacing an older record.
    fn store(&mut self, key: u8, bytes: &[u8]) -> Result<(), StoreError>;
}

/// Records in a range of NOR flash, through [`flash_store::FlashStore`]. The board binds it to
/// the Atom's flash (esp-storage), the virtual robot and the tests to
/// [`flash_store::MemFlash`].
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct FlashParams<F> {
    region: FlashRange<F>,
}

impl<F: NorFlash> FlashParams<F> {
    /// Records kept in `range` of `flash` (whole erase pages, at least two).
    pub fn new(flash: F, range: Range<u32>) -> Self {
        Self {
            region: FlashRange::new(flash, range),
        }
    }

    /// The flash, for a look at what is stored (tests, saving the virtual robot's flash).
    pub fn flash(&self) -> Option<&F> {
        self.region.flash()
    }
}

impl<F: NorFlash> ParamStore for FlashParams<F> {
    fn fetch(&mut self, key: u8, into: &mut [u8]) -> Result<Option<usize>, StoreError> {
        self.region.with_store(|store| store.fetch(key, into))
    }

    fn store(&mut self, key: u8, bytes: &[u8]) -> Result<(), StoreError> {
        self.region.with_store(|store| store.store(key, bytes))
    }
}

/// Records kept in memory, for the parts' unit tests.
#[cfg(test)]
pub mod test_support {
    use super::*;

    /// Records in a `Vec`, the newest under each key.
    #[derive(Default)]
    pub struct Memory(std::vec::Vec<(u8, std::vec::Vec<u8>)>);

    impl ParamStore for Memory {
        fn fetch(&mut self, key: u8, into: &mut [u8]) -> Result<Option<usize>, StoreError> {
            let Some((_, bytes)) = self.0.iter().find(|(k, _)| *k == key) else {
                return Ok(None);
            };
            let slot = into.get_mut(..bytes.len()).ok_or(StoreError::Invalid)?;
            slot.copy_from_slice(bytes);
            Ok(Some(bytes.len()))
        }

        fn store(&mut self, key: u8, bytes: &[u8]) -> Result<(), StoreError> {
            self.0.retain(|(k, _)| *k != key);
            self.0.push((key, bytes.to_vec()));
            Ok(())
        }
    }
}
