//! Host frames: `FE FE LEN CMD DATA... FA`, `LEN = len(DATA) + 2`.
//!
//! [`Frame`] is one validated frame (its command byte and data); [`FrameDecoder`] finds frames
//! in a byte stream. The decoder follows `protocol.md` section 2: it parses by length (so `FE`
//! and `FA` inside the data are ordinary bytes), drops a candidate whose footer is not `FA` or
//! whose LEN is impossible and rescans from the byte after its first `FE`, skips every byte
//! outside a frame, and drops a partial frame when the line goes quiet mid-frame
//! ([`FrameDecoder::on_quiet_line`]).

use heapless::Vec;

use crate::scanner::{Format, Scan, Scanner};

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
/// Shortest possible frame on the wire: `FE FE 02 CMD FA`, no data.
pub const MIN_FRAME_BYTES: usize = 3 + MIN_LEN as usize;
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
    scanner: Scanner<MAX_FRAME_BYTES>,
    lengths: FrameLengths,
}

/// How a [`FrameDecoder`] reads LEN.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Hash)]
pub enum FrameLengths {
    /// LEN = len(DATA) + 2, always (`protocol.md` section 2).
    #[default]
    Counted,
    #[cfg(feature = "seed-dialect")]
    /// As [`Counted`](Self::Counted), and the seed manual's miscounted LENs are accepted
    /// where they cannot mean anything else ([`SEED_MISCOUNTS`]): the frame ends at the first
    /// `FA` among the lengths that command really has and the LEN printed.
    SeedManual,
}

#[cfg(feature = "seed-dialect")]
/// The LENs the seed manual prints wrong in its request examples (`docs/protocol.md`,
/// "Dialects"): the command, the LEN as printed, and the data lengths the command really
/// has. 0x2A and 0x3C print decimal 15 as `0x15`, 0x81 and 0x83 decimal 14 as `0x14`, 0x41 sends
/// its speed byte under LEN 2 and 0x50 ("check connection") has no data under LEN 3.
pub const SEED_MISCOUNTS: [(u8, u8, &[u8]); 6] = [
    (0x2A, 0x15, &[12, 13]),
    (0x3C, 0x15, &[13]),
    (0x81, 0x14, &[12]),
    (0x83, 0x14, &[12]),
    (0x41, 0x02, &[1]),
    (0x50, 0x03, &[0]),
];

/// The data lengths a seed-manual frame with `cmd` and `len` really has, besides LEN's own.
#[cfg(feature = "seed-dialect")]
fn seed_miscount(cmd: u8, len: u8) -> Option<&'static [u8]> {
    SEED_MISCOUNTS
        .iter()
        .find(|(c, l, _)| *c == cmd && *l == len)
        .map(|(_, _, real)| *real)
}

/// Host frames as the seed manual prints them: [`HostFrames`] plus [`SEED_MISCOUNTS`].
#[cfg(feature = "seed-dialect")]
struct SeedFrames;

#[cfg(feature = "seed-dialect")]
impl Format for SeedFrames {
    const HEADER: u8 = HEADER;

    fn scan(b: &[u8]) -> Scan {
        let (Some(&len), Some(&cmd)) = (b.get(2), b.get(3)) else {
            return HostFrames::scan(b);
        };
        let Some(real) = seed_miscount(cmd, len).filter(|_| b.starts_with(&[HEADER, HEADER]))
        else {
            return HostFrames::scan(b);
        };
        // Every candidate end, shortest first: the first one with FA there is the frame.
        let printed = len - 2;
        let mut lengths = real
            .iter()
            .copied()
            .chain(Some(printed))
            .collect::<Vec<u8, 4>>();
        lengths.sort_unstable();
        for data_len in lengths {
            let end = 4 + data_len as usize;
            match b.get(end) {
                None => return Scan::NeedMore,
                Some(&FOOTER) => return Scan::Complete(end + 1),
                Some(_) => {}
            }
        }
        Scan::Reject
    }

    fn missing(b: &[u8]) -> usize {
        match (b.get(2), b.get(3)) {
            (Some(&len), Some(&cmd)) => match seed_miscount(cmd, len) {
                Some(real) => {
                    let shortest = real.iter().copied().chain(Some(len - 2)).min().unwrap_or(0);
                    (5 + shortest as usize).saturating_sub(b.len()).max(1)
                }
                None => HostFrames::missing(b),
            },
            _ => 1,
        }
    }
}

impl Default for FrameDecoder {
    fn default() -> Self {
        Self::new()
    }
}

/// The host-frame format for the [`Scanner`].
struct HostFrames;

impl Format for HostFrames {
    const HEADER: u8 = HEADER;

    fn scan(b: &[u8]) -> Scan {
        match (b.first(), b.get(1), b.get(2)) {
            (None, _, _) => Scan::NeedMore,
            (Some(&h), _, _) if h != HEADER => Scan::Reject,
            (_, None, _) => Scan::NeedMore,
            (_, Some(&h), _) if h != HEADER => Scan::Reject,
            (_, _, None) => Scan::NeedMore,
            (_, _, Some(&len)) if !(MIN_LEN..=MAX_LEN).contains(&len) => Scan::Reject,
            (_, _, Some(&len)) => match b.get(2 + len as usize) {
                None => Scan::NeedMore,
                Some(&FOOTER) => Scan::Complete(3 + len as usize),
                Some(_) => Scan::Reject,
            },
        }
    }

    fn missing(b: &[u8]) -> usize {
        match b {
            [HEADER, HEADER, len, ..] if (MIN_LEN..=MAX_LEN).contains(len) => {
                (3 + *len as usize).saturating_sub(b.len())
            }
            _ => 1,
        }
    }
}

/// The frame in `bytes`, a complete `FE FE LEN CMD DATA FA`.
fn frame_from(bytes: &[u8]) -> Option<Frame> {
    let (&cmd, rest) = bytes.get(3..)?.split_first()?;
    let (_footer, data) = rest.split_last()?;
    Frame::new(cmd, data)
}

impl FrameDecoder {
    /// An empty decoder.
    pub const fn new() -> Self {
        Self {
            scanner: Scanner::new(),
            lengths: FrameLengths::Counted,
        }
    }

    /// Reads LEN as `lengths` says from the next frame on; a frame already begun is read the
    /// same way once it is complete.
    pub fn set_lengths(&mut self, lengths: FrameLengths) {
        self.lengths = lengths;
    }

    /// How this decoder reads LEN.
    pub fn lengths(&self) -> FrameLengths {
        self.lengths
    }

    /// Appends one received byte; returns the frame it completes, if any.
    pub fn push(&mut self, byte: u8) -> Option<Frame> {
        self.scanner.push(byte);
        self.next_frame()
    }

    /// Feeds every byte of `bytes`, calling `on_frame` with each frame found, in order.
    ///
    /// Same result as [`push`](Self::push)ing byte by byte and draining, but faster: while idle
    /// it skips straight to the next `FE`, and once a candidate's LEN is known it copies the
    /// rest of the candidate in one go.
    pub fn feed(&mut self, bytes: &[u8], on_frame: impl FnMut(Frame)) {
        match self.lengths {
            FrameLengths::Counted => self
                .scanner
                .feed::<HostFrames, _>(bytes, frame_from, on_frame),
            #[cfg(feature = "seed-dialect")]
            FrameLengths::SeedManual => {
                self.scanner
                    .feed::<SeedFrames, _>(bytes, frame_from, on_frame);
            }
        }
    }

    /// Returns the next complete frame already in the buffer, if any.
    pub fn next_frame(&mut self) -> Option<Frame> {
        match self.lengths {
            FrameLengths::Counted => self.scanner.next::<HostFrames, _>(frame_from),
            #[cfg(feature = "seed-dialect")]
            FrameLengths::SeedManual => self.scanner.next::<SeedFrames, _>(frame_from),
        }
    }

    /// Tells the decoder the line has been quiet long enough that a frame in progress was cut
    /// short (a sender writes a frame in one go). Every incomplete candidate is dropped, and any
    /// complete frame found inside them on the rescan is returned (drain with
    /// [`next_frame`](Self::next_frame) as after [`push`](Self::push)).
    pub fn on_quiet_line(&mut self) -> Option<Frame> {
        self.scanner.on_quiet_line();
        self.next_frame()
    }

    /// Bytes held: the candidate in progress and whatever was received after its start.
    pub(crate) fn held(&self) -> usize {
        self.scanner.len()
    }

    /// Forgets the first `n` bytes held (they were something else, a servo packet's data or
    /// checksum that looked like the start of a frame); the rest is scanned again.
    pub(crate) fn discard(&mut self, n: usize) {
        self.scanner.discard(n);
    }

    /// True while the decoder holds the start of a frame that is not complete yet.
    pub fn has_partial(&self) -> bool {
        self.scanner.has_partial()
    }

    /// The bytes held: the candidate in progress (from its first `FE`) and whatever arrived
    /// after its start; empty when no frame is in progress. A transponder that passes a frame
    /// on as it arrives reads it here.
    pub fn partial(&self) -> &[u8] {
        self.scanner.bytes()
    }

    /// Number of received bytes that were not part of any frame (noise, servo packets,
    /// rejected candidates). Wraps at `u32::MAX`.
    pub fn skipped_bytes(&self) -> u32 {
        self.scanner.skipped()
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
