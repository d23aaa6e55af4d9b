//! [`Reply`]: the typed answers the firmware sends, and their parsing for clients.

use heapless::Vec;

use crate::frame::{Frame, MAX_REPLY_DATA};
use crate::units::{Centideg, Decideg, Steps};

use super::types::{JointId, Pose, ServoId};
use super::wire::{Reader, Writer};

/// One reply's data, typed. Written with [`Reply::to_frame`] under the request's CMD byte;
/// never more than 28 data bytes (pymycobot rejects LEN > 30).
#[derive(Clone, Debug, PartialEq, Eq, Hash)]
pub enum Reply {
    /// The status reply `01`: done / accepted. Every command with nothing to return.
    Ack,
    /// One byte: a flag, mode, version x 10, percentage, [`ErrorCode`](super::ErrorCode)...
    Byte(u8),
    /// One int16: an encoder, ToF distance in mm, a count, a 2-byte servo register...
    Int16(i16),
    /// Six joint angles.
    Angles([Centideg; 6]),
    /// A pose.
    Coords(Pose),
    /// Six encoders.
    Encoders([Steps; 6]),
    /// Six int16 values: servo speeds (steps/s) or currents (mA).
    Int16x6([i16; 6]),
    /// Six bytes: servo voltages (volts x 10), status bits or temperatures (deg C).
    Bytes6([u8; 6]),
    /// Read next error: one [`ServoErrorCode`](super::ServoErrorCode) byte per servo 1..=7.
    ServoErrors([u8; 7]),
    /// Angles then coords (0xD5).
    AnglesAndCoords {
        /// Joint angles.
        angles: [Centideg; 6],
        /// Pose.
        coords: Pose,
    },
    /// A pin and its level (0x62, 0xA1). The pin byte is mandatory: pymycobot skips it.
    PinLevel {
        /// GPIO number.
        pin: u8,
        /// High.
        high: bool,
    },
    /// A joint and one of its limits (0x4A, 0x4B).
    JointLimit {
        /// Joint.
        joint: JointId,
        /// Limit.
        limit: Decideg,
    },
    /// A servo and whether its torque is on (0x50).
    ServoEnabled {
        /// Servo.
        servo: ServoId,
        /// Torque on.
        enabled: bool,
    },
    /// One recorded drag-teaching point (0xF3), or `None` once every point was read: 24 bytes,
    /// joint by joint the encoder then the speed (int16 each), all zero for `None` (pymycobot
    /// splits even and odd values into `[[encoders], [speeds]]`, and answers -1 for all zero).
    DragPoint(Option<DragPoint>),
    /// Anything else, raw.
    Raw(Vec<u8, MAX_REPLY_DATA>),
}

/// One point of a drag-teaching recording: where each joint was and how fast it turned.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Hash)]
pub struct DragPoint {
    /// Encoder position of joints 1..6, steps (0..=4095).
    pub encoders: [Steps; 6],
    /// Speed of joints 1..6, steps per second (what set encoders drag, 0x3E, takes back).
    pub speeds_steps_per_s: [i16; 6],
}

/// Declares [`ReplyKind`] and [`ReplyKind::ALL`] from one list, so the list cannot miss a kind.
macro_rules! reply_kinds {
    ($($kind:ident),* $(,)?) => {
        /// The shape of reply a request expects
        /// ([`Request::reply_kind`](super::Request::reply_kind)).
        #[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
        pub enum ReplyKind {
            $(
                #[doc = concat!("[`Reply::", stringify!($kind), "`].")]
                $kind,
            )*
        }

        impl ReplyKind {
            /// Every kind, in declaration order.
            pub const ALL: &'static [Self] = &[$(Self::$kind),*];
        }
    };
}

reply_kinds! {
    Ack,
    Byte,
    Int16,
    Angles,
    Coords,
    Encoders,
    Int16x6,
    Bytes6,
    ServoErrors,
    AnglesAndCoords,
    PinLevel,
    JointLimit,
    ServoEnabled,
    DragPoint,
    Raw,
}

/// Why a reply frame does not have the expected shape.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub enum ReplyError {
    /// The data length does not match the expected kind.
    BadLength {
        /// Expected kind.
        kind: ReplyKind,
        /// Data bytes received.
        data_len: u8,
    },
    /// A field holds an impossible value (status other than 1, joint 0, level 7...).
    BadValue(u8),
}

impl Reply {
    /// The kind of this reply.
    pub fn kind(&self) -> ReplyKind {
        match self {
            Self::Ack => ReplyKind::Ack,
            Self::Byte(_) => ReplyKind::Byte,
            Self::Int16(_) => ReplyKind::Int16,
            Self::Angles(_) => ReplyKind::Angles,
            Self::Coords(_) => ReplyKind::Coords,
            Self::Encoders(_) => ReplyKind::Encoders,
            Self::Int16x6(_) => ReplyKind::Int16x6,
            Self::Bytes6(_) => ReplyKind::Bytes6,
            Self::ServoErrors(_) => ReplyKind::ServoErrors,
            Self::AnglesAndCoords { .. } => ReplyKind::AnglesAndCoords,
            Self::PinLevel { .. } => ReplyKind::PinLevel,
            Self::JointLimit { .. } => ReplyKind::JointLimit,
            Self::ServoEnabled { .. } => ReplyKind::ServoEnabled,
            Self::DragPoint(_) => ReplyKind::DragPoint,
            Self::Raw(_) => ReplyKind::Raw,
        }
    }

    /// The reply frame for the request with command code `cmd`.
    pub fn to_frame(&self, cmd: u8) -> Frame {
        let mut w = Writer::default();
        match self {
            Self::Ack => {
                w.u8(1);
            }
            Self::Byte(b) => {
                w.u8(*b);
            }
            Self::Int16(v) => {
                w.i16(*v);
            }
            Self::Angles(a) => {
                w.centideg6(a);
            }
            Self::Coords(p) => {
                w.pose(p);
            }
            Self::Encoders(e) => {
                w.steps6(e);
            }
            Self::Int16x6(v) => {
                w.i16s(v);
            }
            Self::Bytes6(b) => {
                w.bytes(b);
            }
            Self::ServoErrors(b) => {
                w.bytes(b);
            }
            Self::AnglesAndCoords { angles, coords } => {
                w.centideg6(angles).pose(coords);
            }
            Self::PinLevel { pin, high } => {
                w.u8(*pin).u8(u8::from(*high));
            }
            Self::JointLimit { joint, limit } => {
                w.u8(joint.get()).i16(limit.0);
            }
            Self::ServoEnabled { servo, enabled } => {
                w.u8(servo.get()).u8(u8::from(*enabled));
            }
            Self::DragPoint(point) => {
                let point = point.unwrap_or_default();
                for (e, v) in point.encoders.iter().zip(point.speeds_steps_per_s) {
                    w.i16(e.0).i16(v);
                }
            }
            Self::Raw(data) => {
                w.bytes(data);
            }
        }
        w.frame(cmd)
    }

    /// Reads a reply frame's data as `kind` (the CMD byte is the caller's to check).
    pub fn parse(kind: ReplyKind, frame: &Frame) -> Result<Self, ReplyError> {
        let data = frame.data();
        let bad_len = ReplyError::BadLength {
            kind,
            // Frame data is at most 62 bytes.
            data_len: data.len() as u8,
        };
        let expected = match kind {
            ReplyKind::Ack | ReplyKind::Byte => 1,
            ReplyKind::Int16 | ReplyKind::PinLevel | ReplyKind::ServoEnabled => 2,
            ReplyKind::JointLimit => 3,
            ReplyKind::Bytes6 => 6,
            ReplyKind::ServoErrors => 7,
            ReplyKind::Angles | ReplyKind::Coords | ReplyKind::Encoders | ReplyKind::Int16x6 => 12,
            ReplyKind::AnglesAndCoords | ReplyKind::DragPoint => 24,
            ReplyKind::Raw => data.len(),
        };
        if data.len() != expected || data.len() > MAX_REPLY_DATA {
            return Err(bad_len);
        }
        let mut r = Reader::new(data);
        let flag = |v: u8| match v {
            0 => Ok(false),
            1 => Ok(true),
            _ => Err(ReplyError::BadValue(v)),
        };
        let reply = match kind {
            ReplyKind::Ack => match r.u8() {
                Some(1) => Self::Ack,
                other => return Err(ReplyError::BadValue(other.unwrap_or(0))),
            },
            ReplyKind::Byte => Self::Byte(r.u8().ok_or(bad_len)?),
            ReplyKind::Int16 => Self::Int16(r.i16().ok_or(bad_len)?),
            ReplyKind::Angles => Self::Angles(r.centideg6().ok_or(bad_len)?),
            ReplyKind::Coords => Self::Coords(r.pose().ok_or(bad_len)?),
            ReplyKind::Encoders => Self::Encoders(r.steps6().ok_or(bad_len)?),
            ReplyKind::Int16x6 => Self::Int16x6(r.i16x6().ok_or(bad_len)?),
            ReplyKind::Bytes6 => Self::Bytes6(r.u8x().ok_or(bad_len)?),
            ReplyKind::ServoErrors => Self::ServoErrors(r.u8x().ok_or(bad_len)?),
            ReplyKind::AnglesAndCoords => Self::AnglesAndCoords {
                angles: r.centideg6().ok_or(bad_len)?,
                coords: r.pose().ok_or(bad_len)?,
            },
            ReplyKind::PinLevel => Self::PinLevel {
                pin: r.u8().ok_or(bad_len)?,
                high: flag(r.u8().ok_or(bad_len)?)?,
            },
            ReplyKind::JointLimit => {
                let j = r.u8().ok_or(bad_len)?;
                Self::JointLimit {
                    joint: JointId::new(j).ok_or(ReplyError::BadValue(j))?,
                    limit: Decideg(r.i16().ok_or(bad_len)?),
                }
            }
            ReplyKind::ServoEnabled => {
                let s = r.u8().ok_or(bad_len)?;
                Self::ServoEnabled {
                    servo: ServoId::new(s).ok_or(ReplyError::BadValue(s))?,
                    enabled: flag(r.u8().ok_or(bad_len)?)?,
                }
            }
            ReplyKind::DragPoint => {
                let mut point = DragPoint::default();
                for (e, v) in point
                    .encoders
                    .iter_mut()
                    .zip(point.speeds_steps_per_s.iter_mut())
                {
                    *e = Steps(r.i16().ok_or(bad_len)?);
                    *v = r.i16().ok_or(bad_len)?;
                }
                Self::DragPoint((point != DragPoint::default()).then_some(point))
            }
            ReplyKind::Raw => Self::Raw(Vec::from_slice(data).map_err(|_| bad_len)?),
        };
        Ok(reply)
    }
}
