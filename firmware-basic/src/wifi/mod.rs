//! Wi-Fi: the settings pymycobot sets over 0xB0..0xB2, where they are kept, and the station
//! that joins the network they name, as host-tested parts. The board layer binds them to
//! esp-radio (the driver), smoltcp (DHCP, the TCP listener) and esp-storage (the flash); the
//! virtual robot to a file-backed flash and its own TCP server.
//!
//! * [`config`]: [`WifiSettings`] (SSID, password, port) and their checks; the exact wire
//!   layouts of 0xB0 / 0xB1 / 0xB2 as pymycobot 4.0.7 uses them (0xB0's bare text after an
//!   announcing frame, caught per link by a [`SetTextCapture`]; 0xB1's bare text answer); the
//!   flash record.
//! * [`store`]: the [`WifiStore`] trait, [`FlashWifiStore`] over any NOR flash through
//!   `flash_store` (wear-levelled, all-or-nothing writes), and [`WifiConfig`], the settings in
//!   effect, changed only after the flash write succeeded.
//! * [`connection`]: the [`Station`] state machine: join, DHCP, reconnect with back-off, new
//!   credentials, no credentials = off; actions out, driver events and time in.
//! * `commands`: [`Wifi`], the three together as the Basic owns them (from its first poll on,
//!   on a board that lends a store): answers 0xB0..0xB2, keeps the station's credentials in
//!   step with the settings, and reports a [`WifiStatus`] for the LCD.
//! * `writes`: [`SettingsWrites`], the changes (0xB0, 0xB2) waiting for a quiet bus before
//!   they are written to flash, at most [`WIFI_WRITE_WAIT_US`].
//!
//! This file is the facade: the parts below it, and what the Basic and the board use of them.
//!
//! What a client sees: `01` when a setting was stored (or was already set), `00` when it was
//! refused (an empty or over-long SSID, a password that is no WPA key, port 0, a text in
//! another layout) or the flash write failed; either way a refusal changes nothing. New
//! credentials are joined at once; a new port takes new connections (the clients already
//! connected stay).

mod commands;
pub mod config;
pub mod connection;
pub mod store;
mod writes;

pub use commands::{Wifi, WifiAnswer, WifiError, WifiReply, WifiStatus, writes_settings};
pub use config::{
    Captured, Credentials, MAX_GET_TEXT, SetTextCapture, SetTextEnd, SettingsError, WifiSettings,
};
pub use connection::{Action, Failure, JoinFailure, LinkEvent, Station, StationState};
pub use store::{ChangeError, Changed, FlashWifiStore, LoadError, WifiConfig, WifiStore};
pub use writes::{SettingsChange, SettingsWrites, WIFI_WRITE_WAIT_US};
