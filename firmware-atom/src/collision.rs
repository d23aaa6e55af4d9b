//! Collision protection: a joint that presses without moving has hit something, or someone.
//!
//! The Atom feels contact only through what the servos report in their state reads
//! ([`ServoHealth`]): a servo's position loop drives its shaft towards where the motion wants
//! it; when something holds the shaft back, the shaft stops while the loop's torque (the
//! present load) rises towards the torque limit. The detector watches each joint's load and
//! speed: a load at or above the joint's limit ([`load_limit_permille`] of its threshold) on a
//! shaft that is held back (turning slower than [`STALL_SPEED_STEPS`]) or driven back (turning
//! against the motor's torque), or a load [`MOVING_MARGIN_PERMILLE`] above the limit on a shaft
//! that still turns (a push against a moving joint), in [`CONFIRM_READS`] state reads in a row
//! (one read every ~4.4 ms), is a collision. Speeding the arm up loads a servo too, but the
//! shaft turns with the torque then and the load stays below the margin; an obstacle holds the
//! shaft, a push stronger than the motor drives it back. The gripper (servo 7) is not watched:
//! it is made to press on what it holds.
//!
//! A detected collision is latched ([`CollisionDetector::collision`]) until cleared (0x08 clear
//! error information, or 0x10 power on); the Atom stops the arm, sets the blocked joint's goal
//! where it stands, and refuses motion with the collision's error code ([`Collision::code`])
//! meanwhile. Settings (0x74 / 0xFD mode, 0x75 / 0x76 thresholds) are [`CollisionSettings`].

use core::ops::RangeInclusive;

use protocol_core::servo::fault;

use flash_store::StoreError;

use crate::config::JOINTS;
use crate::health::ServoHealth;
use crate::store::{COLLISION_SETTINGS_KEY, ParamStore};

/// The thresholds a joint may have (pymycobot's range; smaller triggers more easily).
pub const THRESHOLDS: RangeInclusive<u8> = 50..=250;
/// Whether collision protection is on until the host switches it (0x74) or the flash says
/// otherwise. Chosen from the benchmark `collision` (docs/motion.md): no false alarm over its
/// corpus at the default threshold.
pub const DEFAULT_PROTECTION: bool = true;
/// Every joint's threshold until the host sets one (pymycobot's default).
pub const DEFAULT_THRESHOLD: u8 = 100;
/// A shaft turning slower than this (steps/s, 8.8 deg/s) while it presses is held back.
pub const STALL_SPEED_STEPS: i16 = 100;
/// State reads in a row that must show a pressing joint.
pub const CONFIRM_READS: u8 = 2;
/// How far above its limit the load of a joint that still turns must be to count as pressing:
/// more than speeding the arm up ever needs (thousandths of the servo's maximum torque), so a
/// push against a moving joint is felt before the move ends.
pub const MOVING_MARGIN_PERMILLE: i16 = 250;

/// The present load (thousandths of the servo's maximum torque) at which a joint with
/// `threshold` counts as pressing: 350 at 50, 500 at the default 100, 950 at 250. Free motion
/// loads a servo with 180 and up to 200 more while it speeds up at its full acceleration.
pub const fn load_limit_permille(threshold: u8) -> i16 {
    200 + 3 * threshold as i16
}

/// What the host set for collision protection; kept in flash ([`CollisionSettings::to_bytes`]).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct CollisionSettings {
    enabled: bool,
    thresholds: [u8; JOINTS],
}

/// A threshold outside [`THRESHOLDS`] or a joint outside 1..=6: nothing was changed.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct BadThreshold;

impl CollisionSettings {
    /// Length of [`CollisionSettings::to_bytes`].
    pub const BYTES: usize = 1 + JOINTS;

    /// Protection `enabled` or not, every joint at [`DEFAULT_THRESHOLD`].
    pub const fn new(enabled: bool) -> Self {
        Self {
            enabled,
            thresholds: [DEFAULT_THRESHOLD; JOINTS],
        }
    }

    /// True while collisions are detected (0x74 1).
    pub fn enabled(&self) -> bool {
        self.enabled
    }

    /// Switches detection on or off (0x74).
    pub fn set_enabled(&mut self, enabled: bool) {
        self.enabled = enabled;
    }

    /// Every joint's threshold, joints 1..=6 (0x76).
    pub fn thresholds(&self) -> [u8; JOINTS] {
        self.thresholds
    }

    /// Joint `index`'s (0-based) threshold; the default for an index without a joint.
    pub fn threshold(&self, index: usize) -> u8 {
        self.thresholds
            .get(index)
            .copied()
            .unwrap_or(DEFAULT_THRESHOLD)
    }

    /// Sets joint `joint`'s (1..=6) threshold to `value` (0x75); refused outside the ranges.
    pub fn set_threshold(&mut self, joint: u8, value: u8) -> Result<(), BadThreshold> {
        if !THRESHOLDS.contains(&value) {
            return Err(BadThreshold);
        }
        let slot = usize::from(joint)
            .checked_sub(1)
            .and_then(|index| self.thresholds.get_mut(index))
            .ok_or(BadThreshold)?;
        *slot = value;
        Ok(())
    }

    /// The settings as stored in flash: the mode, then the six thresholds.
    pub fn to_bytes(&self) -> [u8; Self::BYTES] {
        let mut bytes = [0; Self::BYTES];
        bytes[0] = u8::from(self.enabled);
        for (slot, &t) in bytes.iter_mut().skip(1).zip(&self.thresholds) {
            *slot = t;
        }
        bytes
    }

    /// The settings kept in `store` ([`COLLISION_SETTINGS_KEY`]); `None` if there are none or
    /// the record is not a valid one.
    pub fn load(store: &mut dyn ParamStore) -> Option<Self> {
        let mut bytes = [0; Self::BYTES];
        let len = store.fetch(COLLISION_SETTINGS_KEY, &mut bytes).ok()??;
        Self::from_bytes(bytes.get(..len)?)
    }

    /// Makes `changed` these settings, kept in `store` first so they survive a restart (a board
    /// without a store keeps them until it restarts); settings that do not change are not
    /// written again. A flash that fails changes nothing.
    pub fn replace_kept(
        &mut self,
        changed: Self,
        store: Option<&mut dyn ParamStore>,
    ) -> Result<(), StoreError> {
        if changed == *self {
            // Nothing to keep: a script that sets the same mode on every run wears no flash
            // and stalls nothing.
            return Ok(());
        }
        if let Some(store) = store {
            changed.save(store)?;
        }
        *self = changed;
        Ok(())
    }

    /// Keeps these settings in `store`, so they survive a restart.
    pub fn save(&self, store: &mut dyn ParamStore) -> Result<(), StoreError> {
        store.store(COLLISION_SETTINGS_KEY, &self.to_bytes())
    }

    /// Settings stored by [`CollisionSettings::to_bytes`]; `None` for anything else (a record
    /// of another length or with a value out of range).
    pub fn from_bytes(bytes: &[u8]) -> Option<Self> {
        let (&mode, thresholds) = bytes.split_first()?;
        if mode > 1 || thresholds.len() != JOINTS {
            return None;
        }
        let mut settings = Self::new(mode == 1);
        for (joint, &value) in (1..).zip(thresholds) {
            settings.set_threshold(joint, value).ok()?;
        }
        Some(settings)
    }
}

/// What the arm was doing when the collision was felt; it chooses the error code
/// ([`Kind::code`]).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Kind {
    /// Moving in joint space: angles, encoders, jogs, streams (code 16).
    JointMotion,
    /// Moving in Cartesian space: coordinates, lines, arcs, coordinate jogs (code 17).
    CartesianMotion,
    /// Holding a pose: no motion running, so someone or something pushed the arm (code 18).
    Holding,
}

/// A detected collision.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct Collision {
    /// The joint that pressed, 0-based.
    pub joint: usize,
    /// What the arm was doing.
    pub kind: Kind,
    /// When the collision was detected (the confirming state read), monotonic microseconds.
    pub at_us: u64,
    /// The joint's present load then, signed thousandths of its maximum torque.
    pub load_permille: i16,
}

impl Kind {
    /// What the arm was doing, in words: "moving joints", "moving in a line or arc",
    /// "holding still".
    pub fn during(self) -> &'static str {
        match self {
            Kind::JointMotion => "moving joints",
            Kind::CartesianMotion => "moving in a line or arc",
            Kind::Holding => "holding still",
        }
    }

    /// The error code get error information (0x07) reports: 16 in a joint-space motion, 17 in
    /// a Cartesian motion, 18 when the arm was holding still (19, the last of pymycobot's
    /// collision codes, is not used).
    pub fn code(self) -> u8 {
        match self {
            Kind::JointMotion => 16,
            Kind::CartesianMotion => 17,
            Kind::Holding => 18,
        }
    }
}

impl Collision {
    /// The error code get error information (0x07) reports ([`Kind::code`]).
    pub fn code(&self) -> u8 {
        self.kind.code()
    }
}

/// Watches the joints' state reads for collisions. See the [module doc](self).
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct CollisionDetector {
    /// Consecutive state reads that showed each joint pressing and held back.
    pressing: [u8; JOINTS],
    /// The collision detected and not yet cleared.
    latched: Option<Collision>,
    /// When the state read of each joint looked at last arrived.
    seen_us: [Option<u64>; JOINTS],
}

impl CollisionDetector {
    /// Looks at joint `joint`'s (0-based) state read that arrived at `read_us`, at `now_us`;
    /// a read already looked at is skipped. Returns the collision it confirms, once (it stays
    /// latched until [`CollisionDetector::clear`]). Nothing is watched while `settings` has
    /// detection off, while a collision is latched, or on a servo that is not answering, has
    /// its torque off, or reports its own overload protection (a servo fault, reported as such).
    pub fn on_state(
        &mut self,
        now_us: u64,
        joint: usize,
        read_us: u64,
        state: &ServoHealth,
        settings: &CollisionSettings,
        kind: Kind,
    ) -> Option<Collision> {
        let seen = self.seen_us.get_mut(joint)?;
        if *seen == Some(read_us) {
            return None;
        }
        *seen = Some(read_us);
        let count = self.pressing.get_mut(joint)?;
        let watched = settings.enabled()
            && self.latched.is_none()
            && state.answering
            && state.torque_reported
            && state.fault_bits & fault::OVERLOAD == 0;
        let load = state.load_permille;
        let speed = state.speed_steps_per_s;
        let limit = load_limit_permille(settings.threshold(joint));
        let held_back = speed.saturating_abs() < STALL_SPEED_STEPS;
        let driven_back = i32::from(load) * i32::from(speed) < 0;
        let pressing = watched
            && (load.saturating_abs() >= limit && (held_back || driven_back)
                || load.saturating_abs() >= limit.saturating_add(MOVING_MARGIN_PERMILLE));
        *count = if pressing { count.saturating_add(1) } else { 0 };
        if *count < CONFIRM_READS {
            return None;
        }
        let collision = Collision {
            joint,
            kind,
            at_us: now_us,
            load_permille: state.load_permille,
        };
        self.latched = Some(collision);
        self.pressing = [0; JOINTS];
        Some(collision)
    }

    /// The collision detected and not cleared yet.
    pub fn collision(&self) -> Option<Collision> {
        self.latched
    }

    /// Forgets the collision (0x08, 0x10): motion is allowed again.
    pub fn clear(&mut self) {
        self.latched = None;
        self.pressing = [0; JOINTS];
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn state(load_permille: i16, speed_steps_per_s: i16) -> ServoHealth {
        ServoHealth {
            answering: true,
            torque_reported: true,
            load_permille,
            speed_steps_per_s,
            ..ServoHealth::default()
        }
    }

    const ON: CollisionSettings = CollisionSettings::new(true);

    #[test]
    fn a_joint_pressing_without_moving_for_two_reads_is_a_collision() {
        let mut detector = CollisionDetector::default();
        let pressing = state(-600, 0);
        assert_eq!(
            detector.on_state(0, 1, 0, &pressing, &ON, Kind::JointMotion),
            None
        );
        let collision = detector
            .on_state(4_400, 1, 4_400, &pressing, &ON, Kind::JointMotion)
            .unwrap();
        assert_eq!(
            (collision.joint, collision.code(), collision.at_us),
            (1, 16, 4_400)
        );
        assert_eq!(detector.collision(), Some(collision));
        assert_eq!(
            detector.on_state(8_800, 1, 8_800, &pressing, &ON, Kind::JointMotion),
            None,
            "reported once"
        );
        detector.clear();
        assert_eq!(detector.collision(), None);
    }

    #[test]
    fn the_same_read_looked_at_twice_counts_once() {
        let mut detector = CollisionDetector::default();
        let pressing = state(700, 0);
        for now in [0, 1_000, 2_000] {
            let again = detector.on_state(now, 4, 0, &pressing, &ON, Kind::Holding);
            assert_eq!(again, None);
        }
        assert!(
            detector
                .on_state(3_000, 4, 2_900, &pressing, &ON, Kind::Holding)
                .is_some()
        );
    }

    #[test]
    fn a_loaded_joint_that_turns_is_speeding_up_not_colliding() {
        let mut detector = CollisionDetector::default();
        for t in 0..10 {
            let speeding_up = state(580, 900);
            assert_eq!(
                detector.on_state(t, 0, t, &speeding_up, &ON, Kind::JointMotion),
                None
            );
        }
    }

    #[test]
    fn a_shaft_driven_against_its_motor_is_pushed() {
        let mut detector = CollisionDetector::default();
        let driven = state(-1000, 1500);
        assert_eq!(
            detector.on_state(0, 2, 0, &driven, &ON, Kind::Holding),
            None
        );
        let pushed = detector.on_state(1, 2, 1, &driven, &ON, Kind::Holding);
        assert_eq!(pushed.map(|c| c.code()), Some(18));
    }

    #[test]
    fn a_moving_joint_loaded_far_beyond_its_limit_is_pushed() {
        let mut detector = CollisionDetector::default();
        let pushed = state(760, 600);
        assert_eq!(
            detector.on_state(0, 0, 0, &pushed, &ON, Kind::JointMotion),
            None
        );
        let felt = detector.on_state(1, 0, 1, &pushed, &ON, Kind::JointMotion);
        assert_eq!(felt.map(|c| c.code()), Some(16));
        let mut just_below = CollisionDetector::default();
        for t in 0..5 {
            let read = state(749, 600);
            assert_eq!(
                just_below.on_state(t, 0, t, &read, &ON, Kind::JointMotion),
                None
            );
        }
    }

    #[test]
    fn one_pressing_read_between_calm_ones_is_not_enough() {
        let mut detector = CollisionDetector::default();
        for (t, load) in [600, 100, 600, 100, 600].into_iter().enumerate() {
            let read = state(load, 0);
            assert_eq!(
                detector.on_state(t as u64, 2, t as u64, &read, &ON, Kind::Holding),
                None
            );
        }
    }

    #[test]
    fn the_threshold_sets_the_load_and_off_feels_nothing() {
        let mut settings = ON;
        settings.set_threshold(4, 250).unwrap();
        let mut detector = CollisionDetector::default();
        let hard = state(900, 0);
        for t in 0..5 {
            assert_eq!(
                detector.on_state(t, 3, t, &hard, &settings, Kind::Holding),
                None
            );
        }
        assert!(
            detector
                .on_state(5, 0, 5, &hard, &settings, Kind::Holding)
                .is_none()
        );
        let pushed = detector
            .on_state(6, 0, 6, &hard, &settings, Kind::Holding)
            .unwrap();
        assert_eq!(pushed.code(), 18);
        let mut off = CollisionDetector::default();
        for t in 0..5 {
            assert_eq!(
                off.on_state(
                    t,
                    0,
                    t,
                    &hard,
                    &CollisionSettings::new(false),
                    Kind::Holding
                ),
                None
            );
        }
    }

    #[test]
    fn a_servo_reporting_its_own_overload_is_a_fault_not_a_collision() {
        let mut detector = CollisionDetector::default();
        let overloaded = ServoHealth {
            fault_bits: fault::OVERLOAD,
            ..state(980, 0)
        };
        for t in 0..5 {
            assert_eq!(
                detector.on_state(t, 1, t, &overloaded, &ON, Kind::JointMotion),
                None
            );
        }
    }

    #[test]
    fn thresholds_outside_50_to_250_or_joints_outside_1_to_6_change_nothing() {
        let mut settings = CollisionSettings::new(false);
        for (joint, value) in [(0, 100), (7, 100), (1, 49), (1, 251)] {
            assert_eq!(settings.set_threshold(joint, value), Err(BadThreshold));
        }
        assert_eq!(settings.thresholds(), [DEFAULT_THRESHOLD; JOINTS]);
        settings.set_threshold(6, 50).unwrap();
        settings.set_enabled(true);
        let stored = settings.to_bytes();
        assert_eq!(stored, [1, 100, 100, 100, 100, 100, 50]);
        assert_eq!(CollisionSettings::from_bytes(&stored), Some(settings));
        assert_eq!(
            CollisionSettings::from_bytes(&[2, 100, 100, 100, 100, 100, 100]),
            None
        );
        assert_eq!(
            CollisionSettings::from_bytes(&[1, 100, 100, 100, 100, 100, 20]),
            None
        );
        assert_eq!(CollisionSettings::from_bytes(&[1, 100]), None);
    }

    #[test]
    fn settings_survive_in_the_store_and_a_bad_record_is_ignored() {
        let mut store = crate::store::test_support::Memory::default();
        assert_eq!(CollisionSettings::load(&mut store), None);
        let mut settings = CollisionSettings::new(true);
        settings.set_threshold(2, 180).unwrap();
        settings.save(&mut store).unwrap();
        assert_eq!(CollisionSettings::load(&mut store), Some(settings));
        store.store(COLLISION_SETTINGS_KEY, &[7, 7]).unwrap();
        assert_eq!(CollisionSettings::load(&mut store), None);
    }

    #[test]
    fn a_change_is_kept_and_the_same_settings_are_not_written_again() {
        let mut store = crate::store::test_support::Memory::default();
        let mut settings = CollisionSettings::new(true);
        settings.replace_kept(settings, Some(&mut store)).unwrap();
        assert_eq!(CollisionSettings::load(&mut store), None, "nothing written");
        let off = CollisionSettings::new(false);
        settings.replace_kept(off, Some(&mut store)).unwrap();
        assert_eq!(
            (settings, CollisionSettings::load(&mut store)),
            (off, Some(off))
        );
        settings
            .replace_kept(CollisionSettings::new(true), None)
            .unwrap();
        assert!(
            settings.enabled(),
            "a board without a store keeps it until it restarts"
        );
    }
}
