//! The receiving side of the shared bus: one byte stream carrying host frames (from the
//! Basic), servo status packets, and possibly the Atom's own transmissions read back.
//!
//! Whether the Atom hears its own echo depends on the board wiring (`hardware.md`), so the
//! receiver works both ways: every byte the Atom writes is remembered until it is heard back or
//! until its echo window closes. Incoming bytes that match the expected echo are held; a full
//! match is dropped as echo, a mismatch releases the held bytes to the decoders (the line had no
//! echo, or a collision garbled it).

use heapless::{Deque, Vec};
use protocol_core::servo::{Packet, PacketDecoder};
use protocol_core::timing::{BUS_BAUD, BUS_FRAME_GAP_US, wire_time_us};
use protocol_core::{Frame, FrameDecoder};

/// Longest transmission the echo filter tracks: a host reply frame (at most 33 bytes) or a
/// servo packet (at most 102 bytes). A longer write is only partly filtered.
const ECHO_CAPACITY: usize = protocol_core::servo::MAX_PACKET_BYTES;

/// Time after the last byte of a transmission within which its echo must have arrived: three
/// byte times at 1 Mbaud, covering the UART's receive latency.
const ECHO_GRACE_US: u64 = 30;

/// A servo packet in progress is dropped after this much silence: a servo sends its packet in
/// one go, so two byte times of silence mean it was cut short.
const PACKET_GAP_US: u64 = 40;

/// What the receiver found on the wire.
#[derive(Clone, Debug, PartialEq, Eq)]
pub enum BusEvent {
    /// A host frame (a request from the Basic).
    Frame(Frame),
    /// A servo packet with a valid checksum (a status reply).
    Packet(Packet),
}

/// Separates host frames, servo packets and the Atom's own echo on the shared bus.
#[derive(Clone, Debug, Default)]
pub struct BusReceiver {
    frames: FrameDecoder,
    packets: PacketDecoder,
    /// Bytes written and not heard back yet.
    expected_echo: Deque<u8, ECHO_CAPACITY>,
    /// Received bytes that matched the expected echo so far.
    held: Vec<u8, ECHO_CAPACITY>,
    /// When the current transmission's echo window closes.
    echo_deadline_us: u64,
    /// When the wire last carried a byte (heard or sent).
    last_activity_us: u64,
    /// Bytes dropped as own echo.
    echo_bytes: u32,
    /// True once a whole transmission came back as echo: the line echoes.
    line_echoes: bool,
    /// Set when, on a line that echoes, a transmission came back different (a collision).
    collided: bool,
}

impl BusReceiver {
    /// A receiver with nothing on the wire yet.
    pub fn new() -> Self {
        Self::default()
    }

    /// Records that `bytes` were written to the bus at `now_us` (their echo may follow).
    pub fn on_transmit(&mut self, now_us: u64, bytes: &[u8]) {
        let start = self.last_activity_us.max(now_us);
        let end = start + wire_time_us(bytes.len() as u32, BUS_BAUD);
        for &b in bytes {
            if self.expected_echo.push_back(b).is_err() {
                break;
            }
        }
        self.echo_deadline_us = end + ECHO_GRACE_US;
        self.last_activity_us = end;
    }

    /// Takes one received byte; calls `on_event` for each frame or packet it completes.
    pub fn push(&mut self, now_us: u64, byte: u8, on_event: &mut impl FnMut(BusEvent)) {
        self.last_activity_us = self.last_activity_us.max(now_us);
        if let Some(&expected) = self.expected_echo.front() {
            if expected == byte && self.held.push(byte).is_ok() {
                self.expected_echo.pop_front();
                if self.expected_echo.is_empty() {
                    self.echo_bytes = self.echo_bytes.wrapping_add(self.held.len() as u32);
                    self.held.clear();
                    self.line_echoes = true;
                }
                return;
            }
            // Not our echo: the line does not echo, or a collision changed it.
            if self.line_echoes {
                self.collided = true;
            }
            self.expected_echo.clear();
            self.release_held(on_event);
        }
        self.decode(byte, on_event);
    }

    /// Handles the passage of time: closes the echo window and drops packets or frames cut
    /// short by a quiet line. Call once per poll, after the received bytes.
    pub fn on_time(&mut self, now_us: u64, on_event: &mut impl FnMut(BusEvent)) {
        if now_us > self.echo_deadline_us && !self.expected_echo.is_empty() {
            // The echo never (fully) came: a line without echo (the bytes that matched so far
            // may be the start of a servo's answer, which begins like the instruction did), or
            // on a line that echoes, a transmission garbled beyond recognition.
            if self.line_echoes {
                self.collided = true;
            }
            self.expected_echo.clear();
            self.release_held(on_event);
        }
        let quiet_us = now_us.saturating_sub(self.last_activity_us);
        if quiet_us >= PACKET_GAP_US && self.packets.has_partial() {
            let mut next = self.packets.on_quiet_line();
            while let Some(p) = next {
                on_event(BusEvent::Packet(p));
                next = self.packets.next_packet();
            }
        }
        if quiet_us >= BUS_FRAME_GAP_US && self.frames.has_partial() {
            let mut next = self.frames.on_quiet_line();
            while let Some(f) = next {
                on_event(BusEvent::Frame(f));
                next = self.frames.next_frame();
            }
        }
    }

    /// True (once) if the last transmission collided: the line echoes and the echo differed or
    /// did not come back whole.
    pub fn take_collision(&mut self) -> bool {
        core::mem::take(&mut self.collided)
    }

    /// True while a host frame is arriving (its start seen, its end not yet).
    pub fn frame_in_progress(&self) -> bool {
        self.frames.has_partial()
    }

    /// Microseconds the wire has been silent at `now_us` (0 while the Atom is transmitting).
    pub fn quiet_us(&self, now_us: u64) -> u64 {
        now_us.saturating_sub(self.last_activity_us)
    }

    /// Number of received bytes recognised as the Atom's own echo. Wraps.
    pub fn echo_bytes(&self) -> u32 {
        self.echo_bytes
    }

    /// Number of servo packets dropped for a bad checksum. Wraps.
    pub fn checksum_errors(&self) -> u32 {
        self.packets.checksum_errors()
    }

    fn release_held(&mut self, on_event: &mut impl FnMut(BusEvent)) {
        let held = core::mem::take(&mut self.held);
        for &b in &held {
            self.decode(b, on_event);
        }
    }

    fn decode(&mut self, byte: u8, on_event: &mut impl FnMut(BusEvent)) {
        if let Some(f) = self.frames.push(byte) {
            on_event(BusEvent::Frame(f));
            while let Some(f) = self.frames.next_frame() {
                on_event(BusEvent::Frame(f));
            }
        }
        if let Some(p) = self.packets.push(byte) {
            on_event(BusEvent::Packet(p));
            while let Some(p) = self.packets.next_packet() {
                on_event(BusEvent::Packet(p));
            }
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use protocol_core::servo::Instruction;

    fn run(rx: &mut BusReceiver, t: u64, bytes: &[u8]) -> std::vec::Vec<BusEvent> {
        let mut out = std::vec::Vec::new();
        for (i, &b) in bytes.iter().enumerate() {
            rx.push(t + 10 * i as u64, b, &mut |e| out.push(e));
        }
        out
    }

    fn status(id: u8, data: &[u8]) -> Packet {
        Packet::new(id, 0, data).unwrap()
    }

    #[test]
    fn own_echo_is_dropped_and_replies_are_kept() {
        let mut rx = BusReceiver::new();
        let read = Instruction::Read { addr: 56, count: 2 }
            .to_packet(1)
            .unwrap();
        rx.on_transmit(0, &read.to_bytes());
        assert!(run(&mut rx, 10, &read.to_bytes()).is_empty());
        let reply = status(1, &[0x00, 0x08]);
        assert_eq!(
            run(&mut rx, 200, &reply.to_bytes()),
            [BusEvent::Packet(reply)]
        );
        assert_eq!(rx.echo_bytes(), 8);
    }

    #[test]
    fn line_without_echo_still_delivers_replies() {
        let mut rx = BusReceiver::new();
        let ping = Instruction::Ping.to_packet(1).unwrap();
        rx.on_transmit(0, &ping.to_bytes());
        // The reply shares the first bytes with the instruction (FF FF 01 02): they are held,
        // then released at the first difference.
        let reply = status(1, &[]);
        assert_eq!(
            run(&mut rx, 70, &reply.to_bytes()),
            [BusEvent::Packet(reply.clone())]
        );
        // After the echo window, nothing is held at all.
        rx.on_transmit(1000, &ping.to_bytes());
        rx.on_time(1200, &mut |_| {});
        assert_eq!(
            run(&mut rx, 1200, &reply.to_bytes()),
            [BusEvent::Packet(reply)]
        );
    }

    #[test]
    fn own_reply_frame_is_not_taken_for_a_request() {
        let mut rx = BusReceiver::new();
        let reply = Frame::new(0x1A, &[1]).unwrap();
        rx.on_transmit(0, &reply.to_bytes());
        assert!(run(&mut rx, 0, &reply.to_bytes()).is_empty());
        let request = Frame::new(0x20, &[]).unwrap();
        assert_eq!(
            run(&mut rx, 500, &request.to_bytes()),
            [BusEvent::Frame(request)]
        );
    }

    #[test]
    fn collision_is_reported_on_a_line_that_echoes() {
        let mut rx = BusReceiver::new();
        let reply = Frame::new(0x20, &[0; 12]).unwrap().to_bytes();
        rx.on_transmit(0, &reply);
        run(&mut rx, 10, &reply);
        assert!(!rx.take_collision());
        rx.on_transmit(1000, &reply);
        let mut garbled = reply.clone();
        garbled[6] ^= 0x10;
        run(&mut rx, 1010, &garbled);
        assert!(rx.take_collision());
        assert!(!rx.take_collision(), "reported once");
    }

    #[test]
    fn truncated_frame_is_dropped_after_a_quiet_gap() {
        let mut rx = BusReceiver::new();
        assert!(run(&mut rx, 0, &[0xFE, 0xFE, 0x0F, 0x22]).is_empty());
        assert!(rx.frame_in_progress());
        rx.on_time(30 + BUS_FRAME_GAP_US, &mut |_| {});
        assert!(!rx.frame_in_progress());
        let request = Frame::new(0x20, &[]).unwrap();
        assert_eq!(
            run(&mut rx, 1000, &request.to_bytes()),
            [BusEvent::Frame(request)]
        );
    }
}
