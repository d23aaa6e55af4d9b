//! The Atom application: the bus, the servos, the motion and the host commands, polled.

use protocol_core::BytePort;
use protocol_core::units::Centideg;

use crate::config::{AtomConfig, ConfigError, JOINTS, SERVOS};
use crate::health::ServoHealth;
use crate::io::AtomIo;

/// The Atom firmware. Create it once with [`Atom::new`] and call [`Atom::poll`] in a loop.
pub struct Atom {
    config: AtomConfig,
    config_error: Option<ConfigError>,
    powered: bool,
    error_code: u8,
    health: [ServoHealth; SERVOS],
}

impl Atom {
    /// An Atom with `config`. An invalid configuration is replaced by the default one and the
    /// reason kept in [`Atom::config_error`], so a board always boots into something safe.
    pub fn new(config: AtomConfig) -> Self {
        let (config, config_error) = match config.validate() {
            Ok(()) => (config, None),
            Err(e) => (AtomConfig::default(), Some(e)),
        };
        Self {
            config,
            config_error,
            powered: config.powered_at_boot,
            error_code: 0,
            health: [ServoHealth::default(); SERVOS],
        }
    }

    /// Runs everything that is due at `now_us` (monotonic microseconds): reads the bytes that
    /// arrived on `bus` (the shared 1 Mbaud wire) and `usb` (the Atom's own host link,
    /// [`protocol_core::NullPort`] if unused), answers host commands, drives the servo
    /// transactions and the motion. Never blocks; call it as often as possible.
    pub fn poll<B: BytePort, U: BytePort, I: AtomIo>(
        &mut self,
        now_us: u64,
        bus: &mut B,
        usb: &mut U,
        io: &mut I,
    ) {
        let _ = (now_us, bus, usb, io);
    }

    /// The configuration in use.
    pub fn config(&self) -> &AtomConfig {
        &self.config
    }

    /// Why the configuration passed to [`Atom::new`] was refused, if it was.
    pub fn config_error(&self) -> Option<ConfigError> {
        self.config_error
    }

    /// True while the arm is powered on (torque enabled by 0x10, until 0x11).
    pub fn is_powered(&self) -> bool {
        self.powered
    }

    /// The error code 0x07 reports (0 = none).
    pub fn error_code(&self) -> u8 {
        self.error_code
    }

    /// What the Atom knows about servo `index` (0..6 = joints 1..6, 6 = gripper).
    pub fn servo_health(&self, index: usize) -> Option<&ServoHealth> {
        self.health.get(index)
    }

    /// Present joint angles, from the servos' last reported positions.
    pub fn present_angles(&self) -> [Centideg; JOINTS] {
        core::array::from_fn(|j| {
            let steps = self.health.get(j).map(|h| h.position).unwrap_or_default();
            self.config.steps_to_angle(j, steps)
        })
    }
}
