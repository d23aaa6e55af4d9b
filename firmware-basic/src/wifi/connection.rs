//! The Wi-Fi station as a pure, time-driven state machine: what the driver should do next, from
//! the credentials in effect, what the driver reported and the time. No radio, no clock: the
//! board (esp-radio, smoltcp) and the tests feed it.
//!
//! ```text
//!            credentials                Joined                 GotAddress
//!   Off ───────────────▶ Joining ───────────────▶ GettingAddress ───────────▶ Online
//!    ▲                    │  ▲                        │                          │
//!    │ none               │  │ back-off over          │ DHCP timeout,            │ Left,
//!    │                    ▼  │                        ▼ Left                     ▼ LostAddress
//!    └──────────────── Waiting ◀──────────────────────┴──────────────────────────┘
//!                     (JoinFailed, join timeout)         (LostAddress: GettingAddress again)
//! ```
//!
//! * Inputs: [`Station::set_credentials`] (present, changed or gone), [`Station::on_event`]
//!   (what the driver and the DHCP client report, [`LinkEvent`]) and the time in
//!   [`Station::poll`].
//! * Outputs: [`Station::poll`] returns the next [`Action`] for the driver (join with these
//!   credentials, leave, start DHCP, take the network down), one at a time, in order.
//! * [`Station::state`], [`Station::last_failure`]: what the LCD shows (with the SSID, port
//!   and client count, in [`WifiStatus`](super::WifiStatus)).
//!
//! Every join has an attempt number; events of an older attempt (a join the driver was still
//! finishing when the credentials changed) are ignored.
//!
//! **Reconnecting.** A join that fails (the driver says so, or it has not joined after
//! [`JOIN_TIMEOUT_US`]), an address that does not come within [`DHCP_TIMEOUT_US`], or a link
//! lost while online is retried after a back-off that doubles from [`BACKOFF_FIRST_US`] to at
//! most [`BACKOFF_MAX_US`]: 1, 2, 4, 8, 16, 32, 60, 60, ... seconds after the 1st, 2nd, ...
//! failure in a row. Getting an address resets it, so a network that drops out is rejoined one
//! second later. New credentials are joined at once, whatever the back-off. No credentials:
//! the station leaves and stays off.

use core::net::Ipv4Addr;

use heapless::Deque;

use super::config::Credentials;

/// Longest wait for the driver to join (scan, authenticate, 4-way handshake), in
/// microseconds; a join normally takes 1 to 5 s.
pub const JOIN_TIMEOUT_US: u64 = 20_000_000;
/// Longest wait for a DHCP lease once joined, in microseconds (DHCP retries its discover after
/// 4 s and more; three tries fit).
pub const DHCP_TIMEOUT_US: u64 = 30_000_000;
/// The back-off after the first failure in a row, in microseconds.
pub const BACKOFF_FIRST_US: u64 = 1_000_000;
/// The longest back-off, in microseconds.
pub const BACKOFF_MAX_US: u64 = 60_000_000;

/// The back-off after `failures` failures in a row (at least 1), in microseconds.
pub const fn backoff_us(failures: u32) -> u64 {
    let doublings = if failures > 0 { failures - 1 } else { 0 };
    if doublings >= 6 {
        return BACKOFF_MAX_US;
    }
    let us = BACKOFF_FIRST_US << doublings;
    if us > BACKOFF_MAX_US {
        BACKOFF_MAX_US
    } else {
        us
    }
}

/// Why a join failed, as far as the driver can tell (esp-radio's disconnect reasons, sorted).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum JoinFailure {
    /// No network with that SSID answered.
    NotFound,
    /// The network refused the password (authentication or 4-way handshake failed).
    AuthFailed,
    /// Anything else (the driver refused the settings, association failed, ...).
    Other,
}

/// Why the station stopped being connected, as far as the station machine knows.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Failure {
    /// A join failed.
    Join(JoinFailure),
    /// A join took longer than [`JOIN_TIMEOUT_US`].
    JoinTimeout,
    /// No DHCP lease within [`DHCP_TIMEOUT_US`].
    NoAddress,
    /// The link was lost while joined.
    LinkLost,
}

/// What the driver and the DHCP client report.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum LinkEvent {
    /// The join of `attempt` succeeded: the station is associated and authenticated.
    Joined {
        /// The attempt of the [`Action::Join`] that succeeded.
        attempt: u32,
    },
    /// The join of `attempt` failed.
    JoinFailed {
        /// The attempt of the [`Action::Join`] that failed.
        attempt: u32,
        /// Why.
        reason: JoinFailure,
    },
    /// The station joined by `attempt` lost its network (beacons lost, kicked off).
    Left {
        /// The attempt of the [`Action::Join`] that had joined.
        attempt: u32,
    },
    /// DHCP gave the station `address`.
    GotAddress(Ipv4Addr),
    /// The DHCP lease ended (not renewed, or the server took it back).
    LostAddress,
}

/// What the driver should do.
#[derive(Clone, Debug, PartialEq, Eq)]
pub enum Action {
    /// Join the network `credentials` names (leaving any other first); report the outcome as
    /// [`LinkEvent::Joined`] or [`LinkEvent::JoinFailed`] with `attempt`, and a later loss as
    /// [`LinkEvent::Left`].
    Join {
        /// The network.
        credentials: Credentials,
        /// This join's number, to be given back in its events.
        attempt: u32,
    },
    /// Leave the network (abort a join in progress). Nothing is reported back.
    Leave,
    /// The link is up: forget any old address and ask DHCP for one.
    StartDhcp,
    /// The network is gone (left, lost, or no address): drop the address and close every TCP
    /// client. Always comes before [`Action::Leave`] or a new [`Action::Join`] that ends an
    /// online station.
    Down,
}

/// Where the station is.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum StationState {
    /// No credentials: Wi-Fi off.
    Off,
    /// Joining the network, since `since_us`.
    Joining {
        /// When the join was asked for.
        since_us: u64,
    },
    /// Joined, waiting for a DHCP lease since `since_us`.
    GettingAddress {
        /// When DHCP was started.
        since_us: u64,
    },
    /// Joined with `address`: TCP clients can connect.
    Online {
        /// The station's IPv4 address.
        address: Ipv4Addr,
    },
    /// Waiting until `retry_at_us` to join again after a failure.
    Waiting {
        /// When the next join starts.
        retry_at_us: u64,
    },
}

/// Most actions waiting for the driver: a change of credentials while online is
/// [`Action::Down`], [`Action::Leave`], [`Action::Join`].
const MAX_ACTIONS: usize = 4;

/// The station state machine. See the [module doc](self).
#[derive(Clone, Debug)]
pub struct Station {
    state: StationState,
    credentials: Option<Credentials>,
    /// Number of the latest join (0: none yet).
    attempt: u32,
    /// Failures in a row since the last address (sets the back-off).
    failures: u32,
    last_failure: Option<Failure>,
    actions: Deque<Action, MAX_ACTIONS>,
}

impl Default for Station {
    fn default() -> Self {
        Self::new()
    }
}

impl Station {
    /// A station with no credentials yet: off.
    pub const fn new() -> Self {
        Self {
            state: StationState::Off,
            credentials: None,
            attempt: 0,
            failures: 0,
            last_failure: None,
            actions: Deque::new(),
        }
    }

    /// Where the station is.
    pub fn state(&self) -> StationState {
        self.state
    }

    /// The station's address while online.
    pub fn address(&self) -> Option<Ipv4Addr> {
        match self.state {
            StationState::Online { address } => Some(address),
            _ => None,
        }
    }

    /// Failures in a row since the station was last online.
    pub fn failures(&self) -> u32 {
        self.failures
    }

    /// The last failure, kept until the station is online again.
    pub fn last_failure(&self) -> Option<Failure> {
        self.last_failure
    }

    /// Sets the credentials in effect at `now_us` (at start and after every change); `None`
    /// turns Wi-Fi off. The same credentials again change nothing; others are joined at once.
    pub fn set_credentials(&mut self, now_us: u64, credentials: Option<&Credentials>) {
        if self.credentials.as_ref() == credentials {
            return;
        }
        self.credentials = credentials.cloned();
        self.failures = 0;
        self.last_failure = None;
        self.leave();
        match credentials {
            Some(_) => self.join(now_us),
            None => self.state = StationState::Off,
        }
    }

    /// Takes an event from the driver or the DHCP client, received at `now_us`.
    pub fn on_event(&mut self, now_us: u64, event: LinkEvent) {
        match (self.state, event) {
            (StationState::Joining { .. }, LinkEvent::Joined { attempt })
                if attempt == self.attempt =>
            {
                self.state = StationState::GettingAddress { since_us: now_us };
                self.push(Action::StartDhcp);
            }
            (StationState::Joining { .. }, LinkEvent::JoinFailed { attempt, reason })
                if attempt == self.attempt =>
            {
                self.fail(now_us, Failure::Join(reason));
            }
            (
                StationState::GettingAddress { .. } | StationState::Online { .. },
                LinkEvent::Left { attempt },
            ) if attempt == self.attempt => {
                self.push(Action::Down);
                self.fail(now_us, Failure::LinkLost);
            }
            (
                StationState::GettingAddress { .. } | StationState::Online { .. },
                LinkEvent::GotAddress(address),
            ) => {
                self.state = StationState::Online { address };
                self.failures = 0;
                self.last_failure = None;
            }
            (StationState::Online { .. }, LinkEvent::LostAddress) => {
                self.push(Action::Down);
                self.state = StationState::GettingAddress { since_us: now_us };
                self.push(Action::StartDhcp);
            }
            // Late events of an older attempt, or of a state already left.
            _ => {}
        }
    }

    /// Checks the deadlines at `now_us` and returns the next action for the driver, if any.
    /// Call it until it returns `None`.
    pub fn poll(&mut self, now_us: u64) -> Option<Action> {
        match self.state {
            StationState::Joining { since_us }
                if now_us.saturating_sub(since_us) >= JOIN_TIMEOUT_US =>
            {
                self.push(Action::Leave);
                self.fail(now_us, Failure::JoinTimeout);
            }
            StationState::GettingAddress { since_us }
                if now_us.saturating_sub(since_us) >= DHCP_TIMEOUT_US =>
            {
                self.push(Action::Down);
                self.push(Action::Leave);
                self.fail(now_us, Failure::NoAddress);
            }
            StationState::Waiting { retry_at_us } if now_us >= retry_at_us => self.join(now_us),
            _ => {}
        }
        self.actions.pop_front()
    }

    /// Ends whatever the station is doing: the network goes down and the driver leaves.
    fn leave(&mut self) {
        match self.state {
            StationState::Online { .. } | StationState::GettingAddress { .. } => {
                self.push(Action::Down);
                self.push(Action::Leave);
            }
            StationState::Joining { .. } => self.push(Action::Leave),
            StationState::Off | StationState::Waiting { .. } => {}
        }
    }

    fn join(&mut self, now_us: u64) {
        let Some(credentials) = self.credentials.clone() else {
            self.state = StationState::Off;
            return;
        };
        self.attempt = self.attempt.wrapping_add(1);
        self.push(Action::Join {
            credentials,
            attempt: self.attempt,
        });
        self.state = StationState::Joining { since_us: now_us };
    }

    fn fail(&mut self, now_us: u64, failure: Failure) {
        self.failures = self.failures.saturating_add(1);
        self.last_failure = Some(failure);
        self.state = StationState::Waiting {
            retry_at_us: now_us.saturating_add(backoff_us(self.failures)),
        };
    }

    /// Queues `action`. The queue holds the longest sequence one input makes; were it full,
    /// the oldest action is dropped (a newer one supersedes it).
    fn push(&mut self, action: Action) {
        if self.actions.is_full() {
            self.actions.pop_front();
        }
        let _ = self.actions.push_back(action);
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    const S: u64 = 1_000_000;
    const IP: Ipv4Addr = Ipv4Addr::new(192, 168, 1, 42);

    fn creds(ssid: &str) -> Credentials {
        Credentials::new(ssid.as_bytes(), b"12345678").unwrap()
    }

    fn drain(station: &mut Station, now_us: u64) -> Vec<Action> {
        core::iter::from_fn(|| station.poll(now_us)).collect()
    }

    /// The attempt of the one join in `actions`.
    fn joined(actions: &[Action]) -> u32 {
        match actions {
            [.., Action::Join { attempt, .. }] => *attempt,
            _ => panic!("no join in {actions:?}"),
        }
    }

    /// A station online on "home" at `now_us`; returns the attempt.
    fn online(station: &mut Station, now_us: u64) -> u32 {
        station.set_credentials(now_us, Some(&creds("home")));
        let attempt = joined(&drain(station, now_us));
        station.on_event(now_us, LinkEvent::Joined { attempt });
        assert_eq!(drain(station, now_us), [Action::StartDhcp]);
        station.on_event(now_us, LinkEvent::GotAddress(IP));
        attempt
    }

    #[test]
    fn no_credentials_is_wifi_off() {
        let mut station = Station::new();
        station.set_credentials(0, None);
        assert_eq!(drain(&mut station, 100 * S), []);
        assert_eq!(station.state(), StationState::Off);
    }

    #[test]
    fn credentials_join_then_dhcp_then_online() {
        let mut station = Station::new();
        station.set_credentials(0, Some(&creds("home")));
        let actions = drain(&mut station, 0);
        assert_eq!(
            actions,
            [Action::Join {
                credentials: creds("home"),
                attempt: 1
            }]
        );
        assert_eq!(station.state(), StationState::Joining { since_us: 0 });
        station.on_event(2 * S, LinkEvent::Joined { attempt: 1 });
        assert_eq!(drain(&mut station, 2 * S), [Action::StartDhcp]);
        assert_eq!(station.address(), None);
        station.on_event(3 * S, LinkEvent::GotAddress(IP));
        assert_eq!(station.state(), StationState::Online { address: IP });
        assert_eq!(station.address(), Some(IP));
        assert_eq!(drain(&mut station, 1_000 * S), []);
    }

    #[test]
    fn failed_joins_back_off_doubling_to_a_minute() {
        assert_eq!(
            (1..=9).map(|n| backoff_us(n) / S).collect::<Vec<_>>(),
            [1, 2, 4, 8, 16, 32, 60, 60, 60]
        );
        assert_eq!(backoff_us(u32::MAX), BACKOFF_MAX_US);
        let mut station = Station::new();
        station.set_credentials(0, Some(&creds("home")));
        let mut now = 0;
        let mut attempt = joined(&drain(&mut station, now));
        for failures in 1..=8u32 {
            station.on_event(
                now,
                LinkEvent::JoinFailed {
                    attempt,
                    reason: JoinFailure::AuthFailed,
                },
            );
            assert_eq!(station.failures(), failures);
            assert_eq!(
                station.last_failure(),
                Some(Failure::Join(JoinFailure::AuthFailed))
            );
            let retry = now + backoff_us(failures);
            assert_eq!(drain(&mut station, retry - 1), []);
            now = retry;
            attempt = joined(&drain(&mut station, now));
        }
        assert_eq!(attempt, 9);
    }

    #[test]
    fn a_join_that_never_ends_times_out() {
        let mut station = Station::new();
        station.set_credentials(0, Some(&creds("home")));
        drain(&mut station, 0);
        assert_eq!(drain(&mut station, JOIN_TIMEOUT_US - 1), []);
        assert_eq!(drain(&mut station, JOIN_TIMEOUT_US), [Action::Leave]);
        assert_eq!(station.last_failure(), Some(Failure::JoinTimeout));
        let retry = JOIN_TIMEOUT_US + BACKOFF_FIRST_US;
        assert_eq!(joined(&drain(&mut station, retry)), 2);
    }

    #[test]
    fn no_address_in_time_leaves_and_retries() {
        let mut station = Station::new();
        station.set_credentials(0, Some(&creds("home")));
        drain(&mut station, 0);
        station.on_event(S, LinkEvent::Joined { attempt: 1 });
        drain(&mut station, S);
        let late = S + DHCP_TIMEOUT_US;
        assert_eq!(drain(&mut station, late), [Action::Down, Action::Leave]);
        assert_eq!(station.last_failure(), Some(Failure::NoAddress));
        assert_eq!(joined(&drain(&mut station, late + BACKOFF_FIRST_US)), 2);
    }

    #[test]
    fn a_lost_link_goes_down_and_rejoins_after_a_second() {
        let mut station = Station::new();
        let attempt = online(&mut station, 0);
        station.on_event(100 * S, LinkEvent::Left { attempt });
        assert_eq!(drain(&mut station, 100 * S), [Action::Down]);
        assert_eq!(station.last_failure(), Some(Failure::LinkLost));
        assert_eq!(drain(&mut station, 101 * S - 1), []);
        assert_eq!(joined(&drain(&mut station, 101 * S)), attempt + 1);
    }

    #[test]
    fn a_lost_lease_asks_dhcp_again_without_leaving() {
        let mut station = Station::new();
        online(&mut station, 0);
        station.on_event(50 * S, LinkEvent::LostAddress);
        assert_eq!(
            drain(&mut station, 50 * S),
            [Action::Down, Action::StartDhcp]
        );
        station.on_event(51 * S, LinkEvent::GotAddress(Ipv4Addr::new(10, 0, 0, 2)));
        assert_eq!(station.address(), Some(Ipv4Addr::new(10, 0, 0, 2)));
    }

    #[test]
    fn new_credentials_while_online_go_down_leave_and_join_at_once() {
        let mut station = Station::new();
        let attempt = online(&mut station, 0);
        station.set_credentials(10 * S, Some(&creds("home")));
        assert_eq!(drain(&mut station, 10 * S), []);
        station.set_credentials(10 * S, Some(&creds("office")));
        assert_eq!(
            drain(&mut station, 10 * S),
            [
                Action::Down,
                Action::Leave,
                Action::Join {
                    credentials: creds("office"),
                    attempt: attempt + 1
                }
            ]
        );
    }

    #[test]
    fn new_credentials_skip_the_back_off() {
        let mut station = Station::new();
        station.set_credentials(0, Some(&creds("home")));
        drain(&mut station, 0);
        for attempt in 1..=5 {
            station.on_event(
                0,
                LinkEvent::JoinFailed {
                    attempt,
                    reason: JoinFailure::NotFound,
                },
            );
            station.poll(BACKOFF_MAX_US * 10);
        }
        station.on_event(
            0,
            LinkEvent::JoinFailed {
                attempt: 6,
                reason: JoinFailure::NotFound,
            },
        );
        assert!(matches!(station.state(), StationState::Waiting { .. }));
        station.set_credentials(S, Some(&creds("office")));
        assert_eq!(joined(&drain(&mut station, S)), 7);
        assert_eq!(station.failures(), 0);
    }

    #[test]
    fn removing_the_credentials_turns_wifi_off() {
        let mut station = Station::new();
        online(&mut station, 0);
        station.set_credentials(S, None);
        assert_eq!(drain(&mut station, S), [Action::Down, Action::Leave]);
        assert_eq!(station.state(), StationState::Off);
        assert_eq!(drain(&mut station, 1_000 * S), []);
    }

    #[test]
    fn events_of_an_older_attempt_are_ignored() {
        let mut station = Station::new();
        station.set_credentials(0, Some(&creds("home")));
        drain(&mut station, 0);
        station.set_credentials(S, Some(&creds("office")));
        assert_eq!(joined(&drain(&mut station, S)), 2);
        // The driver was finishing the first join when it was told to leave.
        station.on_event(S, LinkEvent::Joined { attempt: 1 });
        station.on_event(
            S,
            LinkEvent::JoinFailed {
                attempt: 1,
                reason: JoinFailure::Other,
            },
        );
        assert_eq!(station.state(), StationState::Joining { since_us: S });
        assert_eq!(drain(&mut station, S), []);
        station.on_event(2 * S, LinkEvent::Joined { attempt: 2 });
        assert_eq!(drain(&mut station, 2 * S), [Action::StartDhcp]);
        // An address while still joining, a loss while waiting: ignored too.
        let mut station = Station::new();
        station.set_credentials(0, Some(&creds("home")));
        drain(&mut station, 0);
        station.on_event(0, LinkEvent::GotAddress(IP));
        assert_eq!(station.address(), None);
        station.on_event(0, LinkEvent::LostAddress);
        assert_eq!(drain(&mut station, 0), []);
    }

    #[test]
    fn a_station_left_alone_never_panics_or_loops() {
        // Every event in every state, at odd times: the machine stays in a state it can
        // leave, and each poll yields a bounded number of actions.
        let events = [
            LinkEvent::Joined { attempt: 1 },
            LinkEvent::JoinFailed {
                attempt: 1,
                reason: JoinFailure::Other,
            },
            LinkEvent::Left { attempt: 1 },
            LinkEvent::GotAddress(IP),
            LinkEvent::LostAddress,
        ];
        let mut station = Station::new();
        station.set_credentials(0, Some(&creds("home")));
        let mut now = 0;
        for round in 0..200u64 {
            let event = events[(round * 7 % 5) as usize];
            let event = match event {
                LinkEvent::Joined { .. } => LinkEvent::Joined {
                    attempt: station.attempt,
                },
                LinkEvent::Left { .. } => LinkEvent::Left {
                    attempt: station.attempt,
                },
                e => e,
            };
            station.on_event(now, event);
            now += round * 1_234_567;
            assert!(drain(&mut station, now).len() <= MAX_ACTIONS);
        }
    }
}
