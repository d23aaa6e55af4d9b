//! The seed dialect on arbitrary bytes: the decoder with the seed manual's frame lengths, then
//! the translation into pymycobot's dialect and back.
//!
//! The first input byte chooses the chunk size and the quiet-line pattern; the rest is the
//! wire. Checks: nothing panics, the fast `feed` path and byte-by-byte `push` agree, every
//! frame's data is bytes of the stream, and every frame translates, parses and answers
//! (against any reply) without panicking.
#![no_main]

use libfuzzer_sys::fuzz_target;
use protocol_core::command::Request;
use protocol_core::dialect::Dialect;
use protocol_core::{Frame, FrameDecoder};

fuzz_target!(|data: &[u8]| {
    let Some((&control, wire)) = data.split_first() else {
        return;
    };
    let chunk = usize::from(control & 0x1F) + 1;
    let mut fast = FrameDecoder::new();
    let mut slow = FrameDecoder::new();
    fast.set_lengths(Dialect::Seed.frame_lengths());
    slow.set_lengths(Dialect::Seed.frame_lengths());
    let mut fast_out: Vec<Frame> = Vec::new();
    let mut slow_out: Vec<Frame> = Vec::new();
    for (i, part) in wire.chunks(chunk).enumerate() {
        if control & 0x80 != 0 && i % 3 == 2 {
            fast_out.extend(fast.on_quiet_line());
            slow_out.extend(slow.on_quiet_line());
        }
        fast.feed(part, |f| fast_out.push(f));
        for &b in part {
            slow_out.extend(slow.push(b));
            while let Some(f) = slow.next_frame() {
                slow_out.push(f);
            }
        }
    }
    assert_eq!(fast_out, slow_out);
    for frame in &fast_out {
        let bytes = frame.to_bytes();
        let payload = &bytes[3..];
        assert!(wire.windows(payload.len()).any(|w| w == payload));
        let translated = Dialect::Seed.translate(frame);
        let _ = Request::parse(&translated.frame);
        let _ = translated.answer.reply(frame);
        let _ = translated.answer.reply(&translated.frame);
    }
});
