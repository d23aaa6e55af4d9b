//! Transparent mode (0xC2 1): raw bytes both ways between the host and the bus, for tools that
//! talk to the servos directly.
//!
//! Three exact frames from the host are still the Basic's own, so a client can always find out
//! where it is and get back ([`Intercepted`]): `FE FE 03 C2 00 FA` (set mode 0: answered
//! `01`, back to framed mode), `FE FE 03 C2 01 FA` (set mode 1: answered `01`) and
//! `FE FE 02 C3 FA` (get mode: answered `01`). Host bytes that might be the start of one of
//! them are held back until they are known not to be (or the host goes quiet for
//! [`timing::HOST_FRAME_GAP_US`]), so these frames never reach the bus. Everything else is
//! copied: host bytes go onto the bus only into a free wire (as framed requests do), and every bus byte goes to the
//! host except the Basic's own echo.

use heapless::{Deque, Vec};
use protocol_core::BytePort;
use protocol_core::timing;

use crate::forwarder::{ECHO_GRACE_US, may_start_after_quiet};

/// A host frame the Basic still answers in transparent mode.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Intercepted {
    /// `FE FE 03 C2 00 FA`: back to framed mode.
    SetFramed,
    /// `FE FE 03 C2 01 FA`: stay transparent.
    SetTransparent,
    /// `FE FE 02 C3 FA`: which mode.
    GetMode,
}

impl Intercepted {
    /// Every intercepted frame with its wire bytes.
    pub const ALL: [(Self, &'static [u8]); 3] = [
        (Self::SetFramed, &[0xFE, 0xFE, 0x03, 0xC2, 0x00, 0xFA]),
        (Self::SetTransparent, &[0xFE, 0xFE, 0x03, 0xC2, 0x01, 0xFA]),
        (Self::GetMode, &[0xFE, 0xFE, 0x02, 0xC3, 0xFA]),
    ];
}

/// Longest intercepted frame.
const INTERCEPT_MAX: usize = 6;

/// True if `held` could still become an intercepted frame.
fn may_be_intercepted(held: &[u8]) -> bool {
    Intercepted::ALL
        .iter()
        .any(|(_, bytes)| bytes.starts_with(held))
}

/// Host bytes waiting for the bus; the bus drains them 8x faster than the host fills them.
pub const TO_BUS_CAPACITY: usize = 256;
/// Most bytes written to the bus at once (and so most echo bytes expected back).
pub const BUS_WRITE_CHUNK: usize = 64;

/// The transparent pipe's state.
#[derive(Debug, Default)]
pub(crate) struct Transparent {
    /// Host bytes that match the start of an intercepted frame so far.
    held: Vec<u8, INTERCEPT_MAX>,
    to_bus: Deque<u8, TO_BUS_CAPACITY>,
    /// The last write to the bus while its echo may still come back...
    sent: Vec<u8, BUS_WRITE_CHUNK>,
    /// ...and how many of its bytes have come back so far (held until the echo is complete).
    echoed: usize,
    /// When the last write left the transmitter.
    tx_done_us: Option<u64>,
    /// Host bytes dropped because the bus queue was full. Wraps.
    pub(crate) dropped: u32,
}

impl Transparent {
    /// Takes one byte from the host; returns the intercepted frame it completes, if any.
    pub(crate) fn host_byte(&mut self, byte: u8) -> Option<Intercepted> {
        // Cannot fail: `held` is a strict prefix of an intercepted frame, shorter than
        // INTERCEPT_MAX.
        let _ = self.held.push(byte);
        if let Some((hit, _)) = Intercepted::ALL
            .iter()
            .find(|(_, bytes)| *bytes == self.held.as_slice())
        {
            self.held.clear();
            return Some(*hit);
        }
        // Release bytes from the front until what is held could still be intercepted.
        while !may_be_intercepted(&self.held) {
            let first = self.held.first().copied();
            self.held.remove(0);
            if let Some(b) = first {
                self.queue_for_bus(b);
            }
        }
        None
    }

    /// Releases held-back bytes once the host has been quiet long enough that they cannot be
    /// the start of an intercepted frame.
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

    /// Takes one byte from the bus and passes what is not our own echo to `emit`. An echo is
    /// recognised only whole: bytes that match the start of our last write are held until the
    /// rest matches too, and released if it does not. Returns `Some(true)` when a whole echo
    /// came back.
    pub(crate) fn bus_byte(&mut self, byte: u8, mut emit: impl FnMut(u8)) -> Option<bool> {
        if self.sent.get(self.echoed) == Some(&byte) {
            self.echoed += 1;
            if self.echoed == self.sent.len() {
                self.sent.clear();
                self.echoed = 0;
                return Some(true);
            }
            return None;
        }
        self.release_echo(&mut emit);
        emit(byte);
        None
    }

    /// Passes bytes held as a possible echo on to `emit`: they were not one.
    fn release_echo(&mut self, emit: &mut impl FnMut(u8)) {
        for &b in self.sent.get(..self.echoed).unwrap_or(&[]) {
            emit(b);
        }
        self.sent.clear();
        self.echoed = 0;
    }

    /// Writes queued host bytes onto the bus when the wire is free
    /// ([`may_start_after_quiet`]). `echo` is whether the wiring echoes, if known.
    /// Returns `Some(false)` when a write came back silent (no echo on this wiring).
    pub(crate) fn poll<B: BytePort>(
        &mut self,
        now_us: u64,
        bus_quiet_us: u64,
        bus: &mut B,
        echo: Option<bool>,
        mut emit: impl FnMut(u8),
    ) -> Option<bool> {
        if !bus.tx_idle() {
            return None;
        }
        let mut learned = None;
        let done = *self.tx_done_us.get_or_insert(now_us);
        if !self.sent.is_empty() && now_us.saturating_sub(done) >= ECHO_GRACE_US {
            if self.echoed == 0 {
                learned = Some(false);
            }
            self.release_echo(&mut emit);
        }
        if self.to_bus.is_empty() || !self.sent.is_empty() || !may_start_after_quiet(bus_quiet_us) {
            return learned;
        }
        let mut chunk: Vec<u8, BUS_WRITE_CHUNK> = Vec::new();
        while !chunk.is_full() {
            match self.to_bus.pop_front() {
                // Cannot fail: the chunk is not full.
                Some(b) => {
                    let _ = chunk.push(b);
                }
                None => break,
            }
        }
        bus.write(&chunk);
        if echo != Some(false) {
            self.sent = chunk;
        }
        self.tx_done_us = None;
        learned
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn drain(t: &mut Transparent) -> std::vec::Vec<u8> {
        t.to_bus.iter().copied().collect()
    }

    fn feed(t: &mut Transparent, bytes: &[u8]) -> std::vec::Vec<Intercepted> {
        bytes.iter().filter_map(|&b| t.host_byte(b)).collect()
    }

    const EXIT: [u8; 6] = [0xFE, 0xFE, 0x03, 0xC2, 0x00, 0xFA];

    #[test]
    fn exit_frame_is_recognised_and_not_forwarded() {
        let mut t = Transparent::default();
        let ping = [0xFF, 0xFF, 0x01, 0x02, 0x01, 0xFB];
        assert!(feed(&mut t, &ping).is_empty());
        let mut exit = EXIT.to_vec();
        let last = exit.pop().unwrap();
        assert!(feed(&mut t, &exit).is_empty());
        assert_eq!(t.host_byte(last), Some(Intercepted::SetFramed));
        assert_eq!(drain(&mut t), ping);
    }

    #[test]
    fn mode_query_and_set_transparent_are_answered_too() {
        let mut t = Transparent::default();
        let hits = feed(
            &mut t,
            &[
                0xFE, 0xFE, 0x02, 0xC3, 0xFA, 0xFE, 0xFE, 0x03, 0xC2, 0x01, 0xFA,
            ],
        );
        assert_eq!(hits, [Intercepted::GetMode, Intercepted::SetTransparent]);
        assert!(drain(&mut t).is_empty());
    }

    #[test]
    fn a_near_miss_of_the_exit_frame_is_forwarded_whole_and_in_order() {
        let mut t = Transparent::default();
        // FE FE FE 03 C2 07 FA: an extra FE, then "mode 7" - not intercepted.
        let bytes = [0xFE, 0xFE, 0xFE, 0x03, 0xC2, 0x07, 0xFA];
        assert!(feed(&mut t, &bytes).is_empty());
        assert_eq!(drain(&mut t), bytes);
    }

    #[test]
    fn exit_frame_after_an_extra_header_byte_still_exits() {
        let mut t = Transparent::default();
        assert_eq!(t.host_byte(0xFE), None);
        assert_eq!(feed(&mut t, &EXIT), [Intercepted::SetFramed]);
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

    fn from_bus(t: &mut Transparent, bytes: &[u8]) -> (std::vec::Vec<u8>, Option<bool>) {
        let mut out = std::vec::Vec::new();
        let mut learned = None;
        for &b in bytes {
            learned = learned.or(t.bus_byte(b, |x| out.push(x)));
        }
        (out, learned)
    }

    fn write_123(t: &mut Transparent, echo: Option<bool>) {
        for b in [1, 2, 3] {
            t.host_byte(b);
        }
        let mut bus = protocol_core::NullPort;
        t.poll(1_000, 1_000, &mut bus, echo, |_| {});
    }

    #[test]
    fn a_whole_echo_is_removed() {
        let mut t = Transparent::default();
        write_123(&mut t, None);
        assert_eq!(from_bus(&mut t, &[1, 2, 3, 4]), (std::vec![4], Some(true)));
    }

    #[test]
    fn a_reply_that_starts_like_the_request_is_not_taken_for_an_echo() {
        let mut t = Transparent::default();
        write_123(&mut t, None);
        assert_eq!(from_bus(&mut t, &[1, 2, 9]), (std::vec![1, 2, 9], None));
    }

    #[test]
    fn a_silent_write_means_no_echo_and_releases_nothing() {
        let mut t = Transparent::default();
        write_123(&mut t, None);
        let mut bus = protocol_core::NullPort;
        let mut out = std::vec::Vec::new();
        t.poll(1_000, 1_000, &mut bus, None, |b| out.push(b));
        let learned = t.poll(1_000 + ECHO_GRACE_US, 1_000, &mut bus, None, |b| {
            out.push(b)
        });
        assert_eq!(learned, Some(false));
        assert!(out.is_empty());
    }
}
