//! Wi-Fi on the board (feature `wifi`): the library's [`Wifi`] (settings, station machine) bound
//! to esp-radio ([`radio`]), smoltcp ([`net`]) and esp-storage (the settings' flash), all
//! polled from the super-loop by [`Network::poll`].
//!
//! What one poll does, in order, each step bounded:
//! 1. the driver task looks at esp-radio's events (microseconds, [`radio`]);
//! 2. what it and DHCP reported goes to the station machine;
//! 3. smoltcp: maintenance, at most 4 received frames, DHCP, at most 256 bytes each way per TCP
//!    client, egress ([`net`]);
//! 4. the station machine's actions go to the driver (join, leave) or the stack (DHCP, down);
//! 5. the TCP sockets follow the configured port.
//!
//! TCP clients' bytes go to a [`TcpClients`]: the **integration point** with the Basic's router.
//! Until it is wired, [`DiscardClients`] accepts every client and drops what it sends.

pub mod net;
pub mod radio;

use esp_hal::peripherals::{FLASH, WIFI};
use esp_radio::wifi::{ControllerConfig, Interface, WifiController, WifiError};
use esp_storage::FlashStorage;
use firmware_basic::wifi::{Action, FlashWifiStore, Wifi, WifiStatus};

use self::net::Net;
use self::radio::{Mailbox, Radio};

/// Where the Wi-Fi settings live: the `nvs` partition of the default partition table espflash
/// writes (0x9000, 24 KiB, six 4 KiB sectors), as on the Atom; the firmware does not use
/// ESP-IDF's NVS, and esp-radio keeps no calibration data there.
pub const SETTINGS_FLASH: core::ops::Range<u32> = 0x9000..0xF000;

/// **Integration point**: what becomes of the TCP clients. The Basic's router will implement it
/// with a host link per client (open on connect, its framer and output queue, close on leave).
pub trait TcpClients {
    /// A client connected on socket `slot`; `false` turns it away (the connection is reset).
    fn connected(&mut self, slot: usize) -> bool;
    /// Bytes the client on `slot` sent; returns how many were taken (the rest stay in the
    /// socket, and TCP flow control slows the client).
    fn received(&mut self, slot: usize, bytes: &[u8]) -> usize;
    /// Fills `out` with bytes for the client on `slot`; returns how many.
    fn transmit(&mut self, slot: usize, out: &mut [u8]) -> usize;
    /// The client on `slot` has gone (it closed, timed out, or the network went down).
    fn disconnected(&mut self, slot: usize);
}

/// Until the router is wired (the integration step): clients are accepted, what they send is
/// dropped and counted, nothing is sent to them.
#[derive(Debug, Default)]
pub struct DiscardClients {
    /// Bytes received and dropped.
    pub dropped_bytes: u32,
}

impl TcpClients for DiscardClients {
    fn connected(&mut self, _: usize) -> bool {
        true
    }

    fn received(&mut self, _: usize, bytes: &[u8]) -> usize {
        self.dropped_bytes = self.dropped_bytes.wrapping_add(bytes.len() as u32);
        bytes.len()
    }

    fn transmit(&mut self, _: usize, _: &mut [u8]) -> usize {
        0
    }

    fn disconnected(&mut self, _: usize) {}
}

/// The board's Wi-Fi. See the [module doc](self).
pub struct Network {
    wifi: Wifi,
    store: FlashWifiStore<FlashStorage<'static>>,
    mailbox: &'static Mailbox,
    radio: Radio,
    net: Net,
}

impl Network {
    /// Starts Wi-Fi at `now_us`: loads the settings from flash, starts the driver (the
    /// esp-rtos scheduler must be running) and joins the network they name. `seed` randomises
    /// the TCP/IP stack.
    pub fn start(
        now_us: u64,
        wifi: WIFI<'static>,
        flash: FLASH<'static>,
        seed: u64,
    ) -> Result<Self, WifiError> {
        let mut store = FlashWifiStore::new(FlashStorage::new(flash), SETTINGS_FLASH);
        let controller = WifiController::new(wifi, ControllerConfig::default())?;
        let interface = Interface::station();
        let mailbox: &'static Mailbox = alloc::boxed::Box::leak(alloc::boxed::Box::default());
        Ok(Self {
            wifi: Wifi::start(now_us, &mut store),
            store,
            mailbox,
            radio: Radio::new(controller, mailbox),
            net: Net::new(interface, now_us, seed),
        })
    }

    /// One bounded round of Wi-Fi work at `now_us`; TCP clients' bytes go to `clients`.
    pub fn poll(&mut self, now_us: u64, clients: &mut impl TcpClients) {
        self.radio.poll();
        while let Some(event) = self.mailbox.take_event() {
            self.wifi.on_event(now_us, event);
        }
        if let Some(event) = self.net.poll(now_us, clients) {
            self.wifi.on_event(now_us, event);
        }
        while let Some(action) = self.wifi.poll(now_us) {
            match radio::request_for(action) {
                Ok(request) => self.mailbox.request(request),
                Err(Action::StartDhcp) => self.net.start_dhcp(),
                Err(Action::Down) => self.net.down(clients),
                // `request_for` takes these.
                Err(Action::Join { .. } | Action::Leave) => {}
            }
        }
        self.net.listen_on(self.wifi.settings().port());
    }

    /// What the LCD shows.
    pub fn status(&self) -> WifiStatus {
        self.wifi.status(self.net.clients())
    }

    /// **Integration point**: the Wi-Fi settings and their store, for answering 0xB0..0xB2
    /// ([`Wifi::answer`], [`Wifi::answer_set_text`]).
    #[allow(
        dead_code,
        reason = "used once the router answers 0xB0..0xB2 from here"
    )]
    pub fn settings_and_store(
        &mut self,
    ) -> (&mut Wifi, &mut FlashWifiStore<FlashStorage<'static>>) {
        (&mut self.wifi, &mut self.store)
    }
}
