//! Host commands: what each frame means (`protocol.md` section 5).
//!
//! * [`cmd`]: the command codes.
//! * [`Request`]: a typed, validated command, parsed from a [`Frame`](crate::Frame) with
//!   [`Request::parse`] and written back with [`Request::to_frame`]. Layouts of one command
//!   are told apart by LEN. Every command is one entry of the table in `request.rs`: its
//!   code, layouts, parse, emit and reply kind side by side. [`RequestKind`] names a
//!   request's command without its fields ([`RequestKind::ALL`] lists them all).
//! * [`Reply`]: a typed answer, written with [`Reply::to_frame`] and read back (by a client or
//!   a test) with [`Reply::parse`] given the [`ReplyKind`] its request expects.
//! * [`CommandError`], [`ErrorCode`], [`ServoErrorCode`]: what went wrong, on the wire.
//! * [`is_basic_local`]: which commands the Basic answers itself instead of forwarding.
//!
//! A firmware's receive path, in short:
//!
//! ```
//! use protocol_core::command::{JointId, Reply, Request};
//! use protocol_core::units::Centideg;
//! use protocol_core::FrameDecoder;
//!
//! // pymycobot's send_angle(2, -0.02, 50): the angle -2 is FF FE inside the data.
//! let wire = [0xFE, 0xFE, 0x06, 0x21, 0x02, 0xFF, 0xFE, 0x32, 0xFA];
//! let mut replies = Vec::new();
//! FrameDecoder::new().feed(&wire, |frame| {
//!     let reply = match Request::parse(&frame) {
//!         Ok(Request::SendAngle { joint, angle, .. }) => {
//!             assert_eq!((joint, angle), (JointId::new(2).unwrap(), Centideg(-2)));
//!             Reply::Ack
//!         }
//!         Ok(_) | Err(_) => Reply::Byte(0),
//!     };
//!     replies.push(reply.to_frame(frame.cmd()).to_bytes());
//! });
//! assert_eq!(replies[0].as_slice(), &[0xFE, 0xFE, 0x03, 0x21, 0x01, 0xFA]);
//! ```

/// The command codes (CMD byte). Names follow `protocol.md` section 5; where pymycobot's
/// `ProtocolCode` uses another name it is given in the doc.
pub mod cmd;
mod error;
mod reply;
mod request;
mod types;
mod wire;

pub use error::{CommandError, ErrorCode, ServoErrorCode};
pub use reply::{DragPoint, Reply, ReplyError, ReplyKind};
pub use request::{MAX_DRAG_SPEED, Request, RequestKind};
pub use types::{
    AtomPin, Axis, AxisValue, BasicInputPin, BasicOutputPin, CollisionThreshold, DataWidth,
    Dialect, Direction, EndType, GripperModel, GripperSpeed, GripperState, GripperType,
    GripperValue, JointId, MoveMode, PinMode, Pose, PositionTarget, ReferenceFrame, Rgb, RpyAxis,
    ServoId, ServoSelect, ServoValue, TransponderMode,
};

/// True for the commands the Basic answers itself and never forwards to the Atom: its own IO
/// (0xA0, 0xA1), the ToF sensor, its version and transponder mode (0xC0..=0xC3), Wi-Fi
/// settings (0xB0..=0xB2) and the dialect (0xC5).
pub const fn is_basic_local(code: u8) -> bool {
    matches!(code, 0xA0 | 0xA1 | 0xB0..=0xB2 | 0xC0..=0xC3 | 0xC5)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn basic_answers_its_own_io_tof_version_mode_and_wifi() {
        let local: std::vec::Vec<u8> = cmd::ALL
            .into_iter()
            .filter(|&c| is_basic_local(c))
            .collect();
        assert_eq!(
            local,
            [0xA0, 0xA1, 0xB0, 0xB1, 0xB2, 0xC0, 0xC1, 0xC2, 0xC3, 0xC5]
        );
    }

    #[test]
    fn every_known_code_is_known_and_others_are_not() {
        assert!(
            cmd::ALL.windows(2).all(|w| w[0] < w[1]),
            "ALL must be ascending"
        );
        let known = (0..=255u8).filter(|&c| cmd::is_known(c)).count();
        assert_eq!(known, cmd::ALL.len());
        assert!(!cmd::is_known(0x00) && !cmd::is_known(0xFE));
    }
}
