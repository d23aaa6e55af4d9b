//! [`Fields`]: reads a request frame's data field by field, turning each raw byte into its
//! validated type or into the [`CommandError`] that names the bad value.

use heapless::Vec;

use crate::frame::MAX_DATA;
use crate::units::{Centideg, SpeedPercent, Steps};

use super::super::error::CommandError;
use super::super::types::{
    AtomPin, Axis, AxisValue, BasicInputPin, BasicOutputPin, CollisionThreshold, Direction,
    GripperModel, GripperSpeed, GripperState, GripperType, GripperValue, JointId, Pose, RpyAxis,
    ServoId, ServoSelect,
};
use super::super::wire::Reader;

/// Highest encoder value a client may send (pymycobot allows 0..=4096).
pub const MAX_ENCODER: i16 = 4096;
/// Highest per-servo drag speed of 0x3E, steps per second (pymycobot: 0..=6000).
pub const MAX_DRAG_SPEED: i16 = 6000;
/// Servo registers below this address (firmware version, model) are refused by set servo data
/// (0x52), as pymycobot does. Reading them is allowed (pymycobot's `is_torque_gripper` reads
/// register 1 of servo 7).
pub const MIN_SERVO_ADDRESS: u8 = 5;

/// Reads a frame's fields; a read past the end is `short` (the frame's
/// [`CommandError::BadLength`]), a value the protocol does not allow its own error.
pub(super) struct Fields<'a> {
    r: Reader<'a>,
    short: CommandError,
}

impl<'a> Fields<'a> {
    /// Fields of `data`; `short` is the error of a read past its end.
    pub(super) fn new(data: &'a [u8], short: CommandError) -> Self {
        Self {
            r: Reader::new(data),
            short,
        }
    }

    /// Data bytes not read yet.
    pub(super) fn remaining(&self) -> usize {
        self.r.remaining()
    }

    /// The frame's error for a LEN no layout of its command has.
    pub(super) fn bad_len(&self) -> CommandError {
        self.short
    }

    /// `read` if any byte is left, else `None`: the optional tail byte of a command whose
    /// layouts differ by it alone (the LEN pattern of the layout has fixed how many are left).
    pub(super) fn optional<T>(
        &mut self,
        read: fn(&mut Self) -> Result<T, CommandError>,
    ) -> Result<Option<T>, CommandError> {
        if self.r.remaining() == 0 {
            Ok(None)
        } else {
            read(self).map(Some)
        }
    }

    pub(super) fn u8(&mut self) -> Result<u8, CommandError> {
        self.r.u8().ok_or(self.short)
    }

    pub(super) fn i16(&mut self) -> Result<i16, CommandError> {
        self.r.i16().ok_or(self.short)
    }

    pub(super) fn i16x6(&mut self) -> Result<[i16; 6], CommandError> {
        self.r.i16x6().ok_or(self.short)
    }

    /// Every byte left, as it is.
    pub(super) fn payload(&mut self) -> Result<Vec<u8, MAX_DATA>, CommandError> {
        // A frame's data is at most MAX_DATA bytes, the capacity.
        Vec::from_slice(self.r.rest()).map_err(|_| self.short)
    }

    pub(super) fn flag(&mut self) -> Result<bool, CommandError> {
        match self.u8()? {
            0 => Ok(false),
            1 => Ok(true),
            v => Err(CommandError::BadFlag(v)),
        }
    }

    /// One byte made a `T` by `new`; a byte `new` refuses is the error `bad` names it by.
    fn checked<T>(
        &mut self,
        new: fn(u8) -> Option<T>,
        bad: fn(u8) -> CommandError,
    ) -> Result<T, CommandError> {
        let v = self.u8()?;
        new(v).ok_or(bad(v))
    }

    /// A byte-coded enum (`from` is its `from_u8`); any other byte is a bad flag.
    pub(super) fn enum_byte<T>(&mut self, from: fn(u8) -> Option<T>) -> Result<T, CommandError> {
        self.checked(from, CommandError::BadFlag)
    }

    pub(super) fn joint(&mut self) -> Result<JointId, CommandError> {
        self.checked(JointId::new, CommandError::BadJoint)
    }

    pub(super) fn collision_threshold(&mut self) -> Result<CollisionThreshold, CommandError> {
        self.checked(CollisionThreshold::new, CommandError::BadThreshold)
    }

    pub(super) fn servo(&mut self) -> Result<ServoId, CommandError> {
        self.checked(ServoId::new, CommandError::BadServo)
    }

    /// One servo, or all of them when the byte is `all`.
    pub(super) fn servo_or_all(&mut self, all: u8) -> Result<ServoSelect, CommandError> {
        let v = self.u8()?;
        if v == all {
            return Ok(ServoSelect::All);
        }
        ServoId::new(v)
            .map(ServoSelect::One)
            .ok_or(CommandError::BadServo(v))
    }

    /// A servo register a client may write: [`MIN_SERVO_ADDRESS`] or above.
    pub(super) fn address(&mut self) -> Result<u8, CommandError> {
        let v = self.u8()?;
        if v < MIN_SERVO_ADDRESS {
            return Err(CommandError::BadAddress(v));
        }
        Ok(v)
    }

    pub(super) fn speed(&mut self) -> Result<SpeedPercent, CommandError> {
        self.checked(SpeedPercent::new, CommandError::BadSpeed)
    }

    pub(super) fn gripper_speed(&mut self) -> Result<GripperSpeed, CommandError> {
        self.checked(GripperSpeed::new, CommandError::BadSpeed)
    }

    pub(super) fn gripper_type(&mut self) -> Result<GripperType, CommandError> {
        self.checked(GripperType::new, CommandError::BadGripperValue)
    }

    pub(super) fn gripper_state(&mut self) -> Result<GripperState, CommandError> {
        self.checked(GripperState::from_u8, CommandError::BadGripperValue)
    }

    pub(super) fn gripper_value(&mut self) -> Result<GripperValue, CommandError> {
        self.checked(GripperValue::new, CommandError::BadGripperValue)
    }

    /// The optional type / torque tail of 0x66/0x67, told apart by the number of bytes left.
    pub(super) fn gripper_model(&mut self) -> Result<GripperModel, CommandError> {
        Ok(match self.r.remaining() {
            0 => GripperModel::Default,
            1 => GripperModel::Typed(self.gripper_type()?),
            _ => {
                let kind = self.gripper_type()?;
                GripperModel::TypedTorque(kind, self.flag()?)
            }
        })
    }

    pub(super) fn direction(&mut self) -> Result<Direction, CommandError> {
        self.checked(Direction::from_u8, CommandError::BadDirection)
    }

    /// An axis numbered 1..=6 (x..rz), as pymycobot numbers them.
    pub(super) fn axis(&mut self) -> Result<Axis, CommandError> {
        self.checked(Axis::from_u8, CommandError::BadAxis)
    }

    /// An axis (1..=6) and an int16 in its unit.
    pub(super) fn axis_value(&mut self) -> Result<AxisValue, CommandError> {
        let axis = self.axis()?;
        Ok(AxisValue::new(axis, self.i16()?))
    }

    /// The axis and value of send coord (0x24): both axis numberings
    /// ([`Axis::from_send_coord_byte`]).
    pub(super) fn send_coord_axis_value(&mut self) -> Result<AxisValue, CommandError> {
        let v = self.u8()?;
        let axis = Axis::from_send_coord_byte(v).ok_or(CommandError::BadAxis(v))?;
        Ok(AxisValue::new(axis, self.i16()?))
    }

    pub(super) fn rpy_axis(&mut self) -> Result<RpyAxis, CommandError> {
        self.checked(RpyAxis::from_u8, CommandError::BadAxis)
    }

    /// An encoder target, 0..=[`MAX_ENCODER`].
    pub(super) fn encoder(&mut self) -> Result<Steps, CommandError> {
        let v = self.i16()?;
        if !(0..=MAX_ENCODER).contains(&v) {
            return Err(CommandError::BadEncoder(v));
        }
        Ok(Steps(v))
    }

    pub(super) fn encoders(&mut self) -> Result<[Steps; 6], CommandError> {
        let mut out = [Steps(0); 6];
        for e in &mut out {
            *e = self.encoder()?;
        }
        Ok(out)
    }

    /// Six servo speeds of 0x3E, 0..=[`MAX_DRAG_SPEED`] steps per second each.
    pub(super) fn drag_speeds(&mut self) -> Result<[i16; 6], CommandError> {
        let speeds = self.i16x6()?;
        if let Some(&bad) = speeds.iter().find(|s| !(0..=MAX_DRAG_SPEED).contains(*s)) {
            return Err(CommandError::BadDragSpeed(bad));
        }
        Ok(speeds)
    }

    pub(super) fn centideg6(&mut self) -> Result<[Centideg; 6], CommandError> {
        self.r.centideg6().ok_or(self.short)
    }

    pub(super) fn pose(&mut self) -> Result<Pose, CommandError> {
        self.r.pose().ok_or(self.short)
    }

    pub(super) fn atom_pin(&mut self) -> Result<AtomPin, CommandError> {
        self.checked(AtomPin::new, CommandError::BadPin)
    }

    pub(super) fn atom_output_pin(&mut self) -> Result<AtomPin, CommandError> {
        self.checked(AtomPin::output, CommandError::BadPin)
    }

    pub(super) fn basic_output_pin(&mut self) -> Result<BasicOutputPin, CommandError> {
        self.checked(BasicOutputPin::new, CommandError::BadPin)
    }

    pub(super) fn basic_input_pin(&mut self) -> Result<BasicInputPin, CommandError> {
        self.checked(BasicInputPin::new, CommandError::BadPin)
    }

    /// An int16 gripper setting inside `range`.
    pub(super) fn limited_i16(
        &mut self,
        range: core::ops::RangeInclusive<i16>,
    ) -> Result<i16, CommandError> {
        let v = self.i16()?;
        if !range.contains(&v) {
            return Err(CommandError::BadGripperSetting(v));
        }
        Ok(v)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    const SHORT: CommandError = CommandError::BadLength {
        cmd: 0x66,
        data_len: 9,
    };

    #[test]
    fn a_read_past_the_end_is_the_frames_bad_length() {
        let mut f = Fields::new(&[1], SHORT);
        assert_eq!(f.i16(), Err(SHORT));
        assert_eq!(Fields::new(&[0; 11], SHORT).pose(), Err(SHORT));
        assert_eq!(Fields::new(&[], SHORT).bad_len(), SHORT);
    }

    #[test]
    fn an_optional_tail_is_read_only_when_bytes_are_left() {
        let mut f = Fields::new(&[1], SHORT);
        assert_eq!(f.optional(Fields::flag), Ok(Some(true)));
        assert_eq!(f.optional(Fields::flag), Ok(None));
        assert_eq!(
            Fields::new(&[2], SHORT).optional(Fields::flag),
            Err(CommandError::BadFlag(2))
        );
    }

    #[test]
    fn the_gripper_tail_is_told_apart_by_the_bytes_left() {
        let t = |v| GripperType::new(v).unwrap();
        let model = |data: &[u8]| Fields::new(data, SHORT).gripper_model();
        assert_eq!(model(&[]), Ok(GripperModel::Default));
        assert_eq!(model(&[2]), Ok(GripperModel::Typed(t(2))));
        assert_eq!(model(&[2, 1]), Ok(GripperModel::TypedTorque(t(2), true)));
        assert_eq!(model(&[9]), Err(CommandError::BadGripperValue(9)));
    }

    #[test]
    fn values_outside_their_range_name_themselves() {
        let mut f = Fields::new(&[0x10, 0x01, 0x00, 0x04], SHORT);
        assert_eq!(f.encoder(), Err(CommandError::BadEncoder(4097)));
        assert_eq!(f.address(), Err(CommandError::BadAddress(0)));
        let mut speeds = [0u8; 12];
        speeds[10..].copy_from_slice(&6001i16.to_be_bytes());
        assert_eq!(
            Fields::new(&speeds, SHORT).drag_speeds(),
            Err(CommandError::BadDragSpeed(6001))
        );
        assert_eq!(
            Fields::new(&[254], SHORT).servo_or_all(0),
            Err(CommandError::BadServo(254))
        );
        assert_eq!(
            Fields::new(&[254], SHORT).servo_or_all(254),
            Ok(ServoSelect::All)
        );
    }

    #[test]
    fn the_payload_is_every_byte_left() {
        let mut f = Fields::new(b"'ab'(cd)", SHORT);
        assert_eq!(f.u8(), Ok(b'\''));
        assert_eq!(f.payload().as_deref(), Ok(&b"ab'(cd)"[..]));
        assert_eq!(f.remaining(), 0);
    }
}
