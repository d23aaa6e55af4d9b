//! Host frame decoder + command parser on arbitrary bytes.
//!
//! The first input byte chooses the chunk size, the quiet-line pattern and the frame lengths
//! (counted, or the seed dialect's with the manual's miscounted LENs); the rest is the wire.
//! Checks: nothing panics, the fast `feed` path and byte-by-byte `push` agree, every frame's
//! data is bytes of the stream (with its LEN, when counted), every parsed request re-encodes
//! to its frame, and every frame translates from the seed dialect and answers without
//! panicking.
#![no_main]

use libfuzzer_sys::fuzz_target;
use protocol_core::command::{Reply, ReplyKind, Request};
use protocol_core::dialect::Dialect;
use protocol_core::frame::FrameLengths;
use protocol_core::{Frame, FrameDecoder};

fuzz_target!(|data: &[u8]| {
    let Some((&control, wire)) = data.split_first() else {
        return;
    };
    let chunk = usize::from(control & 0x1F) + 1;
    let lengths = if control & 0x40 != 0 {
        Dialect::Seed.frame_lengths()
    } else {
        FrameLengths::Counted
    };
    let mut fast = FrameDecoder::new();
    let mut slow = FrameDecoder::new();
    fast.set_lengths(lengths);
    slow.set_lengths(lengths);
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
        // A seed frame's LEN may be the manual's miscount: its payload is in the stream.
        let seen = if lengths == FrameLengths::Counted { &bytes[..] } else { &bytes[3..] };
        assert!(wire.windows(seen.len()).any(|w| w == seen));
        let translated = Dialect::Seed.translate(frame);
        let _ = Request::parse(&translated.frame);
        let _ = translated.answer.reply(frame);
        let _ = translated.answer.unanswered();
        if let Ok(request) = Request::parse(frame) {
            assert_eq!(&request.to_frame(), frame);
            let _ = request.reply_kind();
        }
        for &kind in ReplyKind::ALL {
            if let Ok(reply) = Reply::parse(kind, frame) {
                assert_eq!(&reply.to_frame(frame.cmd()), frame);
            }
        }
    }
});
