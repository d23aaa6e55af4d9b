//! A small key-value store in NOR flash, for settings that must survive a power cycle: today
//! the Atom's servo parameter backups and collision settings, and the Basic's Wi-Fi settings.
//!
//! The store is `sequential-storage`'s map: items are appended and old ones erased a page at a
//! time, so the flash wears evenly, and an interrupted write leaves the previous value readable.
//! That crate is async; the flashes here (esp-storage on the boards, [`MemFlash`] on the host)
//! are blocking, so every future completes on its first poll and [`FlashStore`] offers a plain
//! blocking API. No allocation, no unsafe code.
#![cfg_attr(not(test), no_std)]
#![forbid(unsafe_code)]

mod mem;

use core::future::Future;
use core::ops::Range;
use core::pin::pin;
use core::task::{Context, Poll, Waker};

use embedded_storage::nor_flash::{NorFlash, ReadNorFlash};
use sequential_storage::cache::{Cache, Uncached};
use sequential_storage::map::{MapConfig, MapStorage};

pub use mem::{MemFlash, PROGRAM_PAGE};

/// Longest value the store takes, bytes (with its key, the work buffer's size).
pub const MAX_VALUE: usize = 120;

/// Why the store could not do what it was asked.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum StoreError {
    /// The flash reported an error (a failed write or erase).
    Flash,
    /// The flash range is full even after erasing what was overwritten.
    Full,
    /// The flash holds something the store cannot read (it should be erased).
    Corrupted,
    /// The value is longer than [`MAX_VALUE`], or the flash range is not usable.
    Invalid,
}

/// A blocking flash seen through the async traits the map is written against.
struct Blocking<F>(F);

impl<F: embedded_storage::nor_flash::ErrorType> embedded_storage_async::nor_flash::ErrorType
    for Blocking<F>
{
    type Error = F::Error;
}

impl<F: ReadNorFlash> embedded_storage_async::nor_flash::ReadNorFlash for Blocking<F> {
    const READ_SIZE: usize = F::READ_SIZE;

    async fn read(&mut self, offset: u32, bytes: &mut [u8]) -> Result<(), Self::Error> {
        self.0.read(offset, bytes)
    }

    fn capacity(&self) -> usize {
        self.0.capacity()
    }
}

impl<F: NorFlash> embedded_storage_async::nor_flash::NorFlash for Blocking<F> {
    const WRITE_SIZE: usize = F::WRITE_SIZE;
    const ERASE_SIZE: usize = F::ERASE_SIZE;

    async fn erase(&mut self, from: u32, to: u32) -> Result<(), Self::Error> {
        self.0.erase(from, to)
    }

    async fn write(&mut self, offset: u32, bytes: &[u8]) -> Result<(), Self::Error> {
        self.0.write(offset, bytes)
    }
}

/// Most polls of one store operation. The flash is blocking, so one is all it takes; the bound
/// only keeps a wait from being endless.
const MAX_POLLS: usize = 16;

/// Runs `future` (which never waits: the flash behind it is blocking) to its end.
fn complete<T>(future: impl Future<Output = T>) -> Option<T> {
    let mut future = pin!(future);
    let mut cx = Context::from_waker(Waker::noop());
    for _ in 0..MAX_POLLS {
        if let Poll::Ready(value) = future.as_mut().poll(&mut cx) {
            return Some(value);
        }
    }
    None
}

fn error<E>(e: sequential_storage::Error<E>) -> StoreError {
    match e {
        sequential_storage::Error::Storage { .. } => StoreError::Flash,
        sequential_storage::Error::FullStorage => StoreError::Full,
        sequential_storage::Error::Corrupted { .. } => StoreError::Corrupted,
        _ => StoreError::Invalid,
    }
}

/// Values under one-byte keys in a range of NOR flash. See the [crate doc](crate).
pub struct FlashStore<F: NorFlash> {
    map: MapStorage<u8, Blocking<F>, Cache<Uncached, Uncached, Uncached, u8>>,
}

impl<F: NorFlash> FlashStore<F> {
    /// A store in `range` of `flash` (whole erase pages, at least two).
    pub fn new(flash: F, range: Range<u32>) -> Result<Self, StoreError> {
        let config = MapConfig::try_new(range).map_err(|_| StoreError::Invalid)?;
        Ok(Self {
            map: MapStorage::new(Blocking(flash), config, Cache::new_uncached()),
        })
    }

    /// The value stored under `key` copied into `out`; its length, or `None` if there is none.
    pub fn fetch(&mut self, key: u8, out: &mut [u8]) -> Result<Option<usize>, StoreError> {
        let mut buffer = [0u8; MAX_VALUE + 8];
        let found = complete(self.map.fetch_item::<&[u8]>(&mut buffer, &key))
            .ok_or(StoreError::Flash)?
            .map_err(error)?;
        match found {
            None => Ok(None),
            Some(value) => {
                let slot = out.get_mut(..value.len()).ok_or(StoreError::Invalid)?;
                slot.copy_from_slice(value);
                Ok(Some(value.len()))
            }
        }
    }

    /// Stores `value` under `key`, replacing what was there. All or nothing: a failed write
    /// leaves the previous value.
    pub fn store(&mut self, key: u8, value: &[u8]) -> Result<(), StoreError> {
        if value.len() > MAX_VALUE {
            return Err(StoreError::Invalid);
        }
        let mut buffer = [0u8; MAX_VALUE + 8];
        complete(self.map.store_item(&mut buffer, &key, &value))
            .ok_or(StoreError::Flash)?
            .map_err(error)
    }

    /// The flash behind the store, taken back.
    pub fn into_flash(self) -> F {
        self.map.destroy().0.0
    }
}

/// A flash and the range a [`FlashStore`] lives in, the store made afresh for each use: the
/// flash stays here between uses, to be looked at or saved (the virtual robot keeps it in a
/// file). What the Atom's parameter backups and the Basic's Wi-Fi settings are kept in.
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct FlashRange<F> {
    /// Always `Some` between uses; taken while a [`FlashStore`] borrows it.
    flash: Option<F>,
    range: Range<u32>,
}

impl<F: NorFlash> FlashRange<F> {
    /// A store in `range` of `flash` (whole erase pages, at least two; another range makes
    /// every use fail with [`StoreError::Invalid`]).
    pub fn new(flash: F, range: Range<u32>) -> Self {
        Self {
            flash: Some(flash),
            range,
        }
    }

    /// The flash, for a look at what is stored (tests, saving the virtual robot's flash).
    pub fn flash(&self) -> Option<&F> {
        self.flash.as_ref()
    }

    /// The flash, to change it behind the store (tests: a failing flash).
    pub fn flash_mut(&mut self) -> Option<&mut F> {
        self.flash.as_mut()
    }

    /// The flash, given back.
    pub fn into_flash(self) -> Option<F> {
        self.flash
    }

    /// Runs `act` on the store. The flash is kept whatever happens, also when the range is
    /// refused ([`FlashStore::new`] would drop it).
    pub fn with_store<T, E: From<StoreError>>(
        &mut self,
        act: impl FnOnce(&mut FlashStore<F>) -> Result<T, E>,
    ) -> Result<T, E> {
        let page = F::ERASE_SIZE as u32;
        let fits = page > 0
            && self.range.start.is_multiple_of(page)
            && self.range.end.is_multiple_of(page)
            && self.range.end.saturating_sub(self.range.start) >= 2 * page;
        if !fits {
            return Err(StoreError::Invalid.into());
        }
        let flash = self.flash.take().ok_or(StoreError::Flash)?;
        let mut store = FlashStore::new(flash, self.range.clone())?;
        let result = act(&mut store);
        self.flash = Some(store.into_flash());
        result
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    type Flash = MemFlash<{ 4 * 4096 }>;

    #[test]
    fn values_are_stored_replaced_and_survive_a_new_store() {
        let mut store = FlashStore::new(Flash::new(), 0..4 * 4096).unwrap();
        let mut out = [0u8; MAX_VALUE];
        assert_eq!(store.fetch(3, &mut out), Ok(None));
        store.store(3, &[1, 2, 3]).unwrap();
        store.store(3, &[4, 5]).unwrap();
        store.store(7, &[9; 40]).unwrap();
        assert_eq!(store.fetch(3, &mut out), Ok(Some(2)));
        assert_eq!(&out[..2], &[4, 5]);
        // A power cycle: a new store over the same flash.
        let flash = store.into_flash();
        let mut store = FlashStore::new(flash, 0..4 * 4096).unwrap();
        assert_eq!(store.fetch(7, &mut out), Ok(Some(40)));
        assert_eq!(store.fetch(3, &mut out), Ok(Some(2)));
    }

    #[test]
    fn many_writes_wear_the_pages_evenly_and_keep_the_last_value() {
        let mut store = FlashStore::new(Flash::new(), 0..4 * 4096).unwrap();
        for i in 0..2_000u16 {
            store.store((i % 7) as u8, &i.to_le_bytes()).unwrap();
        }
        let mut out = [0u8; 2];
        assert_eq!(store.fetch(6, &mut out), Ok(Some(2)));
        assert_eq!(u16::from_le_bytes(out), 1_999 - (1_999 % 7) + 6 - 7);
        let flash = store.into_flash();
        let erases = flash.erase_counts();
        let (min, max) = (erases.iter().min().unwrap(), erases.iter().max().unwrap());
        assert!(max - min <= 1, "erases per page: {erases:?}");
    }

    #[test]
    fn a_failed_write_is_reported_and_the_old_value_stays() {
        let mut store = FlashStore::new(Flash::new(), 0..4 * 4096).unwrap();
        store.store(1, &[1, 1]).unwrap();
        let mut flash = store.into_flash();
        flash.fail_writes(true);
        let mut store = FlashStore::new(flash, 0..4 * 4096).unwrap();
        assert_eq!(store.store(1, &[2, 2]), Err(StoreError::Flash));
        let mut flash = store.into_flash();
        flash.fail_writes(false);
        let mut store = FlashStore::new(flash, 0..4 * 4096).unwrap();
        let mut out = [0u8; 2];
        assert_eq!(store.fetch(1, &mut out), Ok(Some(2)));
        assert_eq!(out, [1, 1]);
    }

    #[test]
    fn a_flash_range_keeps_its_flash_even_when_the_range_is_refused() {
        let mut range = FlashRange::new(Flash::new(), 0..4 * 4096);
        range.with_store(|s| s.store(1, &[7])).unwrap();
        let mut out = [0u8; 1];
        assert_eq!(range.with_store(|s| s.fetch(1, &mut out)), Ok(Some(1)));
        let mut bad = FlashRange::new(range.into_flash().unwrap(), 100..4096);
        assert_eq!(
            bad.with_store(|s| s.fetch(1, &mut out)),
            Err(StoreError::Invalid)
        );
        assert!(bad.flash().is_some());
    }

    #[test]
    fn a_value_too_long_or_a_bad_range_is_refused() {
        assert!(FlashStore::new(Flash::new(), 100..4096).is_err());
        let mut store = FlashStore::new(Flash::new(), 0..4 * 4096).unwrap();
        assert_eq!(
            store.store(1, &[0; MAX_VALUE + 1]),
            Err(StoreError::Invalid)
        );
    }
}
