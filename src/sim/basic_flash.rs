//! The simulated Basic's flash: where its Wi-Fi settings live, as on the board (the same
//! `FlashWifiStore` over 24 KiB of NOR flash, like the board's `nvs` partition), in RAM and
//! optionally kept in a file so that they survive a restart of the virtual robot.
//!
//! The file is the flash's raw image. It is rewritten whole after each settings change, through
//! a temporary file renamed over it, so it is never half written; if that fails the change is
//! undone in RAM too and reported like a failed flash write (the client gets `00`, nothing
//! changed). A missing file is an erased flash.

use std::fs;
use std::io;
use std::path::{Path, PathBuf};

use firmware_basic::DialectStore;
use firmware_basic::wifi::{FlashWifiStore, LoadError, WifiSettings, WifiStore};
use flash_store::{MemFlash, StoreError};

/// Size of the simulated flash: the board's settings range (six 4 KiB sectors).
pub const BASIC_FLASH_BYTES: usize = 6 * 4096;

/// The simulated flash.
pub type BasicFlash = MemFlash<BASIC_FLASH_BYTES>;

/// The simulated Basic's settings store: its flash, in RAM or kept in a file whose raw image
/// is rewritten whole (through a temporary file renamed over it) after each change; a write
/// that fails undoes the change and is reported as a flash failure.
#[derive(Clone, Debug)]
pub struct BasicFlashStore {
    store: FlashWifiStore<BasicFlash>,
    file: Option<PathBuf>,
}

impl Default for BasicFlashStore {
    fn default() -> Self {
        Self::in_memory()
    }
}

impl BasicFlashStore {
    /// An erased flash in RAM only: settings last until the process ends.
    pub fn in_memory() -> Self {
        Self::with_flash(BasicFlash::new(), None)
    }

    /// The flash kept in `path`: read from it if it exists (a missing file is an erased flash),
    /// written to it after every change (its directory is created then).
    pub fn open(path: &Path) -> io::Result<Self> {
        let flash = match fs::read(path) {
            Ok(image) if image.len() == BASIC_FLASH_BYTES => BasicFlash::from_image(&image),
            Ok(image) => {
                return Err(io::Error::new(
                    io::ErrorKind::InvalidData,
                    format!(
                        "{} is {} bytes, not a {BASIC_FLASH_BYTES}-byte flash image",
                        path.display(),
                        image.len()
                    ),
                ));
            }
            Err(e) if e.kind() == io::ErrorKind::NotFound => BasicFlash::new(),
            Err(e) => return Err(e),
        };
        Ok(Self::with_flash(flash, Some(path.to_path_buf())))
    }

    fn with_flash(flash: BasicFlash, file: Option<PathBuf>) -> Self {
        Self {
            store: FlashWifiStore::new(flash, 0..BASIC_FLASH_BYTES as u32),
            file,
        }
    }

    /// The file the flash is kept in, if any.
    pub fn file(&self) -> Option<&Path> {
        self.file.as_deref()
    }

    /// The flash, to look at it (what it holds, how much it has worked).
    pub fn flash(&self) -> Option<&BasicFlash> {
        self.store.flash()
    }

    /// The flash, to make it fail ([`MemFlash::fail_writes`]) or look at it.
    pub fn flash_mut(&mut self) -> Option<&mut BasicFlash> {
        self.store.flash_mut()
    }

    fn write_file(&self, path: &Path) -> io::Result<()> {
        let image = self
            .store
            .flash()
            .ok_or_else(|| io::Error::other("the flash is in use"))?
            .image();
        if let Some(dir) = path.parent().filter(|d| !d.as_os_str().is_empty()) {
            fs::create_dir_all(dir)?;
        }
        let mut temporary = path.as_os_str().to_owned();
        temporary.push(".new");
        fs::write(&temporary, image)?;
        fs::rename(&temporary, path)
    }
}

impl BasicFlashStore {
    /// Makes `change` to the flash and then to the file; if the file cannot be written, the
    /// flash is put back as it was, so the two never differ.
    fn write_through(
        &mut self,
        change: impl FnOnce(&mut FlashWifiStore<BasicFlash>) -> Result<(), StoreError>,
    ) -> Result<(), StoreError> {
        let before = self.store.clone();
        change(&mut self.store)?;
        if let Some(path) = &self.file
            && self.write_file(path).is_err()
        {
            self.store = before;
            return Err(StoreError::Flash);
        }
        Ok(())
    }
}

impl WifiStore for BasicFlashStore {
    fn load(&mut self) -> Result<Option<WifiSettings>, LoadError> {
        self.store.load()
    }

    fn save(&mut self, settings: &WifiSettings) -> Result<(), StoreError> {
        self.write_through(|store| store.save(settings))
    }
}

impl DialectStore for BasicFlashStore {
    fn load_dialect(&mut self) -> Result<Option<protocol_core::dialect::Dialect>, StoreError> {
        self.store.load_dialect()
    }

    fn save_dialect(&mut self, dialect: protocol_core::dialect::Dialect) -> Result<(), StoreError> {
        self.write_through(|store| store.save_dialect(dialect))
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use firmware_basic::wifi::Credentials;

    fn settings(ssid: &str, port: u16) -> WifiSettings {
        WifiSettings::new()
            .with_credentials(Some(
                Credentials::new(ssid.as_bytes(), b"12345678").unwrap(),
            ))
            .with_port(port)
            .unwrap()
    }

    fn temp_dir(name: &str) -> PathBuf {
        let dir = std::env::temp_dir().join(format!("open-mycobot-{name}-{}", std::process::id()));
        let _ = fs::remove_dir_all(&dir);
        dir
    }

    #[test]
    fn settings_survive_reopening_the_file() {
        let dir = temp_dir("flash-reopen");
        let path = dir.join("state/basic-flash.bin");
        let mut store = BasicFlashStore::open(&path).unwrap();
        assert_eq!(store.load(), Ok(None), "a missing file is an erased flash");
        store.save(&settings("robots", 9001)).unwrap();
        assert_eq!(fs::metadata(&path).unwrap().len(), BASIC_FLASH_BYTES as u64);
        let mut again = BasicFlashStore::open(&path).unwrap();
        assert_eq!(again.load(), Ok(Some(settings("robots", 9001))));
        fs::remove_dir_all(dir).unwrap();
    }

    #[test]
    fn a_file_that_cannot_be_written_undoes_the_change() {
        let dir = temp_dir("flash-unwritable");
        let path = dir.join("basic-flash.bin");
        let mut store = BasicFlashStore::open(&path).unwrap();
        store.save(&settings("robots", 9001)).unwrap();
        // The file's directory becomes a file: the next write fails.
        fs::remove_dir_all(&dir).unwrap();
        fs::write(&dir, b"in the way").unwrap();
        assert_eq!(store.save(&settings("other", 9002)), Err(StoreError::Flash));
        assert_eq!(store.load(), Ok(Some(settings("robots", 9001))), "undone");
        fs::remove_file(&dir).unwrap();
    }

    #[test]
    fn a_file_of_another_size_is_refused() {
        let dir = temp_dir("flash-size");
        fs::create_dir_all(&dir).unwrap();
        let path = dir.join("basic-flash.bin");
        fs::write(&path, [0u8; 100]).unwrap();
        let e = BasicFlashStore::open(&path).unwrap_err();
        assert_eq!(e.kind(), io::ErrorKind::InvalidData);
        fs::remove_dir_all(dir).unwrap();
    }

    #[test]
    fn a_failing_flash_is_reported() {
        let mut store = BasicFlashStore::in_memory();
        store.flash_mut().unwrap().fail_writes(true);
        assert_eq!(
            store.save(&settings("robots", 9001)),
            Err(StoreError::Flash)
        );
        assert_eq!(store.load(), Ok(None));
    }
}
