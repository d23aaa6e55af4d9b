//! Writes the flash image of a Basic's Wi-Fi settings: the `nvs` partition (0x9000, 24 KiB)
//! holding the record the board reads at boot, made by the same code as on the board
//! (`FlashWifiStore` over NOR flash, here `MemFlash` at the same addresses). For bringing up a
//! board before clients can set the network over 0xB0..0xB2:
//!
//! ```sh
//! cargo run -p firmware-basic --example wifi_settings -- SSID PASSWORD [PORT] wifi.bin
//! espflash write-bin 0x9000 wifi.bin
//! ```
//!
//! An empty PASSWORD ("") is an open network. The settings are checked like 0xB0's.

use std::process::ExitCode;

use firmware_basic::wifi::{Credentials, FlashWifiStore, WifiSettings, WifiStore};
use flash_store::MemFlash;

/// The settings' flash range on the board (`network::SETTINGS_FLASH` in the board binary).
const SETTINGS_FLASH: std::ops::Range<u32> = 0x9000..0xF000;

fn main() -> ExitCode {
    let args: Vec<String> = std::env::args().skip(1).collect();
    let (ssid, password, port, out) = match args.as_slice() {
        [ssid, password, out] => (ssid, password, "9000", out),
        [ssid, password, port, out] => (ssid, password, port.as_str(), out),
        _ => {
            eprintln!("usage: wifi_settings SSID PASSWORD [PORT] OUT.bin");
            return ExitCode::FAILURE;
        }
    };
    let settings = Credentials::new(ssid.as_bytes(), password.as_bytes())
        .map_err(|e| e.to_string())
        .and_then(|credentials| {
            let port = port.parse::<u16>().map_err(|e| e.to_string())?;
            WifiSettings::new()
                .with_credentials(Some(credentials))
                .with_port(port)
                .map_err(|e| e.to_string())
        });
    let settings = match settings {
        Ok(settings) => settings,
        Err(e) => {
            eprintln!("refused: {e}");
            return ExitCode::FAILURE;
        }
    };
    let mut flash = Box::new(MemFlash::<{ SETTINGS_FLASH.end as usize }>::new());
    let saved = FlashWifiStore::new(&mut *flash, SETTINGS_FLASH).save(&settings);
    if let Err(e) = saved {
        eprintln!("could not store the settings: {e:?}");
        return ExitCode::FAILURE;
    }
    let image = flash
        .image()
        .get(SETTINGS_FLASH.start as usize..)
        .unwrap_or_default();
    if let Err(e) = std::fs::write(out, image) {
        eprintln!("{out}: {e}");
        return ExitCode::FAILURE;
    }
    println!(
        "{out}: {} bytes for 0x{:X}; flash with `espflash write-bin 0x{:X} {out}`",
        image.len(),
        SETTINGS_FLASH.start,
        SETTINGS_FLASH.start
    );
    ExitCode::SUCCESS
}
