//! The machinery both streaming decoders share: a bounded buffer that finds length-delimited
//! packets (`H H ... LEN ...`) in a byte stream, rescans from the byte after a bad candidate's
//! first header byte, and drops candidates a quiet line cut short. The wire formats
//! ([`crate::frame`], [`crate::servo`]) only say what the front of the buffer is.

use heapless::Vec;

/// What the bytes at the front of the buffer are.
pub(crate) enum Scan {
    /// The start of a candidate that needs more bytes.
    NeedMore,
    /// A complete, valid packet of this many bytes.
    Complete(usize),
    /// The first byte cannot start a packet: drop it.
    Reject,
    /// A complete candidate with a wrong checksum: drop its first byte.
    BadChecksum,
}

/// A length-delimited wire format.
pub(crate) trait Format {
    /// The byte every packet starts with, twice.
    const HEADER: u8;
    /// What the front of `buf` is.
    fn scan(buf: &[u8]) -> Scan;
    /// Bytes still missing from the candidate at the front of `buf` once its length is known;
    /// 1 while its header is incomplete.
    fn missing(buf: &[u8]) -> usize;
}

/// A buffer of `N` bytes scanning a stream for packets of one [`Format`].
#[derive(Clone, Debug)]
pub(crate) struct Scanner<const N: usize> {
    buf: Vec<u8, N>,
    /// How many bytes at the front of `buf` arrived before the last quiet gap: a candidate that
    /// starts there can no longer complete.
    stale: usize,
    /// Bytes dropped because they were outside any packet or started a rejected candidate.
    skipped: u32,
    /// Candidates dropped for a wrong checksum.
    bad_checksums: u32,
}

impl<const N: usize> Scanner<N> {
    /// An empty scanner.
    pub(crate) const fn new() -> Self {
        Self {
            buf: Vec::new(),
            stale: 0,
            skipped: 0,
            bad_checksums: 0,
        }
    }

    /// Appends one received byte.
    pub(crate) fn push(&mut self, byte: u8) {
        if self.buf.is_full() {
            // Only reachable when a caller ignored packets waiting to be drained: make room by
            // dropping the oldest byte rather than failing.
            self.drop_front(1);
        }
        // Cannot fail: there is room now.
        let _ = self.buf.push(byte);
    }

    /// The next complete packet in the buffer, turned into a `T` by `build` (given the
    /// packet's bytes; a packet it refuses is dropped).
    pub(crate) fn next<F: Format, T>(&mut self, build: impl Fn(&[u8]) -> Option<T>) -> Option<T> {
        loop {
            match F::scan(&self.buf) {
                Scan::NeedMore if self.stale == 0 => return None,
                Scan::NeedMore | Scan::Reject => self.drop_front(1),
                Scan::BadChecksum => {
                    self.bad_checksums = self.bad_checksums.wrapping_add(1);
                    self.drop_front(1);
                }
                Scan::Complete(n) => {
                    let packet = self.buf.get(..n).and_then(&build);
                    self.drop_front(n);
                    if packet.is_some() {
                        return packet;
                    }
                }
            }
        }
    }

    /// Feeds every byte of `bytes`, calling `on_packet` with each packet found, in order.
    ///
    /// Same result as pushing byte by byte and draining, but faster: while idle it skips
    /// straight to the next header byte, and once a candidate's length is known it copies the
    /// rest of the candidate in one go.
    pub(crate) fn feed<F: Format, T>(
        &mut self,
        mut bytes: &[u8],
        build: impl Fn(&[u8]) -> Option<T>,
        mut on_packet: impl FnMut(T),
    ) {
        while !bytes.is_empty() {
            let take = if self.stale != 0 {
                1
            } else if self.buf.is_empty() {
                // Idle: no byte before the next header byte can start a packet.
                let skip = bytes
                    .iter()
                    .position(|&b| b == F::HEADER)
                    .unwrap_or(bytes.len());
                // skip <= bytes.len(); a wrap of the statistics counter is harmless.
                self.skipped = self.skipped.wrapping_add(skip as u32);
                bytes = bytes.get(skip..).unwrap_or_default();
                if bytes.is_empty() {
                    return;
                }
                1
            } else {
                F::missing(&self.buf).clamp(1, bytes.len())
            };
            let (chunk, rest) = bytes.split_at(take.min(bytes.len()));
            bytes = rest;
            // `take` fits the buffer unless a caller left packets undrained: then evict.
            if self.buf.extend_from_slice(chunk).is_err() {
                chunk.iter().for_each(|&b| self.push(b));
            }
            while let Some(packet) = self.next::<F, T>(&build) {
                on_packet(packet);
            }
        }
    }

    /// The line went quiet: every candidate now in the buffer was cut short.
    pub(crate) fn on_quiet_line(&mut self) {
        self.stale = self.buf.len();
    }

    /// True while the buffer holds the start of a packet that is not complete yet.
    pub(crate) fn has_partial(&self) -> bool {
        !self.buf.is_empty()
    }

    /// Bytes held (a candidate in progress).
    pub(crate) fn len(&self) -> usize {
        self.buf.len()
    }

    /// The bytes held, the candidate in progress first.
    pub(crate) fn bytes(&self) -> &[u8] {
        &self.buf
    }

    /// Forgets the first `n` bytes held (all of them if fewer); a candidate starting after them
    /// is scanned as usual.
    pub(crate) fn discard(&mut self, n: usize) {
        let n = n.min(self.buf.len());
        // n <= N, a buffer size; a wrap of the statistics counter is harmless.
        self.skipped = self.skipped.wrapping_add(n as u32);
        self.remove_front(n);
    }

    /// Bytes dropped outside packets or at the start of rejected candidates. Wraps.
    pub(crate) fn skipped(&self) -> u32 {
        self.skipped
    }

    /// Candidates dropped for a wrong checksum. Wraps.
    pub(crate) fn bad_checksums(&self) -> u32 {
        self.bad_checksums
    }

    /// Removes the first `n` bytes of the buffer; a single dropped byte counts as skipped.
    fn drop_front(&mut self, n: usize) {
        if n == 1 && !self.buf.is_empty() {
            self.skipped = self.skipped.wrapping_add(1);
        }
        self.remove_front(n);
    }

    /// Removes the first `n` bytes of the buffer (all of them if fewer).
    fn remove_front(&mut self, n: usize) {
        let n = n.min(self.buf.len());
        self.stale = self.stale.saturating_sub(n);
        let len = self.buf.len();
        self.buf.copy_within(n..len, 0);
        self.buf.truncate(len - n);
    }
}
