//! What the arm's state is written in: [`JointAngles`] and the flange's [`Pose`].

/// Joint angles q (protocol angles, not DH theta), centidegrees, joints 1..6.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Default)]
pub struct JointAngles(pub [i32; 6]);

/// A pose: x, y, z in tenths of a millimetre; rx, ry, rz in centidegrees,
/// R = Rz(rz) * Ry(ry) * Rx(rx).
#[derive(Clone, Copy, Debug, PartialEq, Eq, Default)]
pub struct Pose {
    /// x, 0.1 mm.
    pub x: i32,
    /// y, 0.1 mm.
    pub y: i32,
    /// z, 0.1 mm.
    pub z: i32,
    /// Roll about the fixed x axis, 0.01 deg.
    pub rx: i32,
    /// Pitch about the fixed y axis, 0.01 deg.
    pub ry: i32,
    /// Yaw about the fixed z axis, 0.01 deg.
    pub rz: i32,
}
