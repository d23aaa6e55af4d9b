//! Wi-Fi on the board (feature `wifi`): the library's station machine (owned by the
//! [`Basic`], which also answers 0xB0..0xB2 with the settings' flash store the board lends)
//! bound to esp-radio ([`radio`]) and smoltcp ([`net`]), and the TCP clients served through the
//! library's [`NetworkClients`] (a host link each on the Basic's router), all polled from the
//! super-loop by [`BoardWifi::poll`].
//!
//! The driver starts on a thread of its own ([`start`]), so the loop serves USB from its first
//! pass; a radio that is not up by [`crate::radio_start::RADIO_START_DEADLINE_US`] (or whose
//! start fails) leaves the Basic a USB transponder, and the LCD says so.
//!
//! What one poll does, in order, each step bounded:
//! 1. the driver task looks at esp-radio's events (microseconds, [`radio`]);
//! 2. what it and DHCP reported goes to the station machine;
//! 3. smoltcp: maintenance, at most 4 received frames, DHCP, at most 256 bytes each way per TCP
//!    client between its socket and [`NetworkClients`], egress ([`net`]);
//! 4. the station machine's actions go to the driver (join, leave) or the stack (DHCP, down);
//!    a `Down` first lets the clients' last answers leave ([`DOWN_GRACE_US`]);
//! 5. the TCP sockets follow the configured port.

pub mod net;
pub mod radio;
pub mod start;

use board_support::board_log;
use esp_hal::peripherals::WIFI;
use esp_radio::wifi::{Interface, WifiController};
use firmware_basic::wifi::Action;
use firmware_basic::{Basic, NetworkClients};

use self::net::Net;
use self::radio::{Mailbox, Radio};
use crate::radio_start::RadioStart;

/// Where the Wi-Fi settings live: the `nvs` partition of the default partition table espflash
/// writes (0x9000, 24 KiB, six 4 KiB sectors), as on the Atom; the firmware does not use
/// ESP-IDF's NVS, and esp-radio keeps no calibration data there.
pub const SETTINGS_FLASH: core::ops::Range<u32> = 0x9000..0xF000;

/// How long the network stays up after the station machine said `Down`, in microseconds: the
/// clients' last answers leave first (new credentials set over Wi-Fi: that client's `01`), and
/// their connections are closed gracefully. pymycobot reads its answer within 50 ms.
pub const DOWN_GRACE_US: u64 = 100_000;

/// The board's Wi-Fi from boot: the radio starting on its own thread, then the network.
pub struct BoardWifi {
    radio: RadioStart,
    /// Randomises the TCP/IP stack.
    seed: u64,
    /// Once the radio is up.
    network: Option<Network>,
}

impl BoardWifi {
    /// Starts the driver on its own thread at `now_us` (the esp-rtos scheduler and the heap
    /// must be set up). Returns at once.
    pub fn begin(now_us: u64, wifi: WIFI<'static>, seed: u64) -> Self {
        start::spawn(wifi);
        Self {
            radio: RadioStart::begin(now_us),
            seed,
            network: None,
        }
    }

    /// Where the radio's start-up is, for the LCD.
    pub fn radio(&self) -> RadioStart {
        self.radio
    }

    /// One bounded round at `now_us`: takes the driver once it has started (or gives up on it
    /// at the deadline), then the network's work ([`Network::poll`]).
    pub fn poll(&mut self, now_us: u64, basic: &mut Basic, clients: &mut NetworkClients) {
        if self.radio.starting() {
            let outcome = start::take_outcome();
            self.radio = self.radio.poll(now_us, outcome.as_ref().map(Result::is_ok));
            match (self.radio, outcome) {
                (RadioStart::Up, Some(Ok(controller))) => {
                    self.network = Some(Network::new(now_us, controller, self.seed));
                }
                (RadioStart::Refused, _) => board_log!("Wi-Fi did not start; USB only"),
                (RadioStart::TimedOut, _) => {
                    board_log!("Wi-Fi radio not up in time; USB only");
                    start::give_up();
                }
                _ => {}
            }
        }
        if let Some(network) = &mut self.network {
            network.poll(now_us, basic, clients);
        }
    }
}

/// The network once the radio is up. See the [module doc](self).
pub struct Network {
    mailbox: &'static Mailbox,
    radio: Radio,
    net: Net,
    /// A `Down` is under way: the network goes down at this time (actions after it wait).
    down_at_us: Option<u64>,
}

impl Network {
    /// The network over the started driver `controller` at `now_us`; the station joins
    /// whatever the Basic's settings name. `seed` randomises the TCP/IP stack.
    pub fn new(now_us: u64, controller: WifiController<'static>, seed: u64) -> Self {
        let interface = Interface::station();
        let mailbox: &'static Mailbox = alloc::boxed::Box::leak(alloc::boxed::Box::default());
        Self {
            mailbox,
            radio: Radio::new(controller, mailbox),
            net: Net::new(interface, now_us, seed),
            down_at_us: None,
        }
    }

    /// One bounded round of Wi-Fi work at `now_us` for `basic` (its station machine); TCP
    /// clients' bytes go through `clients`.
    pub fn poll(&mut self, now_us: u64, basic: &mut Basic, clients: &mut NetworkClients) {
        self.radio.poll();
        let Some(wifi) = basic.wifi_mut() else {
            return;
        };
        while let Some(event) = self.mailbox.take_event() {
            wifi.on_event(now_us, event);
        }
        let event = self.net.poll(now_us, basic, clients);
        let Some(wifi) = basic.wifi_mut() else {
            return;
        };
        if let Some(event) = event {
            wifi.on_event(now_us, event);
        }
        if let Some(at) = self.down_at_us {
            if now_us < at {
                return;
            }
            self.down_at_us = None;
            self.net.down(basic, clients);
        }
        let Some(wifi) = basic.wifi_mut() else {
            return;
        };
        let port = wifi.settings().port();
        while let Some(action) = wifi.poll(now_us) {
            match radio::request_for(action) {
                Ok(request) => self.mailbox.request(request),
                Err(Action::StartDhcp) => self.net.start_dhcp(),
                Err(Action::Down) => {
                    // The rest waits until the clients' last answers have left.
                    self.net.close_gracefully();
                    self.down_at_us = Some(now_us.saturating_add(DOWN_GRACE_US));
                    break;
                }
                // `request_for` takes these.
                Err(Action::Join { .. } | Action::Leave) => {}
            }
        }
        self.net.listen_on(port);
    }
}
