//! NOR flash in RAM, for host tests and the virtual robot: erased bytes read `FF`, a write can
//! only clear bits, erases go by 4 KiB pages (like the ESP32's flash) and are counted.

use embedded_storage::nor_flash::{
    ErrorType, NorFlash, NorFlashError, NorFlashErrorKind, ReadNorFlash,
};

/// Erase page size, bytes (the ESP32's flash sector).
const PAGE: usize = 4096;

/// Program page size, bytes: a NOR flash programs at most one such page per operation.
pub const PROGRAM_PAGE: usize = 256;

/// `SIZE` bytes of NOR flash in RAM. See the [module doc](self).
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct MemFlash<const SIZE: usize> {
    bytes: [u8; SIZE],
    erases: [u32; 64],
    programs: u32,
    fail_writes: bool,
}

/// Why a [`MemFlash`] operation failed.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum MemFlashError {
    /// Outside the flash.
    OutOfBounds,
    /// Not aligned to the word or page size.
    NotAligned,
    /// A write was made to fail ([`MemFlash::fail_writes`]).
    WriteFailed,
}

impl NorFlashError for MemFlashError {
    fn kind(&self) -> NorFlashErrorKind {
        match self {
            Self::OutOfBounds => NorFlashErrorKind::OutOfBounds,
            Self::NotAligned => NorFlashErrorKind::NotAligned,
            Self::WriteFailed => NorFlashErrorKind::Other,
        }
    }
}

impl<const SIZE: usize> Default for MemFlash<SIZE> {
    fn default() -> Self {
        Self::new()
    }
}

impl<const SIZE: usize> MemFlash<SIZE> {
    /// Erased flash (every byte `FF`).
    pub const fn new() -> Self {
        Self {
            bytes: [0xFF; SIZE],
            erases: [0; 64],
            programs: 0,
            fail_writes: false,
        }
    }

    /// Flash holding `image` (e.g. read back from a file); bytes past it are erased.
    pub fn from_image(image: &[u8]) -> Self {
        let mut flash = Self::new();
        let n = image.len().min(SIZE);
        if let (Some(to), Some(from)) = (flash.bytes.get_mut(..n), image.get(..n)) {
            to.copy_from_slice(from);
        }
        flash
    }

    /// The flash's contents (e.g. to save them to a file).
    pub fn image(&self) -> &[u8] {
        &self.bytes
    }

    /// Makes every later write and erase fail (a flash at the end of its life, a brown-out).
    pub fn fail_writes(&mut self, fail: bool) {
        self.fail_writes = fail;
    }

    /// How often each page was erased.
    pub fn erase_counts(&self) -> &[u32] {
        self.erases.get(..SIZE / PAGE).unwrap_or(&[])
    }

    /// Page programs so far: a write takes one per [`PROGRAM_PAGE`]-byte page it touches (the
    /// time a chip spends on a write goes by these). Wraps.
    pub fn program_count(&self) -> u32 {
        self.programs
    }

    fn span(&self, offset: u32, len: usize) -> Result<core::ops::Range<usize>, MemFlashError> {
        let start = offset as usize;
        let end = start.checked_add(len).ok_or(MemFlashError::OutOfBounds)?;
        if end > SIZE {
            return Err(MemFlashError::OutOfBounds);
        }
        Ok(start..end)
    }
}

impl<const SIZE: usize> ErrorType for MemFlash<SIZE> {
    type Error = MemFlashError;
}

impl<const SIZE: usize> ReadNorFlash for MemFlash<SIZE> {
    const READ_SIZE: usize = 1;

    fn read(&mut self, offset: u32, bytes: &mut [u8]) -> Result<(), Self::Error> {
        let span = self.span(offset, bytes.len())?;
        let from = self.bytes.get(span).ok_or(MemFlashError::OutOfBounds)?;
        bytes.copy_from_slice(from);
        Ok(())
    }

    fn capacity(&self) -> usize {
        SIZE
    }
}

impl<const SIZE: usize> NorFlash for MemFlash<SIZE> {
    const WRITE_SIZE: usize = 4;
    const ERASE_SIZE: usize = PAGE;

    fn erase(&mut self, from: u32, to: u32) -> Result<(), Self::Error> {
        if self.fail_writes {
            return Err(MemFlashError::WriteFailed);
        }
        if !(from as usize).is_multiple_of(PAGE) || !(to as usize).is_multiple_of(PAGE) || to < from
        {
            return Err(MemFlashError::NotAligned);
        }
        let span = self.span(from, (to - from) as usize)?;
        for page in span.start / PAGE..span.end / PAGE {
            if let Some(count) = self.erases.get_mut(page) {
                *count += 1;
            }
        }
        self.bytes
            .get_mut(span)
            .ok_or(MemFlashError::OutOfBounds)?
            .fill(0xFF);
        Ok(())
    }

    fn write(&mut self, offset: u32, bytes: &[u8]) -> Result<(), Self::Error> {
        if self.fail_writes {
            return Err(MemFlashError::WriteFailed);
        }
        if !(offset as usize).is_multiple_of(Self::WRITE_SIZE)
            || !bytes.len().is_multiple_of(Self::WRITE_SIZE)
        {
            return Err(MemFlashError::NotAligned);
        }
        let span = self.span(offset, bytes.len())?;
        if !span.is_empty() {
            let pages = (span.end - 1) / PROGRAM_PAGE - span.start / PROGRAM_PAGE + 1;
            // pages <= SIZE / PROGRAM_PAGE; a wrap of the statistics counter is harmless.
            self.programs = self.programs.wrapping_add(pages as u32);
        }
        let to = self.bytes.get_mut(span).ok_or(MemFlashError::OutOfBounds)?;
        // NOR flash: a write can only clear bits.
        for (t, b) in to.iter_mut().zip(bytes) {
            *t &= *b;
        }
        Ok(())
    }
}
