//! The protocol's units as distinct types, so a tenth-millimetre is never added to a
//! centidegree. Wire encodings are in `protocol.md` section 4.

/// An angle in hundredths of a degree (joint angles, rx/ry/rz on the wire).
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, PartialOrd, Ord, Hash)]
pub struct Centideg(pub i16);

/// An angle in tenths of a degree (joint limits 0x4A..0x4D on the wire).
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, PartialOrd, Ord, Hash)]
pub struct Decideg(pub i16);

/// A length in tenths of a millimetre (x, y, z on the wire).
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, PartialOrd, Ord, Hash)]
pub struct DeciMm(pub i16);

/// A raw servo position in encoder steps, 0..4095, 2048 = 0 deg, 4096 steps per turn.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, PartialOrd, Ord, Hash)]
pub struct Steps(pub i16);

/// A speed in percent of the maximum, always 1..=100.
#[derive(Clone, Copy, Debug, PartialEq, Eq, PartialOrd, Ord, Hash)]
pub struct SpeedPercent(u8);

impl SpeedPercent {
    /// Full speed.
    pub const MAX: Self = Self(100);

    /// A speed; `None` outside 1..=100.
    pub const fn new(percent: u8) -> Option<Self> {
        if percent >= 1 && percent <= 100 {
            Some(Self(percent))
        } else {
            None
        }
    }

    /// The percentage, 1..=100.
    pub const fn get(self) -> u8 {
        self.0
    }
}

impl Default for SpeedPercent {
    fn default() -> Self {
        Self::MAX
    }
}
