//! Validated field types of host commands: each one can only hold a value the protocol allows,
//! so a parsed [`Request`](super::Request) never carries joint 9 or speed 0.

use crate::units::{Centideg, DeciMm};

/// Declares a one-byte newtype that can only hold the values matching `$allowed`: `new`
/// checks, `get` gives the wire byte back.
macro_rules! checked_byte {
    ($(#[$meta:meta])* $name:ident($allowed:pat), $what:literal) => {
        $(#[$meta])*
        #[derive(Clone, Copy, Debug, PartialEq, Eq, PartialOrd, Ord, Hash)]
        pub struct $name(u8);

        impl $name {
            #[doc = concat!("A ", $what, "; `None` for a value the protocol does not allow.")]
            pub const fn new(v: u8) -> Option<Self> {
                if matches!(v, $allowed) { Some(Self(v)) } else { None }
            }

            /// The wire byte.
            pub const fn get(self) -> u8 {
                self.0
            }
        }
    };
}

checked_byte!(
    /// An arm joint, 1..=6 (1 = base, 6 = flange rotation). The wire byte is the number itself.
    JointId(1..=6),
    "joint"
);

impl JointId {
    /// Zero-based index into a six-joint array, 0..=5.
    pub const fn index(self) -> usize {
        self.0 as usize - 1
    }

    /// All six joints in order.
    pub fn all() -> impl Iterator<Item = Self> {
        (1..=6).map(Self)
    }
}

checked_byte!(
    /// A joint's collision threshold, 50..=250 (0x75; pymycobot's range, default 100): the
    /// smaller, the more easily a collision is detected.
    CollisionThreshold(50..=250),
    "collision threshold"
);

checked_byte!(
    /// A servo of the arm, 1..=7: the six joints and the gripper servo (7). The Atom maps it
    /// onto a bus id (`AtomConfig::servo_ids`, the same numbers on a factory arm).
    ServoId(1..=7),
    "servo"
);

impl ServoId {
    /// Zero-based index into a seven-servo array, 0..=6 (6 = the gripper).
    pub const fn index(self) -> usize {
        self.0 as usize - 1
    }

    /// The arm joint this servo drives, or `None` for the gripper.
    pub const fn joint(self) -> Option<JointId> {
        JointId::new(self.0)
    }
}

impl From<JointId> for ServoId {
    fn from(j: JointId) -> Self {
        Self(j.0)
    }
}

/// One servo or all of them. On the wire "all" is `0` for focus servo (0x57) and `254` for
/// backup/restore servo parameters (0xEA/0xEB).
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub enum ServoSelect {
    /// Every servo.
    All,
    /// One servo.
    One(ServoId),
}

/// A Cartesian axis of a pose: 1..=6 on the wire = x, y, z, rx, ry, rz.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub enum Axis {
    /// x, tenths of a millimetre.
    X = 1,
    /// y, tenths of a millimetre.
    Y = 2,
    /// z, tenths of a millimetre.
    Z = 3,
    /// Rotation about x, hundredths of a degree.
    Rx = 4,
    /// Rotation about y, hundredths of a degree.
    Ry = 5,
    /// Rotation about z, hundredths of a degree.
    Rz = 6,
}

impl Axis {
    /// All six axes in wire order.
    pub const ALL: [Self; 6] = [Self::X, Self::Y, Self::Z, Self::Rx, Self::Ry, Self::Rz];

    /// The axis for wire byte 1..=6.
    pub const fn from_u8(v: u8) -> Option<Self> {
        match v {
            1 => Some(Self::X),
            2 => Some(Self::Y),
            3 => Some(Self::Z),
            4 => Some(Self::Rx),
            5 => Some(Self::Ry),
            6 => Some(Self::Rz),
            _ => None,
        }
    }

    /// The axis for the axis byte of send coord (0x24). pymycobot numbers the axes 1..=6
    /// (x..rz), the seed manual and MyCobotBasic's `writeCoord` 0..=5. Only 0 (x in the seed's
    /// numbering, no axis in pymycobot's) and 6 (rz, pymycobot's only) say which numbering they
    /// use; 1..=5 follow pymycobot, the reference client (`protocol.md`: the clients win).
    pub const fn from_send_coord_byte(v: u8) -> Option<Self> {
        match v {
            0 => Some(Self::X),
            v => Self::from_u8(v),
        }
    }

    /// Zero-based index into a pose array (x, y, z, rx, ry, rz).
    pub const fn index(self) -> usize {
        self as usize - 1
    }
}

/// A value along one [`Axis`], in that axis's unit, so a length is never read as an angle.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub enum AxisValue {
    /// x.
    X(DeciMm),
    /// y.
    Y(DeciMm),
    /// z.
    Z(DeciMm),
    /// rx.
    Rx(Centideg),
    /// ry.
    Ry(Centideg),
    /// rz.
    Rz(Centideg),
}

impl AxisValue {
    /// The value `raw` (wire int16) along `axis`.
    pub const fn new(axis: Axis, raw: i16) -> Self {
        match axis {
            Axis::X => Self::X(DeciMm(raw)),
            Axis::Y => Self::Y(DeciMm(raw)),
            Axis::Z => Self::Z(DeciMm(raw)),
            Axis::Rx => Self::Rx(Centideg(raw)),
            Axis::Ry => Self::Ry(Centideg(raw)),
            Axis::Rz => Self::Rz(Centideg(raw)),
        }
    }

    /// The axis.
    pub const fn axis(self) -> Axis {
        match self {
            Self::X(_) => Axis::X,
            Self::Y(_) => Axis::Y,
            Self::Z(_) => Axis::Z,
            Self::Rx(_) => Axis::Rx,
            Self::Ry(_) => Axis::Ry,
            Self::Rz(_) => Axis::Rz,
        }
    }

    /// The wire int16 (tenths of a millimetre or hundredths of a degree).
    pub const fn raw(self) -> i16 {
        match self {
            Self::X(v) | Self::Y(v) | Self::Z(v) => v.0,
            Self::Rx(v) | Self::Ry(v) | Self::Rz(v) => v.0,
        }
    }
}

/// A pose on the wire: position in tenths of a millimetre, fixed-axis roll-pitch-yaw
/// orientation in hundredths of a degree (R = Rz(rz) * Ry(ry) * Rx(rx)).
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Hash)]
pub struct Pose {
    /// x.
    pub x: DeciMm,
    /// y.
    pub y: DeciMm,
    /// z.
    pub z: DeciMm,
    /// Roll, about the fixed x axis.
    pub rx: Centideg,
    /// Pitch, about the fixed y axis.
    pub ry: Centideg,
    /// Yaw, about the fixed z axis.
    pub rz: Centideg,
}

impl Pose {
    /// The six wire int16 values in order x, y, z, rx, ry, rz.
    pub const fn to_array(&self) -> [i16; 6] {
        [
            self.x.0, self.y.0, self.z.0, self.rx.0, self.ry.0, self.rz.0,
        ]
    }

    /// A pose from six wire int16 values in order x, y, z, rx, ry, rz.
    pub const fn from_array(v: [i16; 6]) -> Self {
        let [x, y, z, rx, ry, rz] = v;
        Self {
            x: DeciMm(x),
            y: DeciMm(y),
            z: DeciMm(z),
            rx: Centideg(rx),
            ry: Centideg(ry),
            rz: Centideg(rz),
        }
    }

    /// The value along `axis`.
    pub const fn get(&self, axis: Axis) -> AxisValue {
        match axis {
            Axis::X => AxisValue::X(self.x),
            Axis::Y => AxisValue::Y(self.y),
            Axis::Z => AxisValue::Z(self.z),
            Axis::Rx => AxisValue::Rx(self.rx),
            Axis::Ry => AxisValue::Ry(self.ry),
            Axis::Rz => AxisValue::Rz(self.rz),
        }
    }

    /// This pose with one axis replaced.
    pub const fn with(mut self, value: AxisValue) -> Self {
        match value {
            AxisValue::X(v) => self.x = v,
            AxisValue::Y(v) => self.y = v,
            AxisValue::Z(v) => self.z = v,
            AxisValue::Rx(v) => self.rx = v,
            AxisValue::Ry(v) => self.ry = v,
            AxisValue::Rz(v) => self.rz = v,
        }
        self
    }
}

/// An axis of the base frame for jog rpy (0x31): 1 roll (about x), 2 pitch (y), 3 yaw (z).
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub enum RpyAxis {
    /// About the base x axis.
    Roll = 1,
    /// About the base y axis.
    Pitch = 2,
    /// About the base z axis.
    Yaw = 3,
}

impl RpyAxis {
    /// The axis for wire byte 1..=3.
    pub const fn from_u8(v: u8) -> Option<Self> {
        match v {
            1 => Some(Self::Roll),
            2 => Some(Self::Pitch),
            3 => Some(Self::Yaw),
            _ => None,
        }
    }
}

/// Jog direction: wire 0 = negative, 1 = positive.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub enum Direction {
    /// Decreasing angle / coordinate.
    Negative = 0,
    /// Increasing angle / coordinate.
    Positive = 1,
}

impl Direction {
    /// The direction for wire byte 0/1.
    pub const fn from_u8(v: u8) -> Option<Self> {
        match v {
            0 => Some(Self::Negative),
            1 => Some(Self::Positive),
            _ => None,
        }
    }

    /// +1 or -1.
    pub const fn sign(self) -> i32 {
        match self {
            Self::Negative => -1,
            Self::Positive => 1,
        }
    }
}

/// How a Cartesian move is interpolated: wire 0 = in joint space, 1 = straight line.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub enum MoveMode {
    /// Joint-interpolated (the end follows a curve).
    Joint = 0,
    /// Straight line in Cartesian space.
    Linear = 1,
}

impl MoveMode {
    /// The mode for wire byte 0/1.
    pub const fn from_u8(v: u8) -> Option<Self> {
        match v {
            0 => Some(Self::Joint),
            1 => Some(Self::Linear),
            _ => None,
        }
    }
}

/// The frame coordinates are expressed in: wire 0 = robot base, 1 = world.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub enum ReferenceFrame {
    /// The robot base frame.
    Base = 0,
    /// The world frame set with 0x83.
    World = 1,
}

impl ReferenceFrame {
    /// The frame for wire byte 0/1.
    pub const fn from_u8(v: u8) -> Option<Self> {
        match v {
            0 => Some(Self::Base),
            1 => Some(Self::World),
            _ => None,
        }
    }
}

/// The point coordinates refer to: wire 0 = flange, 1 = tool tip (set with 0x81).
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub enum EndType {
    /// The flange.
    Flange = 0,
    /// The tool tip.
    Tool = 1,
}

impl EndType {
    /// The end for wire byte 0/1.
    pub const fn from_u8(v: u8) -> Option<Self> {
        match v {
            0 => Some(Self::Flange),
            1 => Some(Self::Tool),
            _ => None,
        }
    }
}

/// What the fields of is-in-position (0x2A) are: wire flag 0 = joint angles, 1 = coords.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub enum PositionTarget {
    /// Six joint angles.
    Angles([Centideg; 6]),
    /// A pose.
    Coords(Pose),
}

/// Mode of an Atom pin (0x60): wire 0 input, 1 output, 2 input with pull-up.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub enum PinMode {
    /// Floating input.
    Input = 0,
    /// Push-pull output.
    Output = 1,
    /// Input with the internal pull-up.
    InputPullUp = 2,
}

impl PinMode {
    /// The mode for wire byte 0..=2.
    pub const fn from_u8(v: u8) -> Option<Self> {
        match v {
            0 => Some(Self::Input),
            1 => Some(Self::Output),
            2 => Some(Self::InputPullUp),
            _ => None,
        }
    }
}

/// A user pin of the Atom (`protocol.md` section 5): GPIO 19, 22, 23, 33, and 39 (the
/// button, input only).
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub struct AtomPin(u8);

impl AtomPin {
    /// GPIO numbers of the Atom that clients may use.
    pub const ALLOWED: [u8; 5] = [19, 22, 23, 33, 39];
    /// The one input-only pin (the button).
    pub const BUTTON: u8 = 39;

    /// A pin; `None` for a GPIO clients may not use.
    pub fn new(gpio: u8) -> Option<Self> {
        Self::ALLOWED.contains(&gpio).then_some(Self(gpio))
    }

    /// A pin that can drive an output or PWM; `None` for 39 and unknown GPIOs.
    pub fn output(gpio: u8) -> Option<Self> {
        Self::new(gpio).filter(|p| p.can_output())
    }

    /// The GPIO number.
    pub const fn gpio(self) -> u8 {
        self.0
    }

    /// False for the input-only button pin.
    pub const fn can_output(self) -> bool {
        self.0 != Self::BUTTON
    }
}

checked_byte!(
    /// An output of the Basic (0xA0): GPIO 2, or 5 (drives the suction-pump valve).
    BasicOutputPin(2 | 5),
    "Basic output pin"
);

impl BasicOutputPin {
    /// GPIO numbers allowed.
    pub const ALLOWED: [u8; 2] = [2, 5];

    /// The GPIO number.
    pub const fn gpio(self) -> u8 {
        self.0
    }
}

checked_byte!(
    /// An input of the Basic (0xA1): GPIO 35 or 36.
    BasicInputPin(35 | 36),
    "Basic input pin"
);

impl BasicInputPin {
    /// GPIO numbers allowed.
    pub const ALLOWED: [u8; 2] = [35, 36];

    /// The GPIO number.
    pub const fn gpio(self) -> u8 {
        self.0
    }
}

/// What set gripper state (0x66) asks for: wire 0 open, 1 close, 254 release (torque off).
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub enum GripperState {
    /// Open fully.
    Open = 0,
    /// Close fully.
    Close = 1,
    /// Torque off.
    Release = 254,
}

impl GripperState {
    /// The state for wire byte 0, 1 or 254.
    pub const fn from_u8(v: u8) -> Option<Self> {
        match v {
            0 => Some(Self::Open),
            1 => Some(Self::Close),
            254 => Some(Self::Release),
            _ => None,
        }
    }
}

checked_byte!(
    /// Gripper speed in percent, 0..=100 (pymycobot allows 0: `gripper_stop` sends it).
    GripperSpeed(0..=100),
    "gripper speed in percent"
);

checked_byte!(
    /// Gripper opening in percent, 0 (closed) ..= 100 (open).
    GripperValue(0..=100),
    "gripper opening in percent"
);

checked_byte!(
    /// Gripper model byte of 0x65..0x67 (pymycobot): 1 adaptive, 2 five-finger hand, 3 parallel,
    /// 4 flexible, 5 (other vendor model).
    GripperType(1..=5),
    "gripper model"
);

/// The optional tail of 0x66/0x67: nothing, a gripper type, or a type and a torque flag.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Hash)]
pub enum GripperModel {
    /// No type byte: the default (adaptive) gripper.
    #[default]
    Default,
    /// A type byte.
    Typed(GripperType),
    /// A type byte and a force-control flag (1 force control, 0 not).
    TypedTorque(GripperType, bool),
}

/// Transponder mode of the Basic (0xC2): wire 0 framed (parse host frames), 1 transparent
/// (copy bytes both ways).
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub enum TransponderMode {
    /// The Basic parses host frames, answers its own commands and forwards the rest.
    Framed = 0,
    /// The Basic copies bytes between the host and the bus unchanged.
    Transparent = 1,
}

impl TransponderMode {
    /// The mode for wire byte 0/1.
    pub const fn from_u8(v: u8) -> Option<Self> {
        match v {
            0 => Some(Self::Framed),
            1 => Some(Self::Transparent),
            _ => None,
        }
    }
}

/// Value written by set servo data (0x52).
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub enum ServoValue {
    /// One byte (LEN 5 form).
    Byte(u8),
    /// A 16-bit register pair, big-endian on the host wire (LEN 7 form, trailing `01`).
    Word(u16),
}

/// Register width byte of get servo data (0x53, LEN 5 form): `00` one byte, `01` two bytes.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub enum DataWidth {
    /// One byte (mode `00`).
    Byte = 0,
    /// Two bytes (mode `01`).
    Word = 1,
}

impl DataWidth {
    /// The width for wire byte 0/1.
    pub const fn from_u8(v: u8) -> Option<Self> {
        match v {
            0 => Some(Self::Byte),
            1 => Some(Self::Word),
            _ => None,
        }
    }
}

/// An RGB colour for the Atom LEDs, one byte per channel.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Hash)]
pub struct Rgb {
    /// Red, 0..=255.
    pub r: u8,
    /// Green, 0..=255.
    pub g: u8,
    /// Blue, 0..=255.
    pub b: u8,
}

/// How a client speaks the host protocol: pymycobot's dialect or the vendor manual's
/// ([`crate::dialect`], `docs/protocol.md` section 21).
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Hash)]
pub enum Dialect {
    /// pymycobot's protocol: every command answered, joints numbered from 1.
    #[default]
    Pymycobot = 1,
    /// The vendor manual's protocol: set commands unanswered, numbering from 0.
    Seed = 2,
}

impl Dialect {
    /// Both dialects, the default first.
    pub const ALL: [Self; 2] = [Self::Pymycobot, Self::Seed];

    /// The dialect for wire byte `v` (0xC5's data): 1 pymycobot, 2 seed.
    pub const fn from_u8(v: u8) -> Option<Self> {
        match v {
            1 => Some(Self::Pymycobot),
            2 => Some(Self::Seed),
            _ => None,
        }
    }

    /// Its name, as the screen, the 3D view and the command line show it.
    pub const fn name(self) -> &'static str {
        match self {
            Self::Pymycobot => "pymycobot",
            Self::Seed => "seed",
        }
    }
}
