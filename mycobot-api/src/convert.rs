//! Degrees and millimetres to and from the protocol's units, rounded to the nearest unit and
//! saturated at the int16 range (NaN becomes 0).
//!
//! ```
//! use mycobot_api::convert::{deg, mm, pose, to_deg};
//! use protocol_core::units::{Centideg, DeciMm};
//!
//! assert_eq!(deg(-12.345), Centideg(-1235));
//! assert_eq!(to_deg(Centideg(9000)), 90.0);
//! assert_eq!(mm(150.04), DeciMm(1500));
//! assert_eq!(pose([150.0, 0.0, 200.0, -180.0, 0.0, 90.0]).z, DeciMm(2000));
//! ```

use protocol_core::command::Pose;
use protocol_core::units::{Centideg, DeciMm, Decideg};

/// `v` rounded half away from zero to an int16.
fn round(v: f32) -> i16 {
    let r = if v >= 0.0 { v + 0.5 } else { v - 0.5 };
    // `as` saturates and maps NaN to 0.
    r as i16
}

/// An angle in degrees as hundredths of a degree (joint angles, rx, ry, rz).
pub fn deg(degrees: f32) -> Centideg {
    Centideg(round(degrees * 100.0))
}

/// Six angles in degrees, joints 1..6.
pub fn angles(degrees: [f32; 6]) -> [Centideg; 6] {
    degrees.map(deg)
}

/// An angle in degrees as tenths of a degree (joint limits).
pub fn limit_deg(degrees: f32) -> Decideg {
    Decideg(round(degrees * 10.0))
}

/// A length in millimetres as tenths of a millimetre (x, y, z).
pub fn mm(millimetres: f32) -> DeciMm {
    DeciMm(round(millimetres * 10.0))
}

/// A pose from x, y, z in millimetres and rx, ry, rz in degrees.
pub fn pose(v: [f32; 6]) -> Pose {
    let [x, y, z, rx, ry, rz] = v;
    Pose {
        x: mm(x),
        y: mm(y),
        z: mm(z),
        rx: deg(rx),
        ry: deg(ry),
        rz: deg(rz),
    }
}

/// Hundredths of a degree in degrees.
pub fn to_deg(angle: Centideg) -> f32 {
    f32::from(angle.0) / 100.0
}

/// Tenths of a degree in degrees.
pub fn limit_to_deg(angle: Decideg) -> f32 {
    f32::from(angle.0) / 10.0
}

/// Tenths of a millimetre in millimetres.
pub fn to_mm(length: DeciMm) -> f32 {
    f32::from(length.0) / 10.0
}

/// A pose as x, y, z in millimetres and rx, ry, rz in degrees.
pub fn pose_to_mm_deg(p: &Pose) -> [f32; 6] {
    [
        to_mm(p.x),
        to_mm(p.y),
        to_mm(p.z),
        to_deg(p.rx),
        to_deg(p.ry),
        to_deg(p.rz),
    ]
}
