//! Strategies the property tests share: any host frame, any servo packet.

use proptest::prelude::*;
use protocol_core::Frame;
use protocol_core::servo::Packet;

/// Any host frame, up to the longest data.
pub fn any_frame() -> impl Strategy<Value = Frame> {
    (any::<u8>(), prop::collection::vec(any::<u8>(), 0..=62))
        .prop_map(|(cmd, data)| Frame::new(cmd, &data).unwrap())
}

/// Any servo packet (instruction or status), up to 20 parameters.
pub fn any_packet() -> impl Strategy<Value = Packet> {
    (
        0u8..=0xFE,
        any::<u8>(),
        prop::collection::vec(any::<u8>(), 0..=20),
    )
        .prop_map(|(id, code, params)| Packet::new(id, code, &params).unwrap())
}
