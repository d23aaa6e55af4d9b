//! Transparent mode (0xC2 1): raw bytes both ways between the host and the bus, for tools that
//! talk to the servos directly.
//!
//! Three exact frames from the host are still the Basic's own, so a client can always find out
//! where it is and get back ([`Intercepted`]): `FE FE 03 C2 00 FA` (set mode 0: answered
//! `01`, back to framed mode), `FE FE 03 C2 01 FA` (set mode 1: answered `01`) and
//! `FE FE 02 C3 FA` (get mode: answered `01`). Host bytes that might be the start of one of
//! them are held back until they are known not to be (or the host goes quiet for
//! [`timing::HOST_FRAME_GAP_US`]), so these frames never reach the bus. Everything else is
//! copied: host bytes go onto the bus only into a free wire (as framed requests do), and every
//! bus byte goes to the host except the Basic's own echo, which the Basic's bus [`Listener`]
//! holds back and drops (or releases, if it was not one).

use heapless::{Deque, Vec};
use protocol_core::BytePort;
use protocol_core::listener::{Heard, Listener};
use protocol_core::timing;

use crate::forwarder::may_start_after_quiet;

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
/// Most bytes written to the bus at once (and so most echo bytes expected back; within the
/// listener's [`protocol_core::listener::ECHO_CAPACITY`]).
pub const BUS_WRITE_CHUNK: usize = 64;

/// The transparent pipe's state.
#[derive(Debug, Default)]
pub(crate) struct Transparent {
    /// Host bytes that match the start of an intercepted frame so far.
    held: Vec<u8, INTERCEPT_MAX>,
    to_bus: Deque<u8, TO_BUS_CAPACITY>,
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

    /// Takes one byte from the bus, heard through `listener`, and passes what is not the
    /// Basic's own echo to `emit` (bytes held as a possible echo come later, if they were not).
    pub(crate) fn bus_byte(
        now_us: u64,
        byte: u8,
        listener: &mut Listener,
        mut emit: impl FnMut(u8),
    ) {
        listener.push(now_us, byte, &mut |heard| {
            if let Heard::Byte(b) = heard {
                emit(b);
            }
        });
    }

    /// Lets time pass in `listener` (bytes held as an echo that did not come back whole go to
    /// `emit`) and writes queued host bytes onto the bus when the wire is free
    /// ([`may_start_after_quiet`]).
    pub(crate) fn poll<B: BytePort>(
        &mut self,
        now_us: u64,
        bus: &mut B,
        listener: &mut Listener,
        mut emit: impl FnMut(u8),
    ) {
        listener.on_time(now_us, &mut |heard| {
            if let Heard::Byte(b) = heard {
                emit(b);
            }
        });
        if self.to_bus.is_empty()
            || !bus.tx_idle()
            || !may_start_after_quiet(listener.quiet_us(now_us))
        {
            return;
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
        listener.on_transmit(now_us, &chunk);
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

    /// The Basic's bus listener.
    fn listener() -> Listener {
        crate::forwarder::bus_listener(crate::config::EchoMode::Auto)
    }

    /// Bytes from the bus, 10 us apart from 1 010 us (when the echo of a 3-byte write at
    /// 1 000 us comes back): what reached the host, and whether the Basic now knows its wiring
    /// echoes.
    fn from_bus(bus: &mut Listener, bytes: &[u8]) -> (std::vec::Vec<u8>, Option<bool>) {
        let mut out = std::vec::Vec::new();
        for (i, &b) in bytes.iter().enumerate() {
            Transparent::bus_byte(1_010 + 10 * i as u64, b, bus, |x| out.push(x));
        }
        (out, bus.echo_heard())
    }

    fn write_123(t: &mut Transparent, bus: &mut Listener) {
        for b in [1, 2, 3] {
            t.host_byte(b);
        }
        t.poll(1_000, &mut protocol_core::NullPort, bus, |_| {});
    }

    #[test]
    fn a_whole_echo_is_removed() {
        let (mut t, mut bus) = (Transparent::default(), listener());
        write_123(&mut t, &mut bus);
        assert_eq!(
            from_bus(&mut bus, &[1, 2, 3, 4]),
            (std::vec![4], Some(true))
        );
    }

    #[test]
    fn a_reply_that_starts_like_the_request_is_not_taken_for_an_echo() {
        let (mut t, mut bus) = (Transparent::default(), listener());
        write_123(&mut t, &mut bus);
        assert_eq!(from_bus(&mut bus, &[1, 2, 9]), (std::vec![1, 2, 9], None));
    }

    #[test]
    fn a_silent_write_means_no_echo_and_releases_nothing() {
        let (mut t, mut bus) = (Transparent::default(), listener());
        write_123(&mut t, &mut bus);
        let mut out = std::vec::Vec::new();
        t.poll(1_000, &mut protocol_core::NullPort, &mut bus, |b| {
            out.push(b)
        });
        t.poll(
            1_000 + timing::ECHO_GRACE_US,
            &mut protocol_core::NullPort,
            &mut bus,
            |b| out.push(b),
        );
        assert_eq!(bus.echo_heard(), Some(false));
        assert!(out.is_empty());
    }
}
