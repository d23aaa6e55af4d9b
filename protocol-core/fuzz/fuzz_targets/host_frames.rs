//! Host frame decoder + command parser on arbitrary bytes.
//!
//! The first input byte chooses the chunk size and the quiet-line pattern; the rest is the
//! wire. Checks: nothing panics, the fast `feed` path and byte-by-byte `push` agree, every
//! frame re-encodes to bytes of the stream, and every parsed request re-encodes to its frame.
#![no_main]

use libfuzzer_sys::fuzz_target;
use protocol_core::command::{Reply, ReplyKind, Request};
use protocol_core::{Frame, FrameDecoder};

fuzz_target!(|data: &[u8]| {
    let Some((&control, wire)) = data.split_first() else {
        return;
    };
    let chunk = usize::from(control & 0x1F) + 1;
    let mut fast = FrameDecoder::new();
    let mut slow = FrameDecoder::new();
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
        assert!(wire.windows(bytes.len()).any(|w| w == bytes.as_slice()));
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
