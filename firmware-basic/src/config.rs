//! Settings of the transponder. [`BasicConfig::default`] is the real board; a changed config
//! is checked once with [`BasicConfig::validate`].

use protocol_core::timing;

/// Whether the Basic hears its own transmissions on the bus (TX and RX tied on the wire): the
/// same setting every station's bus listener has.
pub use protocol_core::listener::EchoMode;

/// Settings of the transponder. Times in microseconds.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct BasicConfig {
    /// How the bus echo is handled.
    pub echo: EchoMode,
    /// How long a forwarded host request waits for the Atom's reply before the next request
    /// may go, in microseconds. Below pymycobot's 0.5 s resend so its resend is forwarded.
    pub reply_timeout_us: u64,
    /// How long an internal request (power-on, probe) waits for its reply, in microseconds.
    pub probe_timeout_us: u64,
    /// Transmissions of one request before it is given up after collisions (at least 1).
    pub max_send_attempts: u8,
    /// Time after power-up before the Basic makes sure the Atom is powered (asks with 0x12,
    /// then 0x10 if it is off), in microseconds; the Atom boots in parallel and must be
    /// listening.
    pub boot_power_on_delay_us: u64,
    /// With no answer from the Atom for this long while idle, the Basic probes it (0x12), in
    /// microseconds; 0 disables probing (and the boot power-on retries).
    pub probe_interval_us: u64,
    /// Whether to make sure the Atom is powered at boot, like the vendor transponder: unlike
    /// it, the Basic asks first (0x12) and sends power on (0x10) only to an Atom that is off.
    pub power_on_at_boot: bool,
    /// The version the Basic reports for 0xC1, times ten (10 = "1.0").
    pub version_x10: u8,
    /// The dialect to speak from boot (the virtual robot's `--dialect`), kept in the store
    /// too; `None`: the stored one, or pymycobot's.
    pub dialect: Option<protocol_core::dialect::Dialect>,
    /// Whether a reply for a serial client is passed on as it arrives on the bus
    /// (cut-through: `docs/protocol.md` section 13) rather than once it is complete. On by
    /// default; off, every reply waits for its last byte (what the tests compare against).
    pub cut_through: bool,
    /// Whether the Basic holds the bus for a request still arriving on a serial link, so it
    /// goes as soon as it is in rather than at the Atom's next gap between servo transactions
    /// (`docs/protocol.md` section 13, [`crate::forwarder::HOLD_BYTE`]). On by default.
    pub bus_hold: bool,
}

impl Default for BasicConfig {
    fn default() -> Self {
        Self {
            echo: EchoMode::Auto,
            reply_timeout_us: timing::HOST_REPLY_DEADLINE_US * 4 / 5,
            probe_timeout_us: 50_000,
            max_send_attempts: 8,
            boot_power_on_delay_us: 1_000_000,
            probe_interval_us: 1_000_000,
            power_on_at_boot: true,
            version_x10: 10,
            dialect: None,
            cut_through: true,
            bus_hold: true,
        }
    }
}

/// A [`BasicConfig`] that cannot work.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum ConfigError {
    /// `reply_timeout_us` is 0, or not shorter than pymycobot's resend deadline (0.5 s): the
    /// host's resend would queue behind the request it repeats, and get its reply too.
    ReplyTimeout,
    /// `probe_timeout_us` is 0 or longer than `reply_timeout_us`.
    ProbeTimeout,
    /// `max_send_attempts` is 0: nothing would ever be sent.
    NoSendAttempts,
}

impl BasicConfig {
    /// The config, if it can work.
    pub fn validate(self) -> Result<Self, ConfigError> {
        if self.reply_timeout_us == 0 || self.reply_timeout_us >= timing::HOST_REPLY_DEADLINE_US {
            return Err(ConfigError::ReplyTimeout);
        }
        if self.probe_timeout_us == 0 || self.probe_timeout_us > self.reply_timeout_us {
            return Err(ConfigError::ProbeTimeout);
        }
        if self.max_send_attempts == 0 {
            return Err(ConfigError::NoSendAttempts);
        }
        Ok(self)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_default_is_valid() {
        assert_eq!(
            BasicConfig::default().validate(),
            Ok(BasicConfig::default())
        );
    }

    #[test]
    fn a_timeout_at_or_past_the_clients_resend_is_refused() {
        let config = BasicConfig {
            reply_timeout_us: timing::HOST_REPLY_DEADLINE_US,
            ..BasicConfig::default()
        };
        assert_eq!(config.validate(), Err(ConfigError::ReplyTimeout));
        let config = BasicConfig {
            max_send_attempts: 0,
            ..BasicConfig::default()
        };
        assert_eq!(config.validate(), Err(ConfigError::NoSendAttempts));
    }
}
