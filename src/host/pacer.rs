//! Paces what clients send to the speed of the serial line it travels on.
//!
//! A real 115200 baud port cannot carry more than 11 520 bytes a second: a client that writes
//! faster blocks in `write` once the driver's buffer is full. The virtual robot queues whatever
//! it is given, so without pacing a client flooding the pseudo-terminal (`cat /dev/urandom >
//! /dev/pts/5`) would grow that queue without bound and every later request would wait behind
//! the flood. The pacer lets through only what the line can carry within a short window; the
//! rest stays in the kernel's buffers, and the client blocks, as with real hardware.

use protocol_core::timing::wire_time_ns;

/// Bytes allowed ahead of the wire: 256 (22 ms at 115200 baud) covers the longest frame
/// (67 bytes) several times over, so normal requests never wait for the pacer.
pub const WINDOW_BYTES: u32 = 256;

/// Tracks how far ahead of virtual time a serial line is booked.
#[derive(Debug, Clone)]
pub struct LinePacer {
    byte_time_ns: u64,
    window_ns: u64,
    busy_until_ns: u64,
}

impl LinePacer {
    /// A pacer for a line at `baud` (8N1) that lets `window_bytes` queue ahead of the wire.
    pub fn new(baud: u32, window_bytes: u32) -> Self {
        let byte_time_ns = wire_time_ns(1, baud).max(1);
        Self {
            byte_time_ns,
            window_ns: byte_time_ns.saturating_mul(u64::from(window_bytes)),
            busy_until_ns: 0,
        }
    }

    /// How many bytes may be handed to the line at virtual time `now_ns`.
    pub fn room(&self, now_ns: u64) -> usize {
        let backlog_ns = self.busy_until_ns.saturating_sub(now_ns);
        let free_ns = self.window_ns.saturating_sub(backlog_ns);
        usize::try_from(free_ns / self.byte_time_ns).unwrap_or(usize::MAX)
    }

    /// Books `bytes` bytes handed to the line at `now_ns`.
    pub fn consumed(&mut self, bytes: usize, now_ns: u64) {
        let bytes = u64::try_from(bytes).unwrap_or(u64::MAX);
        self.busy_until_ns = self
            .busy_until_ns
            .max(now_ns)
            .saturating_add(bytes.saturating_mul(self.byte_time_ns));
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use protocol_core::timing::HOST_BAUD;

    #[test]
    fn lets_a_window_through_then_one_byte_per_byte_time() {
        let byte_ns = wire_time_ns(1, HOST_BAUD);
        let mut pacer = LinePacer::new(HOST_BAUD, 8);
        assert_eq!(pacer.room(0), 8);
        pacer.consumed(8, 0);
        assert_eq!(pacer.room(0), 0);
        assert_eq!(pacer.room(byte_ns - 1), 0);
        assert_eq!(pacer.room(3 * byte_ns), 3);
        // An idle line does not bank credit beyond the window.
        assert_eq!(pacer.room(1_000 * byte_ns), 8);
    }

    #[test]
    fn a_request_after_a_quiet_spell_goes_through_at_once() {
        let mut pacer = LinePacer::new(HOST_BAUD, WINDOW_BYTES);
        pacer.consumed(5, 1_000);
        assert!(
            pacer.room(2_000) >= 67,
            "room for the longest frame right after a request"
        );
    }
}
