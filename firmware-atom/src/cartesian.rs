//! Coordinates: the kinematics model with the selected tool and world frames, and the
//! conversions between the host protocol's 16-bit pose and the kinematics' 32-bit one.

use core::cell::Cell;

use kinematics_core::{IkError, JointAngles, Kinematics};
use protocol_core::command::{EndType, MoveMode, Pose, ReferenceFrame};
use protocol_core::units::{Centideg, DeciMm};

use crate::config::{JOINTS, JointLimit};

/// The kinematics with the frames the host selected (0x81..0x8A). The frames are private:
/// every setter re-applies them to the model, so the model always matches what they say.
#[derive(Clone, Debug)]
pub struct Cartesian {
    kin: Kinematics,
    /// Tool pose in the flange frame (0x81).
    tool: Pose,
    /// Base pose in the world frame (0x83).
    world: Pose,
    /// Reference frame of reported and commanded coordinates (0x85).
    reference: ReferenceFrame,
    /// End type: flange or tool tip (0x89).
    end: EndType,
    /// Default interpolation of send coords without a mode byte (0x87).
    movement: MoveMode,
    /// FK of the last angles asked about, so repeated queries of an arm at rest cost nothing.
    cache: Cell<Option<([Centideg; JOINTS], Pose)>>,
}

impl Cartesian {
    /// Flange in the base frame, joint interpolation, limits `limits`.
    pub fn new(limits: &[JointLimit; JOINTS]) -> Self {
        let mut c = Self {
            kin: Kinematics::new(),
            tool: Pose::default(),
            world: Pose::default(),
            reference: ReferenceFrame::Base,
            end: EndType::Flange,
            movement: MoveMode::Joint,
            cache: Cell::new(None),
        };
        c.set_limits(limits);
        c
    }

    /// Applies new joint limits to the IK's branch selection.
    pub fn set_limits(&mut self, limits: &[JointLimit; JOINTS]) {
        let mut l = kinematics_core::JointLimits::default();
        for (j, lim) in limits.iter().enumerate() {
            if let (Some(min), Some(max)) = (l.min.get_mut(j), l.max.get_mut(j)) {
                *min = i32::from(lim.min.0);
                *max = i32::from(lim.max.0);
            }
        }
        self.kin.set_limits(l);
    }

    /// Tool pose in the flange frame (0x82).
    pub fn tool(&self) -> Pose {
        self.tool
    }

    /// Sets the tool pose (0x81).
    pub fn set_tool(&mut self, pose: Pose) {
        self.tool = pose;
        self.apply_frames();
    }

    /// Base pose in the world frame (0x84).
    pub fn world(&self) -> Pose {
        self.world
    }

    /// Sets the base pose in the world frame (0x83).
    pub fn set_world(&mut self, pose: Pose) {
        self.world = pose;
        self.apply_frames();
    }

    /// Reference frame of reported and commanded coordinates (0x86).
    pub fn reference(&self) -> ReferenceFrame {
        self.reference
    }

    /// Sets the reference frame (0x85).
    pub fn set_reference(&mut self, frame: ReferenceFrame) {
        self.reference = frame;
        self.apply_frames();
    }

    /// End type: flange or tool tip (0x8A).
    pub fn end(&self) -> EndType {
        self.end
    }

    /// Sets the end type (0x89).
    pub fn set_end(&mut self, end: EndType) {
        self.end = end;
        self.apply_frames();
    }

    /// Default interpolation of send coords without a mode byte (0x88).
    pub fn movement(&self) -> MoveMode {
        self.movement
    }

    /// Sets the default interpolation (0x87); the model does not depend on it.
    pub fn set_movement(&mut self, mode: MoveMode) {
        self.movement = mode;
    }

    /// Applies the tool/world selection to the model after one of the frame settings changed.
    fn apply_frames(&mut self) {
        let tool = (self.end == EndType::Tool).then(|| to_kin(&self.tool));
        let world = (self.reference == ReferenceFrame::World).then(|| to_kin(&self.world));
        self.kin.set_tool(tool);
        self.kin.set_world(world);
        self.cache.set(None);
    }

    /// The end pose at joint angles `angles`.
    pub fn forward(&self, angles: &[Centideg; JOINTS]) -> Pose {
        if let Some((a, p)) = self.cache.get()
            && a == *angles
        {
            return p;
        }
        let pose = from_kin(&self.kin.forward(&joints(angles)));
        self.cache.set(Some((*angles, pose)));
        pose
    }

    /// The joint angles that put the end at `pose`, on the branch nearest `seed`.
    pub fn inverse(
        &self,
        pose: &Pose,
        seed: &[Centideg; JOINTS],
    ) -> Result<[Centideg; JOINTS], IkError> {
        let q = self.kin.inverse(&to_kin(pose), &joints(seed))?;
        Ok(angles(&q))
    }

    /// The kinematics model (for linear paths).
    pub fn model(&self) -> &Kinematics {
        &self.kin
    }
}

/// Protocol joint angles as kinematics joint angles.
pub fn joints(angles: &[Centideg; JOINTS]) -> JointAngles {
    JointAngles(angles.map(|a| i32::from(a.0)))
}

/// Kinematics joint angles as protocol angles (saturated to +-327.67 deg).
pub fn angles(q: &JointAngles) -> [Centideg; JOINTS] {
    q.0.map(|v| Centideg(sat(v)))
}

/// Client bounds of x and y, tenths of a millimetre: pymycobot refuses beyond +-281.45 mm.
const CLIENT_XY_MAX: i16 = 2814;
/// Client bounds of z, tenths of a millimetre: pymycobot refuses outside -70..412.67 mm.
const CLIENT_Z_RANGE: (i16, i16) = (-700, 4126);

/// A pose as reported to the host. pymycobot refuses to send coordinates past its bounds
/// (x, y +-281.45 mm, z -70..412.67 mm), and the arm reaches exactly those bounds (the zero
/// pose is at z = 412.67 mm, which rounds to 412.7): a value that rounding alone put one wire
/// unit (0.1 mm) past a bound is reported at the bound, so a pose read back can always be sent
/// again. Values farther out (a tilted flange above 412.67 mm, a world frame) are reported as
/// they are.
pub fn for_client(mut p: Pose) -> Pose {
    let pull_in = |v: i16, min: i16, max: i16| match v {
        v if v == max + 1 => max,
        v if v == min - 1 => min,
        v => v,
    };
    p.x.0 = pull_in(p.x.0, -CLIENT_XY_MAX, CLIENT_XY_MAX);
    p.y.0 = pull_in(p.y.0, -CLIENT_XY_MAX, CLIENT_XY_MAX);
    p.z.0 = pull_in(p.z.0, CLIENT_Z_RANGE.0, CLIENT_Z_RANGE.1);
    p
}

/// A protocol pose as a kinematics pose.
pub fn to_kin(p: &Pose) -> kinematics_core::Pose {
    kinematics_core::Pose {
        x: i32::from(p.x.0),
        y: i32::from(p.y.0),
        z: i32::from(p.z.0),
        rx: i32::from(p.rx.0),
        ry: i32::from(p.ry.0),
        rz: i32::from(p.rz.0),
    }
}

/// A kinematics pose as a protocol pose (each value saturated to int16).
pub fn from_kin(p: &kinematics_core::Pose) -> Pose {
    Pose {
        x: DeciMm(sat(p.x)),
        y: DeciMm(sat(p.y)),
        z: DeciMm(sat(p.z)),
        rx: Centideg(sat(p.rx)),
        ry: Centideg(sat(p.ry)),
        rz: Centideg(sat(p.rz)),
    }
}

fn sat(v: i32) -> i16 {
    v.clamp(i32::from(i16::MIN), i32::from(i16::MAX)) as i16
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::config::DEFAULT_LIMITS;

    #[test]
    fn zero_pose_matches_the_vendor_model() {
        let c = Cartesian::new(&DEFAULT_LIMITS);
        let p = c.forward(&[Centideg(0); JOINTS]);
        // docs/kinematics.md: flange at (45.6, -63.4, 412.67) mm, (-90, 0, -90) deg.
        assert!((i32::from(p.x.0) - 456).abs() <= 1, "{p:?}");
        assert!((i32::from(p.y.0) + 634).abs() <= 1, "{p:?}");
        assert!((i32::from(p.z.0) - 4127).abs() <= 1, "{p:?}");
    }

    #[test]
    fn reported_poses_stay_sendable_but_are_not_clamped_further() {
        let pose = |x, y, z| Pose {
            x: DeciMm(x),
            y: DeciMm(y),
            z: DeciMm(z),
            ..Pose::default()
        };
        // One wire unit past pymycobot's bounds: rounding, reported at the bound.
        assert_eq!(for_client(pose(2815, -2815, 4127)), pose(2814, -2814, 4126));
        assert_eq!(for_client(pose(0, 0, -701)), pose(0, 0, -700));
        // Inside, or truly outside (a tilted flange, a world frame): unchanged.
        for p in [pose(2814, 0, 4126), pose(2900, 0, 4250), pose(0, 0, -800)] {
            assert_eq!(for_client(p), p);
        }
    }
}
