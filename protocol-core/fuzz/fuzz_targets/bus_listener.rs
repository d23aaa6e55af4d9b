//! The timed bus listener on arbitrary operations.
//!
//! The first input byte chooses the config (decoders, echo mode, gaps); the rest is a script
//! of two-byte operations: the first byte picks the operation and how far time moves (the
//! second byte is the received byte, or the length of a transmission taken from what was heard
//! so far, so echoes occur). Checks: nothing panics, every received byte comes out once or is
//! dropped as own echo, and every frame or packet given out was in the bytes given out.
#![no_main]

use libfuzzer_sys::fuzz_target;
use protocol_core::listener::{EchoMode, Heard, Listener, ListenerConfig};

/// Sorts what the listener gave out: raw bytes, and the wire bytes of frames and packets.
fn take(heard: Heard, bytes: &mut Vec<u8>, found: &mut Vec<Vec<u8>>) {
    match heard {
        Heard::Byte(b) => bytes.push(b),
        Heard::Frame(f) => found.push(f.to_bytes().to_vec()),
        Heard::Packet(p) => found.push(p.to_bytes().to_vec()),
        Heard::Echo(_) => {}
    }
}

fuzz_target!(|data: &[u8]| {
    let Some((&control, script)) = data.split_first() else {
        return;
    };
    let echo = match control & 0x03 {
        0 => EchoMode::Auto,
        1 => EchoMode::Present,
        _ => EchoMode::Absent,
    };
    let config = ListenerConfig::new()
        .with_frames(control & 0x04 == 0)
        .with_packets(control & 0x08 == 0)
        .with_bytes(true)
        .with_frame_gap_us(u64::from(control >> 4) * 50)
        .with_packet_gap_us(u64::from(control >> 6) * 20)
        .with_echo(echo);
    let mut rx = Listener::new(config);
    let mut pushed: Vec<u8> = Vec::new();
    let mut bytes: Vec<u8> = Vec::new();
    let mut found: Vec<Vec<u8>> = Vec::new();
    let mut now: u64 = 0;
    for op in script.chunks_exact(2) {
        let (kind, arg) = (op[0], op[1]);
        now = match kind >> 6 {
            3 => now.wrapping_sub(u64::from(kind & 0x0F)),
            _ => now.wrapping_add(u64::from(kind & 0x3F) * 7),
        };
        match kind & 0x30 {
            0x00 | 0x10 => {
                pushed.push(arg);
                rx.push(now, arg, &mut |h| take(h, &mut bytes, &mut found));
            }
            0x20 => {
                let from = pushed.len().saturating_sub(usize::from(arg));
                rx.on_transmit(now, &pushed[from..]);
            }
            _ if arg & 1 == 0 => rx.on_time(now, &mut |h| take(h, &mut bytes, &mut found)),
            _ => rx.drop_partials(),
        }
    }
    rx.on_time(u64::MAX, &mut |h| take(h, &mut bytes, &mut found));
    assert_eq!(bytes.len() + rx.echo_bytes() as usize, pushed.len());
    for wire in &found {
        assert!(bytes.windows(wire.len()).any(|w| w == wire.as_slice()));
    }
});
