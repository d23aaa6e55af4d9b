//! Records waiting to be written to the Atom's flash until the arm is quiet.
//!
//! A flash erase or write runs with the cache off: the chip stands still for as long as it
//! takes (a 4 KiB sector erase 45 ms typically, 400 ms at worst; a page program 0.4 / 3 ms),
//! and with it the loop, the servo transactions and the answers to the Basic, whose deadline
//! is 400 ms. So a record the host changes (the collision settings, a servo's parameter
//! backup) is in force at once and kept here, in RAM, and the reply does not wait for the
//! flash. [`FlashWrites::write_one`] writes the oldest record once the Atom is quiet
//! ([`crate::Atom`] decides: no request heard for [`QUIET_US`], no motion, no servo
//! transaction or reply under way), one per loop pass.
//!
//! What that costs: a record reaches the flash only after the arm has rested for
//! [`QUIET_US`]. A client that never pauses that long (polling faster than about 50 times a
//! second) postpones it, and a power cut before then loses the change, not the one before it.
//! Only the newest record per key waits, so [`MAX_WAITING`] keys are enough for the Atom's
//! records; a further key is written at once, as before.

use flash_store::{MAX_VALUE, StoreError};
use heapless::Vec;

use crate::store::ParamStore;

/// How long the Atom has heard no request before it writes a waiting record, in us: a ROS
/// node polling at 30 Hz leaves gaps about this long, a client polling flat out none.
pub const QUIET_US: u64 = 20_000;

/// Keys whose newest record can wait: the six joints and the gripper's backups, and the
/// collision settings.
pub const MAX_WAITING: usize = 8;

/// One record waiting: its key and its bytes.
#[derive(Clone, Debug, PartialEq, Eq)]
struct Record {
    key: u8,
    bytes: Vec<u8, MAX_VALUE>,
}

/// The records waiting for a quiet arm, oldest first. See the [module doc](self).
#[derive(Clone, Debug, Default, PartialEq, Eq)]
pub struct FlashWrites {
    waiting: Vec<Record, MAX_WAITING>,
}

impl FlashWrites {
    /// True if every record is in flash.
    pub fn is_empty(&self) -> bool {
        self.waiting.is_empty()
    }

    /// The flash seen through the records waiting: a read finds the newest record, a write
    /// waits here. `None` on a board without a flash.
    pub fn over<'a>(&'a mut self, flash: Option<&'a mut dyn ParamStore>) -> Option<Queued<'a>> {
        flash.map(|flash| Queued {
            writes: self,
            flash,
        })
    }

    /// Writes the oldest waiting record to `flash`: `None` if none waits, else how the write
    /// went. A failed write is not tried again (a broken flash would stall every pass); the
    /// change stays in force until the Atom restarts.
    pub fn write_one(&mut self, flash: &mut dyn ParamStore) -> Option<Result<(), StoreError>> {
        if self.waiting.is_empty() {
            return None;
        }
        let record = self.waiting.remove(0);
        Some(flash.store(record.key, &record.bytes))
    }
}

/// The flash seen through [`FlashWrites`] ([`FlashWrites::over`]).
pub struct Queued<'a> {
    writes: &'a mut FlashWrites,
    flash: &'a mut dyn ParamStore,
}

impl ParamStore for Queued<'_> {
    fn fetch(&mut self, key: u8, into: &mut [u8]) -> Result<Option<usize>, StoreError> {
        let Some(record) = self.writes.waiting.iter().find(|r| r.key == key) else {
            return self.flash.fetch(key, into);
        };
        let slot = into
            .get_mut(..record.bytes.len())
            .ok_or(StoreError::Invalid)?;
        slot.copy_from_slice(&record.bytes);
        Ok(Some(record.bytes.len()))
    }

    fn store(&mut self, key: u8, bytes: &[u8]) -> Result<(), StoreError> {
        let bytes = Vec::from_slice(bytes).map_err(|_| StoreError::Invalid)?;
        let waiting = &mut self.writes.waiting;
        if let Some(record) = waiting.iter_mut().find(|r| r.key == key) {
            record.bytes = bytes;
            return Ok(());
        }
        match waiting.push(Record { key, bytes }) {
            Ok(()) => Ok(()),
            // No room to wait: written now, as a board without the queue would.
            Err(record) => self.flash.store(key, &record.bytes),
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::store::test_support::Memory;

    fn fetch(store: &mut dyn ParamStore, key: u8) -> Option<std::vec::Vec<u8>> {
        let mut out = [0u8; MAX_VALUE];
        let len = store.fetch(key, &mut out).unwrap()?;
        Some(out[..len].to_vec())
    }

    #[test]
    fn a_record_is_read_back_at_once_and_reaches_the_flash_only_when_written() {
        let mut flash = Memory::default();
        flash.store(1, &[1]).unwrap();
        let mut writes = FlashWrites::default();
        let mut queued = writes.over(Some(&mut flash)).unwrap();
        queued.store(1, &[2, 2]).unwrap();
        assert_eq!(fetch(&mut queued, 1), Some(vec![2, 2]));
        assert_eq!(fetch(&mut flash, 1), Some(vec![1]), "not in flash yet");
        assert_eq!(writes.write_one(&mut flash), Some(Ok(())));
        assert_eq!(fetch(&mut flash, 1), Some(vec![2, 2]));
        assert!(writes.is_empty());
        assert_eq!(writes.write_one(&mut flash), None);
    }

    #[test]
    fn only_the_newest_record_per_key_waits_and_the_oldest_key_goes_first() {
        let mut flash = Memory::default();
        let mut writes = FlashWrites::default();
        let mut queued = writes.over(Some(&mut flash)).unwrap();
        for value in 0..50u8 {
            queued.store(0xFF, &[value]).unwrap();
            queued.store(3, &[value, value]).unwrap();
        }
        assert_eq!(writes.waiting.len(), 2);
        assert_eq!(writes.write_one(&mut flash), Some(Ok(())));
        assert_eq!(fetch(&mut flash, 0xFF), Some(vec![49]));
        assert_eq!(fetch(&mut flash, 3), None);
        assert_eq!(writes.write_one(&mut flash), Some(Ok(())));
        assert_eq!(fetch(&mut flash, 3), Some(vec![49, 49]));
    }

    #[test]
    fn a_key_beyond_the_room_is_written_at_once() {
        let mut flash = Memory::default();
        let mut writes = FlashWrites::default();
        let mut queued = writes.over(Some(&mut flash)).unwrap();
        for key in 0..=MAX_WAITING as u8 {
            queued.store(key, &[key]).unwrap();
        }
        assert_eq!(
            fetch(&mut flash, MAX_WAITING as u8),
            Some(vec![MAX_WAITING as u8])
        );
        assert_eq!(fetch(&mut flash, 0), None, "the first ones wait");
    }

    #[test]
    fn a_record_too_long_for_the_flash_is_refused_and_no_flash_means_no_store() {
        let mut flash = Memory::default();
        let mut writes = FlashWrites::default();
        let mut queued = writes.over(Some(&mut flash)).unwrap();
        assert_eq!(
            queued.store(1, &[0; MAX_VALUE + 1]),
            Err(StoreError::Invalid)
        );
        assert!(writes.is_empty());
        assert!(writes.over(None).is_none());
    }

    #[test]
    fn a_failed_write_is_reported_and_not_tried_again() {
        struct Broken;
        impl ParamStore for Broken {
            fn fetch(&mut self, _: u8, _: &mut [u8]) -> Result<Option<usize>, StoreError> {
                Ok(None)
            }
            fn store(&mut self, _: u8, _: &[u8]) -> Result<(), StoreError> {
                Err(StoreError::Flash)
            }
        }
        let mut writes = FlashWrites::default();
        writes
            .over(Some(&mut Broken))
            .unwrap()
            .store(1, &[1])
            .unwrap();
        assert_eq!(writes.write_one(&mut Broken), Some(Err(StoreError::Flash)));
        assert!(writes.is_empty());
    }
}
