//! Servo packet decoder + instruction parser on arbitrary bytes.
//!
//! The first input byte chooses the chunk size and the quiet-line pattern; the rest is the
//! wire. Checks: nothing panics, the fast `feed` path and byte-by-byte `push` agree, every
//! packet re-encodes to bytes of the stream, and every parsed instruction re-encodes to it.
#![no_main]

use libfuzzer_sys::fuzz_target;
use protocol_core::servo::{Instruction, Packet, PacketDecoder};

fuzz_target!(|data: &[u8]| {
    let Some((&control, wire)) = data.split_first() else {
        return;
    };
    let chunk = usize::from(control & 0x1F) + 1;
    let mut fast = PacketDecoder::new();
    let mut slow = PacketDecoder::new();
    let mut fast_out: Vec<Packet> = Vec::new();
    let mut slow_out: Vec<Packet> = Vec::new();
    for (i, part) in wire.chunks(chunk).enumerate() {
        if control & 0x80 != 0 && i % 3 == 2 {
            fast_out.extend(fast.on_quiet_line());
            slow_out.extend(slow.on_quiet_line());
        }
        fast.feed(part, |p| fast_out.push(p));
        for &b in part {
            slow_out.extend(slow.push(b));
            while let Some(p) = slow.next_packet() {
                slow_out.push(p);
            }
        }
    }
    assert_eq!(fast_out, slow_out);
    for packet in &fast_out {
        let bytes = packet.to_bytes();
        assert!(wire.windows(bytes.len()).any(|w| w == bytes.as_slice()));
        if let Ok(instruction) = Instruction::parse(packet) {
            if let Some(again) = instruction.to_packet(packet.id()) {
                assert_eq!(again.id(), packet.id());
            }
        }
    }
});
