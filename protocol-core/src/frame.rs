//! Host frames: `FE FE LEN CMD DATA... FA`, `LEN = len(DATA) + 2`.
//!
//! [`Frame`] is one validated frame (its command byte and data); [`FrameDecoder`] finds frames
//! in a byte stream. The decoder follows `protocol.md` section 2: it parses by length (so `FE`
//! and `FA` inside the data are ordinary bytes), drops a candidate whose footer is not `FA` or
//! whose LEN is impossible and rescans from the byte after its first `FE`, skips every byte
//! outside a frame, and drops a partial frame when the line goes quiet mid-frame
//! ([`FrameDecoder::on_quiet_line`]).

use heapless::Vec;

/// First two bytes of every host frame.
pub const HEADER: u8 = 0xFE;
/// Last byte of every host frame.
pub const FOOTER: u8 = 0xFA;
/// Largest LEN the decoder accepts. pymycobot requests go up to 0x1A and replies must not exceed
/// 30 (`protocol.md` section 2); 64 leaves room for other clients while keeping a false start
/// (an `FE FE` in noise followed by a large byte) from holding real frames back for long.
pub const MAX_LEN: u8 = 64;
/// Smallest valid LEN: CMD and FA with no data.
pub const MIN_LEN: u8 = 2;
/// Most data bytes a frame can carry (`MAX_LEN - 2`).
pub const MAX_DATA: usize = MAX_LEN as usize - 2;
/// Most bytes one encoded frame occupies on the wire (`FE FE LEN` + LEN).
pub const MAX_FRAME_BYTES: usize = 3 + MAX_LEN as usize;
/// Largest reply data pymycobot accepts (it rejects LEN > 30).
pub const MAX_REPLY_DATA: usize = 28;

/// One host frame: the command byte and up to [`MAX_DATA`] data bytes.
#[derive(Clone, PartialEq, Eq, Hash, Default)]
pub struct Frame {
    cmd: u8,
    data: Vec<u8, MAX_DATA>,
}

impl Frame {
    /// A frame for `cmd` carrying `data`; `None` if `data` is longer than [`MAX_DATA`].
    pub fn new(cmd: u8, data: &[u8]) -> Option<Self> {
        Some(Self {
            cmd,
            data: Vec::from_slice(data).ok()?,
        })
    }

    /// The command byte (position 3 on the wire).
    pub fn cmd(&self) -> u8 {
        self.cmd
    }

    /// The data bytes between CMD and the footer.
    pub fn data(&self) -> &[u8] {
        &self.data
    }

    /// The LEN byte this frame has on the wire: `len(DATA) + 2`.
    pub fn len_byte(&self) -> u8 {
        // data.len() <= MAX_DATA = 62, so this cannot overflow.
        self.data.len() as u8 + 2
    }

    /// Number of bytes [`Frame::encode`] writes.
    pub fn encoded_len(&self) -> usize {
        self.data.len() + 5
    }

    /// Writes the frame's wire bytes into `out`; returns how many, or `None` if `out` is short.
    pub fn encode(&self, out: &mut [u8]) -> Option<usize> {
        let n = self.encoded_len();
        let out = out.get_mut(..n)?;
        let (head, rest) = out.split_at_mut(4);
        head.copy_from_slice(&[HEADER, HEADER, self.len_byte(), self.cmd]);
        let (data, footer) = rest.split_at_mut(self.data.len());
        data.copy_from_slice(&self.data);
        footer.copy_from_slice(&[FOOTER]);
        Some(n)
    }

    /// The frame's wire bytes.
    pub fn to_bytes(&self) -> Vec<u8, MAX_FRAME_BYTES> {
        let mut buf = [0u8; MAX_FRAME_BYTES];
        let n = self.encode(&mut buf).unwrap_or(0);
        // n <= MAX_FRAME_BYTES, the capacity, so from_slice cannot fail.
        Vec::from_slice(buf.get(..n).unwrap_or(&[])).unwrap_or_default()
    }
}

impl core::fmt::Debug for Frame {
    fn fmt(&self, f: &mut core::fmt::Formatter<'_>) -> core::fmt::Result {
        write!(
            f,
            "Frame {{ cmd: {:#04x}, data: {:02x?} }}",
            self.cmd,
            self.data.as_slice()
        )
    }
}

/// Streaming decoder of host frames.
///
/// Feed it every received byte with [`push`](Self::push); it returns each complete frame once.
/// A bad candidate (wrong footer, LEN out of range) never swallows a real frame behind it: the
/// decoder rescans from the byte after the candidate's first `FE`. Because a rescan can uncover
/// more than one frame at once, drain [`next_frame`](Self::next_frame) after every `Some`.
///
/// Memory: one buffer of [`MAX_FRAME_BYTES`] bytes. Never allocates, never panics.
#[derive(Clone, Debug)]
pub struct FrameDecoder {
    buf: Vec<u8, MAX_FRAME_BYTES>,
    /// How many bytes at the front of `buf` arrived before the last quiet gap: a candidate that
    /// starts there can no longer complete.
    stale: usize,
    /// Bytes skipped because they were outside any frame or in a rejected candidate.
    skipped: u32,
}

impl Default for FrameDecoder {
    fn default() -> Self {
        Self::new()
    }
}

enum Scan {
    /// The buffer holds the start of a candidate that needs more bytes.
    NeedMore,
    /// A complete frame of `n` bytes starts the buffer.
    Complete(usize),
    /// The first byte cannot start a frame; drop it.
    Reject,
}

impl FrameDecoder {
    /// An empty decoder.
    pub const fn new() -> Self {
        Self {
            buf: Vec::new(),
            stale: 0,
            skipped: 0,
        }
    }

    /// Appends one received byte; returns the frame it completes, if any.
    pub fn push(&mut self, byte: u8) -> Option<Frame> {
        if self.buf.is_full() {
            // Only reachable when a caller ignored frames waiting in `next_frame`: make room by
            // dropping the oldest byte rather than failing.
            self.drop_front(1);
        }
        // Cannot fail: there is room now.
        let _ = self.buf.push(byte);
        self.next_frame()
    }

    /// Feeds every byte of `bytes`, calling `on_frame` with each frame found, in order.
    ///
    /// Same result as [`push`](Self::push)ing byte by byte and draining, but faster: while idle
    /// it skips straight to the next `FE`, and once a candidate's LEN is known it copies the
    /// rest of the candidate in one go.
    pub fn feed(&mut self, mut bytes: &[u8], mut on_frame: impl FnMut(Frame)) {
        while !bytes.is_empty() {
            let take = if self.stale != 0 {
                1
            } else if self.buf.is_empty() {
                // Idle: no byte before the next FE can start a frame.
                let skip = bytes
                    .iter()
                    .position(|&b| b == HEADER)
                    .unwrap_or(bytes.len());
                // skip <= bytes.len(); a wrap of the statistics counter is harmless.
                self.skipped = self.skipped.wrapping_add(skip as u32);
                bytes = bytes.get(skip..).unwrap_or_default();
                if bytes.is_empty() {
                    return;
                }
                1
            } else {
                self.missing().clamp(1, bytes.len())
            };
            let (chunk, rest) = bytes.split_at(take.min(bytes.len()));
            bytes = rest;
            // `take` fits the buffer unless a caller left frames undrained: then evict.
            if self.buf.extend_from_slice(chunk).is_err() {
                for &b in chunk {
                    if self.buf.is_full() {
                        self.drop_front(1);
                    }
                    let _ = self.buf.push(b);
                }
            }
            while let Some(frame) = self.next_frame() {
                on_frame(frame);
            }
        }
    }

    /// Bytes still missing from the candidate at the front of the buffer, once its LEN is
    /// known; 1 while the header is incomplete.
    fn missing(&self) -> usize {
        match self.buf.as_slice() {
            [HEADER, HEADER, len, ..] if (MIN_LEN..=MAX_LEN).contains(len) => {
                (3 + *len as usize).saturating_sub(self.buf.len())
            }
            _ => 1,
        }
    }

    /// Returns the next complete frame already in the buffer, if any.
    pub fn next_frame(&mut self) -> Option<Frame> {
        loop {
            match self.scan() {
                Scan::NeedMore if self.stale == 0 => return None,
                Scan::NeedMore | Scan::Reject => self.drop_front(1),
                Scan::Complete(n) => {
                    let frame = self
                        .buf
                        .get(4..n - 1)
                        .and_then(|data| Frame::new(self.buf.get(3).copied().unwrap_or(0), data));
                    self.drop_front(n);
                    if frame.is_some() {
                        return frame;
                    }
                }
            }
        }
    }

    /// Tells the decoder the line has been quiet long enough that a frame in progress was cut
    /// short (a sender writes a frame in one go). Every incomplete candidate is dropped, and any
    /// complete frame found inside them on the rescan is returned (drain with
    /// [`next_frame`](Self::next_frame) as after [`push`](Self::push)).
    pub fn on_quiet_line(&mut self) -> Option<Frame> {
        self.stale = self.buf.len();
        self.next_frame()
    }

    /// True while the decoder holds the start of a frame that is not complete yet.
    pub fn has_partial(&self) -> bool {
        !self.buf.is_empty()
    }

    /// Number of received bytes that were not part of any frame (noise, servo packets,
    /// rejected candidates). Wraps at `u32::MAX`.
    pub fn skipped_bytes(&self) -> u32 {
        self.skipped
    }

    /// Decides what the start of the buffer is.
    fn scan(&self) -> Scan {
        let b = &self.buf;
        match (b.first(), b.get(1), b.get(2)) {
            (None, _, _) => Scan::NeedMore,
            (Some(&h), _, _) if h != HEADER => Scan::Reject,
            (_, None, _) => Scan::NeedMore,
            (_, Some(&h), _) if h != HEADER => Scan::Reject,
            (_, _, None) => Scan::NeedMore,
            (_, _, Some(&len)) if !(MIN_LEN..=MAX_LEN).contains(&len) => Scan::Reject,
            (_, _, Some(&len)) => {
                let n = 3 + len as usize;
                match b.get(n - 1) {
                    None => Scan::NeedMore,
                    Some(&FOOTER) => Scan::Complete(n),
                    Some(_) => Scan::Reject,
                }
            }
        }
    }

    /// Removes the first `n` bytes of the buffer, counting rejected ones as skipped.
    fn drop_front(&mut self, n: usize) {
        let n = n.min(self.buf.len());
        self.stale = self.stale.saturating_sub(n);
        if n == 1 {
            self.skipped = self.skipped.wrapping_add(1);
        }
        let len = self.buf.len();
        self.buf.copy_within(n..len, 0);
        self.buf.truncate(len - n);
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn decode_all(bytes: &[u8]) -> std::vec::Vec<Frame> {
        let mut d = FrameDecoder::new();
        let mut out = std::vec::Vec::new();
        d.feed(bytes, |f| out.push(f));
        out
    }

    fn frame(cmd: u8, data: &[u8]) -> Frame {
        Frame::new(cmd, data).unwrap()
    }

    #[test]
    fn encodes_get_angles_request() {
        assert_eq!(
            frame(0x20, &[]).to_bytes().as_slice(),
            &[0xFE, 0xFE, 0x02, 0x20, 0xFA]
        );
    }

    #[test]
    fn decodes_frame_with_fe_and_fa_in_data() {
        // send_angle joint 1 to -1.5 deg (0xFF6A)... and a data byte equal to FA and FE.
        let f = frame(0x22, &[0xFE, 0xFA, 0xFE, 0xFE, 0xFA, 0x00]);
        assert_eq!(decode_all(&f.to_bytes()), [f]);
    }

    #[test]
    fn skips_noise_and_servo_packets() {
        let f = frame(0x20, &[]);
        let mut bytes = std::vec![0xFF, 0xFF, 0x01, 0x02, 0x00, 0xFC, 0x12, 0xFA];
        bytes.extend_from_slice(&f.to_bytes());
        bytes.extend_from_slice(&[0x00, 0xFE]);
        assert_eq!(decode_all(&bytes), [f]);
    }

    #[test]
    fn triple_header_still_decodes() {
        assert_eq!(
            decode_all(&[0xFE, 0xFE, 0xFE, 0x02, 0x20, 0xFA]),
            [frame(0x20, &[])]
        );
    }

    #[test]
    fn bad_footer_rescans_and_finds_embedded_frame() {
        // A candidate with LEN 6 whose sixth byte is not FA hides a real frame.
        let bytes = [0xFE, 0xFE, 0x06, 0xFE, 0xFE, 0x02, 0x29, 0xFA, 0x11];
        assert_eq!(decode_all(&bytes), [frame(0x29, &[])]);
    }

    #[test]
    fn rejects_len_zero_one_and_absurd() {
        let good = frame(0x12, &[]).to_bytes();
        for bad_len in [0u8, 1, MAX_LEN + 1, 0xFF] {
            let mut bytes = std::vec![0xFE, 0xFE, bad_len];
            bytes.extend_from_slice(&good);
            assert_eq!(decode_all(&bytes), [frame(0x12, &[])], "LEN {bad_len}");
        }
    }

    #[test]
    fn any_chunking_gives_the_same_frames() {
        let a = frame(0x22, &[0, 1, 0xFF, 0x6A, 0, 0, 0, 0, 0, 0, 0, 0, 50]);
        let b = frame(0x20, &[]);
        let mut bytes = std::vec::Vec::new();
        bytes.extend_from_slice(&a.to_bytes());
        bytes.extend_from_slice(&b.to_bytes());
        for split in 0..bytes.len() {
            let mut d = FrameDecoder::new();
            let mut out = std::vec::Vec::new();
            d.feed(&bytes[..split], |f| out.push(f));
            d.feed(&bytes[split..], |f| out.push(f));
            assert_eq!(out, [a.clone(), b.clone()]);
        }
    }

    #[test]
    fn quiet_line_drops_truncated_frame_but_keeps_the_next() {
        let mut d = FrameDecoder::new();
        let mut out = std::vec::Vec::new();
        d.feed(&[0xFE, 0xFE, 0x0F, 0x22, 0x01], |f| out.push(f));
        assert!(d.has_partial());
        assert_eq!(d.on_quiet_line(), None);
        assert!(!d.has_partial());
        d.feed(&frame(0x20, &[]).to_bytes(), |f| out.push(f));
        assert_eq!(out, [frame(0x20, &[])]);
    }

    #[test]
    fn quiet_line_recovers_frame_inside_a_false_candidate() {
        let mut d = FrameDecoder::new();
        let mut out = std::vec::Vec::new();
        d.feed(&[0xFE, 0xFE, 0x30, 0xFE, 0xFE, 0x02, 0x20, 0xFA], |f| {
            out.push(f)
        });
        assert!(out.is_empty());
        let first = d.on_quiet_line();
        assert_eq!(first, Some(frame(0x20, &[])));
        assert!(!d.has_partial());
    }

    #[test]
    fn frame_data_too_long_is_refused() {
        assert!(Frame::new(0x01, &[0; MAX_DATA + 1]).is_none());
        assert!(Frame::new(0x01, &[0; MAX_DATA]).is_some());
    }
}
