//! Transparent mode (0xC2 1): raw bytes both ways between the host and the bus, for tools that
//! talk to the servos directly.
//!
//! The one thing still recognised from the host is [`EXIT_FRAME`] (`FE FE 03 C2 00 FA`, "set
//! transponder mode 0"): the Basic answers it with `FE FE 03 C2 01 FA` and returns to framed
//! mode. Host bytes that might be the start of it are held back until they are known not to be
//! (or the host goes quiet for [`timing::HOST_FRAME_GAP_US`]), so the exit frame never reaches
//! the bus. Host bytes go onto the bus only into a quiet wire; the Basic's own echo is removed
//! from what goes back to the host.

use heapless::{Deque, Vec};
use protocol_core::BytePort;
use protocol_core::timing;

use crate::forwarder::ECHO_GRACE_US;

/// The frame that ends transparent mode.
pub const EXIT_FRAME: [u8; 6] = [0xFE, 0xFE, 0x03, 0xC2, 0x00, 0xFA];
/// Host bytes waiting for the bus; the bus drains them 8x faster than the host fills them.
pub const TO_BUS_CAPACITY: usize = 256;
/// Most bytes written to the bus at once (and so most echo bytes expected back).
pub const BUS_WRITE_CHUNK: usize = 64;

/// The transparent pipe's state.
#[derive(Debug, Default)]
pub(crate) struct Transparent {
    /// Host bytes that match the start of [`EXIT_FRAME`] so far.
    held: Vec<u8, 6>,
    to_bus: Deque<u8, TO_BUS_CAPACITY>,
    /// Bytes written to the bus whose echo has not come back yet.
    echo: Deque<u8, BUS_WRITE_CHUNK>,
    /// When the last write left the transmitter; echo still expected until the grace is over.
    tx_done_us: Option<u64>,
    /// Host bytes dropped because the bus queue was full. Wraps.
    pub(crate) dropped: u32,
}

impl Transparent {
    /// Takes one byte from the host; true if it completed [`EXIT_FRAME`].
    pub(crate) fn host_byte(&mut self, byte: u8) -> bool {
        // Cannot fail: `held` is a strict prefix of the 6-byte exit frame, at most 5 bytes.
        let _ = self.held.push(byte);
        if self.held.as_slice() == EXIT_FRAME {
            self.held.clear();
            return true;
        }
        // Release bytes from the front until what is held could still become the exit frame.
        while !EXIT_FRAME.starts_with(&self.held) {
            let first = self.held.first().copied();
            self.held.remove(0);
            if let Some(b) = first {
                self.queue_for_bus(b);
            }
        }
        false
    }

    /// Releases held-back bytes once the host has been quiet long enough that they cannot be
    /// the start of an exit frame.
    pub(crate) fn host_quiet(&mut self, quiet_us: u64) {
        if quiet_us >= timing::HOST_FRAME_GAP_US && !self.held.is_empty() {
            let held = core::mem::take(&mut self.held);
            for b in held {
                self.queue_for_bus(b);
            }
        }
    }

    fn queue_for_bus(&mut self, byte: u8) {
        if self.to_bus.push_back(byte).is_err() {
            self.dropped = self.dropped.wrapping_add(1);
        }
    }

    /// Takes one byte from the bus; returns it unless it is the echo of our own transmission.
    pub(crate) fn bus_byte(&mut self, byte: u8) -> Option<u8> {
        match self.echo.front() {
            Some(&expected) if expected == byte => {
                self.echo.pop_front();
                None
            }
            Some(_) => {
                // Not our echo: a collision or a station answering; stop expecting it.
                self.echo.clear();
                Some(byte)
            }
            None => Some(byte),
        }
    }

    /// Writes queued host bytes onto the bus when the wire has been quiet for
    /// [`timing::BUS_QUIET_BEFORE_SEND_US`]. `echo` says whether the wiring echoes.
    pub(crate) fn poll<B: BytePort>(
        &mut self,
        now_us: u64,
        bus_quiet_us: u64,
        bus: &mut B,
        echo: bool,
    ) {
        if !bus.tx_idle() {
            return;
        }
        let done = *self.tx_done_us.get_or_insert(now_us);
        if now_us.saturating_sub(done) >= ECHO_GRACE_US {
            self.echo.clear();
        }
        if self.to_bus.is_empty()
            || !self.echo.is_empty()
            || bus_quiet_us < timing::BUS_QUIET_BEFORE_SEND_US
        {
            return;
        }
        let mut chunk: Vec<u8, BUS_WRITE_CHUNK> = Vec::new();
        while !chunk.is_full() {
            match self.to_bus.pop_front() {
                Some(b) => {
                    let _ = chunk.push(b);
                    if echo {
                        let _ = self.echo.push_back(b);
                    }
                }
                None => break,
            }
        }
        bus.write(&chunk);
        self.tx_done_us = None;
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn drain(t: &mut Transparent) -> std::vec::Vec<u8> {
        t.to_bus.iter().copied().collect()
    }

    #[test]
    fn exit_frame_is_recognised_and_not_forwarded() {
        let mut t = Transparent::default();
        let ping = [0xFF, 0xFF, 0x01, 0x02, 0x01, 0xFB];
        for b in ping {
            assert!(!t.host_byte(b));
        }
        let exits: std::vec::Vec<bool> = EXIT_FRAME.iter().map(|&b| t.host_byte(b)).collect();
        assert_eq!(exits, [false, false, false, false, false, true]);
        assert_eq!(drain(&mut t), ping);
    }

    #[test]
    fn a_near_miss_of_the_exit_frame_is_forwarded_whole_and_in_order() {
        let mut t = Transparent::default();
        // FE FE FE 03 C2 01 FA: an extra FE, then "mode 1" - not an exit.
        let bytes = [0xFE, 0xFE, 0xFE, 0x03, 0xC2, 0x01, 0xFA];
        assert!(!bytes.iter().any(|&b| t.host_byte(b)));
        assert_eq!(drain(&mut t), bytes);
    }

    #[test]
    fn exit_frame_after_an_extra_header_byte_still_exits() {
        let mut t = Transparent::default();
        assert!(!t.host_byte(0xFE));
        let exited = EXIT_FRAME.iter().map(|&b| t.host_byte(b)).any(|e| e);
        assert!(exited);
        assert_eq!(drain(&mut t), [0xFE]);
    }

    #[test]
    fn held_bytes_are_released_when_the_host_goes_quiet() {
        let mut t = Transparent::default();
        t.host_byte(0xFE);
        t.host_byte(0xFE);
        t.host_quiet(timing::HOST_FRAME_GAP_US - 1);
        assert!(drain(&mut t).is_empty());
        t.host_quiet(timing::HOST_FRAME_GAP_US);
        assert_eq!(drain(&mut t), [0xFE, 0xFE]);
    }

    #[test]
    fn own_echo_is_removed_but_other_bytes_pass() {
        let mut t = Transparent::default();
        for b in [1, 2, 3] {
            t.host_byte(b);
        }
        let mut bus = protocol_core::NullPort;
        t.poll(1_000, 1_000, &mut bus, true);
        assert_eq!(t.bus_byte(1), None);
        assert_eq!(t.bus_byte(2), None);
        assert_eq!(t.bus_byte(9), Some(9));
        assert_eq!(t.bus_byte(3), Some(3));
    }
}
