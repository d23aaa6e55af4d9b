//! A serial line into the Basic: bytes at the line's speed, each readable once its last bit is
//! in. Both of the image's ports are one: the bus (1 Mbaud) and the USB link (115 200 baud).

use heapless::Deque;
use protocol_core::timing::wire_time_us;

/// Bytes on their way to the Basic, and when the line is free again. See the
/// [module doc](self).
pub struct Line<const N: usize> {
    baud: u32,
    /// Each byte with the time its last bit is in.
    arriving: Deque<(u64, u8), N>,
    busy_until_us: u64,
}

impl<const N: usize> Line<N> {
    /// A quiet line at `baud`.
    pub const fn new(baud: u32) -> Self {
        Self {
            baud,
            arriving: Deque::new(),
            busy_until_us: 0,
        }
    }

    /// Sends `bytes` to the Basic from `start_us`, or once the line is free; when the last is in.
    pub fn send(&mut self, start_us: u64, bytes: &[u8]) -> u64 {
        let mut t = start_us.max(self.busy_until_us);
        for &b in bytes {
            t += wire_time_us(1, self.baud);
            self.arriving.push_back((t, b)).ok();
        }
        self.busy_until_us = t;
        t
    }

    /// Takes the line for `len` bytes the Basic sends from `start_us` (it does not hear them
    /// back); when they are out.
    pub fn occupy(&mut self, start_us: u64, len: usize) -> u64 {
        let start = start_us.max(self.busy_until_us);
        self.busy_until_us = start + wire_time_us(len as u32, self.baud);
        self.busy_until_us
    }

    /// The next byte that is in by `now_us`.
    pub fn take(&mut self, now_us: u64) -> Option<u8> {
        match self.arriving.front() {
            Some(&(due, b)) if due <= now_us => {
                self.arriving.pop_front();
                Some(b)
            }
            _ => None,
        }
    }

    /// True once nothing is on the line at `now_us`.
    pub fn free(&self, now_us: u64) -> bool {
        now_us >= self.busy_until_us
    }

    /// Room for this many more bytes.
    pub fn room(&self) -> usize {
        N - self.arriving.len()
    }
}
