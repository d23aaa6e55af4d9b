//! Wi-Fi settings changes waiting for a quiet bus before they are written to flash.
//!
//! A flash erase stalls the CPU for tens of milliseconds, long enough to lose bus bytes, so the
//! Basic writes a settings change (0xB2, 0xB0 with its text framed, or the end of a link's bare
//! 0xB0 text) only while no request is on the bus, or once it has waited
//! [`WIFI_WRITE_WAIT_US`]. [`SettingsWrites`] keeps the changes in the order they arrived, each
//! with who asked (the answer goes to that client only), at most `N` (one per link: a client
//! waits for its answer).

use heapless::Deque;
use protocol_core::Frame;
use protocol_core::command::cmd;

use super::config::SetTextEnd;

/// Longest a Wi-Fi settings change waits for a quiet bus before it is written to flash anyway,
/// in microseconds. The bus is quiet again within an exchange with the Atom (about 1 ms); only
/// a silent Atom keeps it busy longer (up to `BasicConfig::reply_timeout_us`), and the
/// client's answer must still come within pymycobot's 50 ms read.
pub const WIFI_WRITE_WAIT_US: u64 = 20_000;

/// A change of the Wi-Fi settings, as it arrived.
#[derive(Debug, PartialEq, Eq)]
pub enum SettingsChange {
    /// 0xB2, or 0xB0 with the text framed.
    Frame(Frame),
    /// The end of a link's bare 0xB0 text.
    Text(SetTextEnd),
}

impl SettingsChange {
    /// The command that asked for the change (what a refusal answers).
    pub fn cmd(&self) -> u8 {
        match self {
            Self::Frame(frame) => frame.cmd(),
            Self::Text(_) => cmd::SET_SSID_PWD,
        }
    }
}

/// A change waiting, with who asked and since when.
#[derive(Debug)]
struct Waiting<K> {
    asker: K,
    since_us: u64,
    change: SettingsChange,
}

/// Settings changes waiting for a quiet bus, oldest first, each with who asked (`K`); at most
/// `N`. A change is due once no request is on the bus, or once it has waited
/// [`WIFI_WRITE_WAIT_US`] (a flash erase stalls the CPU).
#[derive(Debug)]
pub struct SettingsWrites<K, const N: usize> {
    waiting: Deque<Waiting<K>, N>,
}

impl<K, const N: usize> Default for SettingsWrites<K, N> {
    fn default() -> Self {
        Self::new()
    }
}

impl<K, const N: usize> SettingsWrites<K, N> {
    /// Nothing waiting.
    pub const fn new() -> Self {
        Self {
            waiting: Deque::new(),
        }
    }

    /// True if no change is waiting.
    pub fn is_empty(&self) -> bool {
        self.waiting.is_empty()
    }

    /// Keeps `change` from `asker`, arrived at `now_us`, until the bus is quiet; gives it back
    /// if `N` are waiting already (the caller refuses it).
    pub fn push(
        &mut self,
        now_us: u64,
        asker: K,
        change: SettingsChange,
    ) -> Result<(), SettingsChange> {
        self.waiting
            .push_back(Waiting {
                asker,
                since_us: now_us,
                change,
            })
            .map_err(|w| w.change)
    }

    /// The oldest change, due to be written at `now_us`: at once if the bus is quiet
    /// (`bus_busy` false), else once it has waited [`WIFI_WRITE_WAIT_US`]. Call until `None`.
    pub fn next_due(&mut self, now_us: u64, bus_busy: bool) -> Option<(K, SettingsChange)> {
        let front = self.waiting.front()?;
        if bus_busy && now_us.saturating_sub(front.since_us) < WIFI_WRITE_WAIT_US {
            return None;
        }
        self.waiting.pop_front().map(|w| (w.asker, w.change))
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn port_change(port: u16) -> SettingsChange {
        SettingsChange::Frame(Frame::new(cmd::SET_SERVER_PORT, &port.to_be_bytes()).unwrap())
    }

    #[test]
    fn a_change_waits_for_a_quiet_bus_but_no_longer_than_the_limit() {
        let mut writes: SettingsWrites<u8, 2> = SettingsWrites::new();
        writes.push(1_000, 7, port_change(9001)).unwrap();
        assert_eq!(writes.next_due(1_000 + WIFI_WRITE_WAIT_US - 1, true), None);
        assert!(!writes.is_empty());
        assert_eq!(
            writes.next_due(1_000 + WIFI_WRITE_WAIT_US, true),
            Some((7, port_change(9001))),
            "written anyway once it has waited the limit"
        );
        writes.push(50_000, 3, port_change(9002)).unwrap();
        assert_eq!(
            writes.next_due(50_000, false),
            Some((3, port_change(9002))),
            "at once on a quiet bus"
        );
        assert!(writes.is_empty());
    }

    #[test]
    fn changes_go_oldest_first_and_a_full_queue_gives_the_change_back() {
        let mut writes: SettingsWrites<u8, 2> = SettingsWrites::new();
        writes.push(0, 1, port_change(9001)).unwrap();
        writes.push(10, 2, port_change(9002)).unwrap();
        let refused = writes.push(20, 3, port_change(9003));
        assert_eq!(refused, Err(port_change(9003)));
        assert_eq!(refused.map_err(|c| c.cmd()), Err(cmd::SET_SERVER_PORT));
        let askers: std::vec::Vec<u8> = core::iter::from_fn(|| writes.next_due(30, false))
            .map(|(asker, _)| asker)
            .collect();
        assert_eq!(askers, [1, 2]);
    }
}
