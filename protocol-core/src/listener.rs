//! The one timed listener every station hears a wire through: received bytes with their time
//! and the station's own transmissions in; host frames, servo packets, raw bytes and a verdict
//! on each transmission's echo out.
//!
//! The Atom and the Basic hear the shared bus with it, the Basic also its host link, and the
//! simulated servos the bus. What differs between them is a [`ListenerConfig`]: which decoders
//! run, how long a silence cuts a frame or a packet short, and whether the station hears its
//! own bytes ([`EchoMode`]).
//!
//! * **Quiet line.** A sender writes a frame or packet in one go, so a partial one followed by
//!   silence was cut short: [`Listener::on_time`] drops it once the line has been quiet for the
//!   frame gap (`BUS_FRAME_GAP_US` on the bus, `HOST_FRAME_GAP_US` on a host link) or the
//!   packet gap ([`BUS_PACKET_GAP_US`]), and anything complete found inside it comes out.
//!   Only `on_time` applies the gaps: a station that reads the bytes of one poll late stamps
//!   them late, and that must not look like a silence before them.
//! * **Own echo.** Whether a station hears its own transmissions depends on the wiring. Every
//!   byte it sends ([`Listener::on_transmit`]) is expected back until the echo window closes
//!   ([`ECHO_GRACE_US`] after the transmission's end). Received bytes that match the expected
//!   echo are held back: a whole match is dropped as echo; at the first difference, or when the
//!   window closes first, the held bytes are released to the decoders in order (the line did
//!   not echo and they were another station's, or a collision changed them). Each
//!   transmission gets one [`Echo`] verdict, which is what the Basic decides retransmissions
//!   on, and a collision on a line known to echo is also kept for [`Listener::take_collision`].
//!   On a line that does not echo, a byte read after the window is over closes it first: an
//!   answer that repeats the transmission byte for byte, read late, is the answer.
//!
//! * **Where a byte belongs.** The listener counts the bytes it decodes, so it knows where every
//!   frame, packet and candidate lies in the stream. A host frame that completes inside a
//!   servo packet still arriving (its header and LEN already heard, its end not yet) is held
//!   until that packet resolves: a valid packet around it means it was the servo's data and it
//!   is dropped; a packet that fails its checksum or is cut short releases it, in order. A
//!   frame candidate that started inside a valid packet is dropped up to the packet's end, and
//!   only that: a frame starting after the packet is kept, however late the packet was found
//!   (a false packet candidate before it can delay the real packet by its whole length).
//!
//! Zero allocation, bounded buffers, never panics on any input or any timing (time may even
//! go backwards: every difference saturates).

use heapless::Vec;

use crate::frame::{Frame, FrameDecoder, MAX_FRAME_BYTES, MIN_FRAME_BYTES};
use crate::servo::{MAX_PACKET_BYTES, Packet, PacketDecoder};
use crate::timing::{BUS_BAUD, BUS_FRAME_GAP_US, BUS_PACKET_GAP_US, ECHO_GRACE_US, wire_time_us};

/// Longest transmission whose echo is tracked, in bytes: the longest servo packet or host
/// frame. Of a longer transmission only the first this many bytes are recognised as echo.
pub const ECHO_CAPACITY: usize = if MAX_PACKET_BYTES > MAX_FRAME_BYTES {
    MAX_PACKET_BYTES
} else {
    MAX_FRAME_BYTES
};

/// Most host frames that can lie inside one servo packet, each held until the packet resolves.
const HELD_FRAMES: usize = MAX_PACKET_BYTES / MIN_FRAME_BYTES;

/// A complete host frame that may be a servo packet's data, and where it lies in the stream.
#[derive(Clone, Debug)]
struct HeldFrame {
    /// Stream position of its first byte.
    start: u64,
    /// Stream position after its last byte.
    end: u64,
    frame: Frame,
}

/// Whether a station hears its own transmissions (TX and RX tied on the wire). The wiring of
/// the myCobot's boards is not documented, so the default finds out.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub enum EchoMode {
    /// Decide from what comes back: once a whole echo has been heard, a missing or different
    /// one is a collision; until then a transmission that comes back silent counts as sent
    /// (and the line as one without echo).
    #[default]
    Auto,
    /// Every transmitted byte comes back; a missing or different echo is a collision.
    Present,
    /// Nothing transmitted comes back; any byte heard while transmitting is a collision.
    Absent,
}

/// What a [`Listener`] decodes and when it calls a line quiet. `Default` is a station on the
/// shared bus: host frames and servo packets, the bus gaps, echo found out.
///
/// Built like an esp-hal config: start from [`ListenerConfig::new`] (or `default()`) and change
/// what differs with the `with_*` methods, which are `const`.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct ListenerConfig {
    frames: bool,
    packets: bool,
    bytes: bool,
    frame_gap_us: u64,
    packet_gap_us: u64,
    echo: EchoMode,
}

impl ListenerConfig {
    /// A station on the shared bus: decodes host frames and servo packets, no raw bytes, frame
    /// gap [`BUS_FRAME_GAP_US`], packet gap [`BUS_PACKET_GAP_US`], [`EchoMode::Auto`].
    pub const fn new() -> Self {
        Self {
            frames: true,
            packets: true,
            bytes: false,
            frame_gap_us: BUS_FRAME_GAP_US,
            packet_gap_us: BUS_PACKET_GAP_US,
            echo: EchoMode::Auto,
        }
    }

    /// Whether host frames (`FE FE LEN CMD DATA FA`) are decoded ([`Heard::Frame`]).
    pub const fn with_frames(mut self, on: bool) -> Self {
        self.frames = on;
        self
    }

    /// Whether servo packets with a valid checksum are decoded ([`Heard::Packet`]).
    pub const fn with_packets(mut self, on: bool) -> Self {
        self.packets = on;
        self
    }

    /// Whether every received byte that is not the station's own echo is also given out as it
    /// is ([`Heard::Byte`]), before the frames and packets it completes.
    pub const fn with_bytes(mut self, on: bool) -> Self {
        self.bytes = on;
        self
    }

    /// Silence after which a partial host frame was cut short, in microseconds:
    /// `timing::BUS_FRAME_GAP_US` on the bus, `timing::HOST_FRAME_GAP_US` on a host link.
    pub const fn with_frame_gap_us(mut self, gap_us: u64) -> Self {
        self.frame_gap_us = gap_us;
        self
    }

    /// Silence after which a partial servo packet was cut short, in microseconds.
    pub const fn with_packet_gap_us(mut self, gap_us: u64) -> Self {
        self.packet_gap_us = gap_us;
        self
    }

    /// Whether the station hears its own transmissions.
    pub const fn with_echo(mut self, echo: EchoMode) -> Self {
        self.echo = echo;
        self
    }
}

impl Default for ListenerConfig {
    fn default() -> Self {
        Self::new()
    }
}

/// What happened to the echo of one transmission (or of transmissions written back to back
/// before the first one's verdict).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Echo {
    /// Every byte came back unchanged and was dropped: the line echoes.
    Whole,
    /// A byte came back different, or, with [`EchoMode::Absent`], another station's byte was
    /// heard while transmitting: a collision (or, on a line not known to echo, an answer that
    /// began before the transmission was over). The bytes held as echo so far are released.
    Differed,
    /// Part of the echo came back and the rest never did, or, on a line known to echo, none of
    /// it, within [`ECHO_GRACE_US`] of the transmission's end. What was held is released.
    Missing,
    /// Nothing came back and nothing had to: [`EchoMode::Absent`], or a line not known to echo
    /// (which [`EchoMode::Auto`] now knows does not). Given once the transmission has ended and
    /// [`ECHO_GRACE_US`] has passed since its start (an echo starts while the transmission is
    /// still going out).
    Silent,
}

/// What a [`Listener`] found on its line, in the order it happened.
#[derive(Clone, Debug, PartialEq, Eq)]
pub enum Heard {
    /// A complete host frame.
    Frame(Frame),
    /// A complete servo packet with a valid checksum.
    Packet(Packet),
    /// A received byte that is not the station's own echo (with
    /// [`ListenerConfig::with_bytes`]).
    Byte(u8),
    /// The verdict on the station's last transmission; bytes it releases follow it.
    Echo(Echo),
}

/// The transmission whose echo is awaited.
#[derive(Clone, Copy, Debug)]
struct Window {
    /// When its first byte started on the wire, in microseconds.
    start_us: u64,
    /// When its last byte ends on the wire, in microseconds.
    end_us: u64,
}

/// A station's ears on one line. See the [module doc](self).
#[derive(Clone, Debug)]
pub struct Listener {
    config: ListenerConfig,
    frames: FrameDecoder,
    packets: PacketDecoder,
    /// The transmission awaiting its verdict, if any.
    window: Option<Window>,
    /// Its bytes (as many as fit)...
    sent: Vec<u8, ECHO_CAPACITY>,
    /// ...and how many of them have come back so far: `sent[..echoed]` is held back.
    echoed: usize,
    /// When the line last carried a byte, heard or sent (the end of a transmission still going
    /// out is in the future), in microseconds.
    last_activity_us: u64,
    /// What the echo has shown so far: heard whole once, or found absent ([`EchoMode::Auto`]).
    echo_heard: Option<bool>,
    /// A transmission differed or went missing on a line known to echo, not yet taken.
    collided: bool,
    /// Received bytes dropped as own echo. Wraps.
    echo_bytes: u32,
    /// Bytes the frame decoder and the packet decoder have taken so far: the stream position
    /// after the last byte each has seen (they differ while a byte is between them).
    frames_fed: u64,
    packets_fed: u64,
    /// Complete frames inside a servo packet candidate, in stream order, until it resolves.
    held: Vec<HeldFrame, HELD_FRAMES>,
}

impl Default for Listener {
    fn default() -> Self {
        Self::new(ListenerConfig::new())
    }
}

impl Listener {
    /// A listener that has heard nothing yet.
    pub const fn new(config: ListenerConfig) -> Self {
        Self {
            config,
            frames: FrameDecoder::new(),
            packets: PacketDecoder::new(),
            window: None,
            sent: Vec::new(),
            echoed: 0,
            last_activity_us: 0,
            echo_heard: None,
            collided: false,
            echo_bytes: 0,
            frames_fed: 0,
            packets_fed: 0,
            held: Vec::new(),
        }
    }

    /// Records that the station wrote `bytes` to the line at `now_us` (after whatever it wrote
    /// before, if that is still going out); their echo may follow. Assumes the bus baud rate.
    pub fn on_transmit(&mut self, now_us: u64, bytes: &[u8]) {
        if bytes.is_empty() {
            return;
        }
        let start_us = self.last_activity_us.max(now_us);
        let len = u32::try_from(bytes.len()).unwrap_or(u32::MAX);
        let end_us = start_us.saturating_add(wire_time_us(len, BUS_BAUD));
        self.last_activity_us = end_us;
        let start_us = self.window.map_or(start_us, |w| w.start_us);
        self.window = Some(Window { start_us, end_us });
        if self.config.echo != EchoMode::Absent {
            let room = self.sent.capacity() - self.sent.len();
            // Cannot fail: at most `room` bytes.
            let _ = self
                .sent
                .extend_from_slice(bytes.get(..room.min(bytes.len())).unwrap_or_default());
        }
    }

    /// Takes one byte received at `now_us`; calls `on_heard` with everything it completes or
    /// releases, in order.
    pub fn push(&mut self, now_us: u64, byte: u8, on_heard: &mut impl FnMut(Heard)) {
        self.release_uncovered(on_heard);
        self.last_activity_us = self.last_activity_us.max(now_us);
        if self.window.is_some() && self.late_bytes_are_foreign() {
            // Read after the window is over (the station polled late): not the echo, even
            // if it repeats what was sent (FE FE 03 EA 01 FA answers a backup of servo 1).
            self.judge_echo(now_us, on_heard);
        }
        if self.window.is_some() {
            if self.config.echo != EchoMode::Absent && self.sent.get(self.echoed) == Some(&byte) {
                self.echoed += 1;
                if self.echoed >= self.sent.len() {
                    // Cannot wrap: echoed <= ECHO_CAPACITY.
                    self.echo_bytes = self.echo_bytes.wrapping_add(self.echoed as u32);
                    self.sent.clear();
                    self.echoed = 0;
                    self.window = None;
                    self.echo_heard = Some(true);
                    on_heard(Heard::Echo(Echo::Whole));
                }
                return;
            }
            self.close_window(Echo::Differed, on_heard);
        }
        self.decode(byte, on_heard);
    }

    /// Lets time pass up to `now_us`: closes an echo window that is over and drops frames and
    /// packets cut short by a quiet line, calling `on_heard` with what that gives out. Call it
    /// once per poll, after the bytes received in that poll.
    #[inline]
    pub fn on_time(&mut self, now_us: u64, on_heard: &mut impl FnMut(Heard)) {
        // Most polls find nothing to do: keep those to a few loads.
        if self.window.is_some() {
            self.judge_echo(now_us, on_heard);
        }
        if self.frames.has_partial() || self.packets.has_partial() {
            self.cut_short(now_us, on_heard);
        }
        if !self.held.is_empty() {
            self.release_uncovered(on_heard);
        }
    }

    /// Reads host frames' LEN as `lengths` says from the next frame on (a host link's
    /// dialect: [`crate::dialect::Dialect::frame_lengths`]).
    pub fn set_frame_lengths(&mut self, lengths: crate::frame::FrameLengths) {
        self.frames.set_lengths(lengths);
    }

    /// Forgets every frame and packet in progress, and whatever complete one a rescan would
    /// find inside them: for a station that knows the line is quiet before it transmits (a
    /// partial candidate must not swallow the answer), or that changes what the line means.
    pub fn drop_partials(&mut self) {
        let mut next = self.frames.on_quiet_line();
        while next.is_some() {
            next = self.frames.next_frame();
        }
        let mut next = self.packets.on_quiet_line();
        while next.is_some() {
            next = self.packets.next_packet();
        }
    }

    /// Counts the line as busy until `now_us`, as if a byte had been heard then: at boot its
    /// history is unknown, so it gets a quiet time first.
    pub fn assume_busy_until(&mut self, now_us: u64) {
        self.last_activity_us = self.last_activity_us.max(now_us);
    }

    /// True (once) if a transmission collided on a line known to echo: its echo differed or
    /// did not come back whole.
    pub fn take_collision(&mut self) -> bool {
        core::mem::take(&mut self.collided)
    }

    /// True while a host frame is arriving (its start heard, its end not yet), or a complete
    /// one waits for the servo packet around it to resolve.
    pub fn frame_in_progress(&self) -> bool {
        self.frames.has_partial() || !self.held.is_empty()
    }

    /// The host frame candidate being heard: the stream position of its first byte (counting
    /// every byte the frame decoder has taken) and its bytes so far (from its first `FE`);
    /// empty bytes when none is in progress. The position tells one candidate from the next:
    /// a candidate dropped (cut short, or not a frame) and another begun shows a new position.
    pub fn frame_partial(&self) -> (u64, &[u8]) {
        (self.frames_front(), self.frames.partial())
    }

    /// How many bytes the frame decoder has taken so far: the stream position the next byte
    /// given out as [`Heard::Byte`] will have (each such byte is then taken by it, in order).
    pub fn frames_heard(&self) -> u64 {
        self.frames_fed
    }

    /// True while part of the open transmission's echo has come back: the line echoes, even if
    /// [`EchoMode::Auto`] has not judged a whole echo yet.
    pub fn echo_coming_back(&self) -> bool {
        self.window.is_some() && self.echoed > 0
    }

    /// True while a transmission's echo verdict is still to come.
    pub fn echo_pending(&self) -> bool {
        self.window.is_some()
    }

    /// Whether the station hears its own transmissions, as far as shown so far: `Some(true)`
    /// once a whole echo came back, `Some(false)` once a transmission came back silent with
    /// [`EchoMode::Auto`], `None` before.
    pub fn echo_heard(&self) -> Option<bool> {
        self.echo_heard
    }

    /// Microseconds the line has been silent at `now_us`; 0 while the station's own
    /// transmission is still going out.
    pub fn quiet_us(&self, now_us: u64) -> u64 {
        now_us.saturating_sub(self.last_activity_us)
    }

    /// When the line was last busy, in us: the end of the last byte heard, or of what the
    /// station wrote (later than now while its bytes are still going out).
    pub fn busy_until_us(&self) -> u64 {
        self.last_activity_us
    }

    /// Received bytes recognised as the station's own echo and dropped. Wraps.
    pub fn echo_bytes(&self) -> u32 {
        self.echo_bytes
    }

    /// Servo packets dropped for a bad checksum. Wraps.
    pub fn checksum_errors(&self) -> u32 {
        self.packets.checksum_errors()
    }

    /// Whether the echo must come back whole for a transmission to count as sent intact: the
    /// line is known to echo ([`EchoMode::Present`], or [`EchoMode::Auto`] once a whole echo
    /// came back). Only then does a differing echo prove a collision; on another line, a byte
    /// heard while transmitting may as well be an answer (or a late one) to an intact frame.
    pub fn echo_required(&self) -> bool {
        match self.config.echo {
            EchoMode::Present => true,
            EchoMode::Absent => false,
            EchoMode::Auto => self.echo_heard == Some(true),
        }
    }

    /// True if a byte read after the echo window is over cannot be the echo: the line does not
    /// echo ([`EchoMode::Absent`], or [`EchoMode::Auto`] once a transmission came back
    /// silent). Where it echoes, or is not known yet, such a byte may be an echo the station
    /// read late, and is matched as one.
    fn late_bytes_are_foreign(&self) -> bool {
        match self.config.echo {
            EchoMode::Absent => true,
            EchoMode::Auto => self.echo_heard == Some(false),
            EchoMode::Present => false,
        }
    }

    /// Gives the open transmission its verdict once its echo window is over.
    fn judge_echo(&mut self, now_us: u64, on_heard: &mut impl FnMut(Heard)) {
        let Some(window) = self.window else {
            return;
        };
        let ended = now_us >= window.end_us;
        let verdict = if self.config.echo == EchoMode::Absent {
            ended.then_some(Echo::Silent)
        } else if self.echoed == 0
            && !self.echo_required()
            && ended
            && now_us >= window.start_us.saturating_add(ECHO_GRACE_US)
        {
            Some(Echo::Silent)
        } else if now_us >= window.end_us.saturating_add(ECHO_GRACE_US) {
            Some(Echo::Missing)
        } else {
            None
        };
        if let Some(verdict) = verdict {
            self.close_window(verdict, on_heard);
        }
    }

    /// Drops the frames and packets in progress that a quiet line has cut short.
    fn cut_short(&mut self, now_us: u64, on_heard: &mut impl FnMut(Heard)) {
        let quiet_us = self.quiet_us(now_us);
        if self.config.packets
            && quiet_us >= self.config.packet_gap_us
            && self.packets.has_partial()
        {
            let next = self.packets.on_quiet_line();
            self.found_packets(next, on_heard);
        }
        if self.config.frames && quiet_us >= self.config.frame_gap_us && self.frames.has_partial() {
            let next = self.frames.on_quiet_line();
            self.found_frames(next, on_heard);
        }
    }

    /// Gives the open transmission its verdict and releases the bytes held as its echo.
    fn close_window(&mut self, verdict: Echo, on_heard: &mut impl FnMut(Heard)) {
        match verdict {
            Echo::Differed | Echo::Missing if self.echo_required() => self.collided = true,
            Echo::Silent if self.config.echo == EchoMode::Auto => self.echo_heard = Some(false),
            _ => {}
        }
        self.window = None;
        let sent = core::mem::take(&mut self.sent);
        let held = core::mem::take(&mut self.echoed);
        on_heard(Heard::Echo(verdict));
        for &byte in sent.get(..held).unwrap_or_default() {
            self.decode(byte, on_heard);
        }
    }

    /// Passes a byte that is not own echo to the decoders that are on: the frame decoder
    /// first, so that a packet ending on the same byte finds the frame it contains.
    fn decode(&mut self, byte: u8, on_heard: &mut impl FnMut(Heard)) {
        if self.config.bytes {
            on_heard(Heard::Byte(byte));
        }
        if self.config.frames {
            self.frames_fed = self.frames_fed.wrapping_add(1);
            let next = self.frames.push(byte);
            self.found_frames(next, on_heard);
        }
        if self.config.packets {
            self.packets_fed = self.packets_fed.wrapping_add(1);
            let next = self.packets.push(byte);
            self.found_packets(next, on_heard);
        }
        self.release_uncovered(on_heard);
    }

    /// Stream position of the first byte the packet decoder holds.
    fn packets_front(&self) -> u64 {
        self.packets_fed.wrapping_sub(self.packets.held() as u64)
    }

    /// Stream position of the first byte the frame decoder holds.
    fn frames_front(&self) -> u64 {
        self.frames_fed.wrapping_sub(self.frames.held() as u64)
    }

    /// Gives out `first` and the packets after it; each one's bytes are no host frame.
    fn found_packets(&mut self, first: Option<Packet>, on_heard: &mut impl FnMut(Heard)) {
        let mut next = first;
        while let Some(packet) = next {
            let end = self.packets_front();
            let start = end.wrapping_sub(packet.encoded_len() as u64);
            // Frames held inside it were its data; those before it come out first.
            while let Some(first) = self.held.first() {
                if first.start >= start && first.end <= end {
                    self.held.remove(0);
                } else if first.start < start {
                    self.release_first(on_heard);
                } else {
                    break;
                }
            }
            on_heard(Heard::Packet(packet));
            // A frame candidate starting inside the packet is dropped up to the packet's end;
            // what follows the packet is scanned again.
            let frame_front = self.frames_front();
            if self.config.frames && frame_front >= start && frame_front < end {
                // end - frame_front <= a packet's length.
                self.frames.discard((end - frame_front) as usize);
                let next = self.frames.next_frame();
                self.found_frames(next, on_heard);
            }
            next = self.packets.next_packet();
        }
    }

    /// Gives out `first` and the frames after it, or holds each one that a servo packet
    /// candidate still arriving may contain.
    fn found_frames(&mut self, first: Option<Frame>, on_heard: &mut impl FnMut(Heard)) {
        let mut next = first;
        while let Some(frame) = next {
            let end = self.frames_front();
            let start = end.wrapping_sub(frame.encoded_len() as u64);
            let held = HeldFrame { start, end, frame };
            if self.packet_may_contain(&held) || !self.held.is_empty() {
                if let Err(held) = self.held.push(held) {
                    // Cannot happen (a packet holds at most HELD_FRAMES frames); never lose
                    // one: the oldest comes out.
                    self.release_first(on_heard);
                    let _ = self.held.push(held);
                }
            } else {
                self.give_frame(held, on_heard);
            }
            next = self.frames.next_frame();
        }
    }

    /// Gives out the held frames that no servo packet candidate may contain any more, in order.
    fn release_uncovered(&mut self, on_heard: &mut impl FnMut(Heard)) {
        while let Some(first) = self.held.first() {
            if self.packet_may_contain(first) {
                return;
            }
            self.release_first(on_heard);
        }
    }

    /// True if the servo packet candidate in progress started before `frame`: the frame may
    /// be that packet's data.
    fn packet_may_contain(&self, frame: &HeldFrame) -> bool {
        self.packets.has_partial() && self.packets_front() < frame.start
    }

    /// Gives out the oldest held frame.
    fn release_first(&mut self, on_heard: &mut impl FnMut(Heard)) {
        if !self.held.is_empty() {
            let held = self.held.remove(0);
            self.give_frame(held, on_heard);
        }
    }

    /// Gives out a frame that is no servo packet's data. A packet candidate that started
    /// inside it was the frame's data, not a packet: dropped up to the frame's end.
    fn give_frame(&mut self, frame: HeldFrame, on_heard: &mut impl FnMut(Heard)) {
        on_heard(Heard::Frame(frame.frame));
        let front = self.packets_front();
        if self.packets.has_partial() && front > frame.start && front < frame.end {
            // frame.end - front < a frame's length.
            self.packets.discard((frame.end - front) as usize);
            let next = self.packets.next_packet();
            self.found_packets(next, on_heard);
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::servo::Instruction;
    use crate::timing::HOST_FRAME_GAP_US;

    /// Bytes arriving back to back at 1 Mbaud from `t_us`, each pushed when it ends.
    fn run(rx: &mut Listener, t_us: u64, bytes: &[u8]) -> std::vec::Vec<Heard> {
        let mut out = std::vec::Vec::new();
        for (i, &b) in bytes.iter().enumerate() {
            rx.push(t_us + 10 * i as u64, b, &mut |h| out.push(h));
        }
        out
    }

    fn tick(rx: &mut Listener, now_us: u64) -> std::vec::Vec<Heard> {
        let mut out = std::vec::Vec::new();
        rx.on_time(now_us, &mut |h| out.push(h));
        out
    }

    fn status(id: u8, data: &[u8]) -> Packet {
        Packet::new(id, 0, data).unwrap()
    }

    fn frame(cmd: u8, data: &[u8]) -> Frame {
        Frame::new(cmd, data).unwrap()
    }

    #[test]
    fn the_frame_being_heard_is_seen_with_its_place_in_the_stream() {
        let mut rx = Listener::new(ListenerConfig::new().with_packets(false).with_bytes(true));
        assert_eq!(rx.frame_partial(), (0, &[][..]));
        run(&mut rx, 0, &[0x11, 0xFE, 0xFE, 0x03]);
        assert_eq!(rx.frames_heard(), 4);
        assert_eq!(rx.frame_partial(), (1, &[0xFE, 0xFE, 0x03][..]));
        // Its footer is wrong: dropped, and the rescan finds nothing in it.
        run(&mut rx, 100, &[0x20, 0x01, 0x00]);
        assert_eq!(rx.frame_partial().1, &[][..]);
        // The next one is another candidate, at another place.
        run(&mut rx, 200, &[0xFE, 0xFE]);
        assert_eq!(rx.frame_partial(), (7, &[0xFE, 0xFE][..]));
        // Cut short by a quiet line.
        tick(&mut rx, 250 + BUS_FRAME_GAP_US);
        assert_eq!(rx.frame_partial().1, &[][..]);
        assert_eq!(rx.frames_heard(), 9);
    }

    fn heard_frames(heard: &[Heard]) -> std::vec::Vec<Frame> {
        heard
            .iter()
            .filter_map(|h| match h {
                Heard::Frame(f) => Some(f.clone()),
                _ => None,
            })
            .collect()
    }

    #[test]
    fn a_servo_reply_ending_in_fe_leaves_no_frame_in_progress() {
        // One reply in 256 has the checksum FE, the first byte of a host frame: the station
        // must not wait for the frame gap before its next transaction.
        let reply = (0..=255u8)
            .map(|load| status(1, &[0x00, 0x08, load, 0x00]))
            .find(|p| p.to_bytes().last() == Some(&0xFE))
            .unwrap();
        let mut rx = Listener::default();
        assert_eq!(run(&mut rx, 0, &reply.to_bytes()), [Heard::Packet(reply)]);
        assert!(!rx.frame_in_progress());
        // A host frame right after it is still heard whole.
        let request = frame(0x20, &[]);
        let heard = run(&mut rx, 200, &request.to_bytes());
        assert_eq!(heard_frames(&heard), [request]);
    }

    #[test]
    fn a_frame_after_a_late_found_packet_is_kept() {
        // The shrunk case of `own_echo_never_comes_out_on_a_line_that_echoes`: a host frame
        // whose data looks like the start of a servo packet (FF FF 00 LEN), a real packet, then
        // a host frame. The false candidate holds the real packet back until its checksum
        // fails, so the packet is found while the last frame is already arriving: that frame
        // started after the packet and must come out.
        let first = frame(0x20, &[0xFF, 0xFF, 0x00, 0x0A]);
        let reply = status(1, &[0x00, 0x08]);
        let last = frame(0x2B, &[]);
        let mut rx = Listener::default();
        let mut heard = run(&mut rx, 0, &first.to_bytes());
        heard.extend(run(&mut rx, 500, &reply.to_bytes()));
        heard.extend(run(&mut rx, 1_000, &last.to_bytes()));
        assert_eq!(heard_frames(&heard), [first, last], "{heard:?}");
        assert!(heard.contains(&Heard::Packet(reply)));
        assert!(!rx.frame_in_progress());
    }

    #[test]
    fn a_host_frame_inside_a_servo_reply_is_not_a_request() {
        // A servo's answer to a long read whose data happens to hold a whole host frame.
        let fake = frame(0x29, &[]).to_bytes();
        let mut data = [0x11u8; 12];
        data[3..3 + fake.len()].copy_from_slice(&fake);
        let reply = status(3, &data);
        let mut rx = Listener::default();
        let heard = run(&mut rx, 0, &reply.to_bytes());
        assert_eq!(heard, [Heard::Packet(reply)]);
        assert!(!rx.frame_in_progress());
        // Ending on the packet's last byte too.
        let mut data = [0x11u8; 8];
        let tail = frame(0x29, &[]).to_bytes();
        data[8 - 4..].copy_from_slice(&tail[..4]);
        let packet = status(3, &data).to_bytes();
        assert!(heard_frames(&run(&mut rx, 500, &packet)).is_empty());
    }

    #[test]
    fn a_host_frame_after_a_false_packet_start_comes_out_once_the_packet_fails() {
        // FF FF 01 10 promises 16 more bytes; a host frame arrives inside them. It is held
        // until the false packet's checksum fails, then comes out.
        let request = frame(0x20, &[]);
        let mut bytes = std::vec![0xFF, 0xFF, 0x01, 0x10];
        bytes.extend_from_slice(&request.to_bytes());
        let mut rx = Listener::default();
        let heard = run(&mut rx, 0, &bytes);
        assert!(
            heard_frames(&heard).is_empty(),
            "held while it may be packet data"
        );
        assert!(rx.frame_in_progress());
        let heard = run(&mut rx, 200, &[0u8; 12]);
        assert_eq!(heard_frames(&heard), std::slice::from_ref(&request));
        // Or once the line goes quiet and the packet is cut short.
        let mut rx = Listener::default();
        run(&mut rx, 0, &bytes);
        let heard = tick(&mut rx, 90 + BUS_FRAME_GAP_US + BUS_PACKET_GAP_US);
        assert_eq!(heard_frames(&heard), [request]);
    }

    #[test]
    fn own_echo_is_dropped_and_replies_are_kept() {
        let mut rx = Listener::default();
        let read = Instruction::Read { addr: 56, count: 2 }
            .to_packet(1)
            .unwrap();
        rx.on_transmit(0, &read.to_bytes());
        assert_eq!(
            run(&mut rx, 10, &read.to_bytes()),
            [Heard::Echo(Echo::Whole)]
        );
        let reply = status(1, &[0x00, 0x08]);
        assert_eq!(run(&mut rx, 200, &reply.to_bytes()), [Heard::Packet(reply)]);
        assert_eq!(rx.echo_bytes(), 8);
        assert_eq!(rx.echo_heard(), Some(true));
    }

    #[test]
    fn line_without_echo_still_delivers_replies() {
        let mut rx = Listener::default();
        let ping = Instruction::Ping.to_packet(1).unwrap();
        rx.on_transmit(0, &ping.to_bytes());
        // The reply shares the first bytes with the instruction (FF FF 01 02): they are held,
        // then released at the first difference.
        let reply = status(1, &[]);
        assert_eq!(
            run(&mut rx, 70, &reply.to_bytes()),
            [Heard::Echo(Echo::Differed), Heard::Packet(reply.clone())]
        );
        // After the echo window, nothing is held at all.
        rx.on_transmit(1000, &ping.to_bytes());
        assert_eq!(tick(&mut rx, 1200), [Heard::Echo(Echo::Silent)]);
        assert_eq!(rx.echo_heard(), Some(false));
        assert_eq!(
            run(&mut rx, 1200, &reply.to_bytes()),
            [Heard::Packet(reply)]
        );
        assert!(
            !rx.take_collision(),
            "nothing to collide with on a silent line"
        );
    }

    #[test]
    fn an_answer_that_repeats_the_request_is_not_its_echo_when_read_late() {
        // Seen on the emulated C3 Basic: its loop stood still from its request's end to the
        // Atom's answer, identical to the request; with the window still open at the read, the
        // answer was dropped as the echo and the client never got it.
        let backup = frame(0xEA, &[1]).to_bytes();
        for config in [
            ListenerConfig::new(),
            ListenerConfig::new().with_echo(EchoMode::Absent),
        ] {
            let mut rx = Listener::new(config);
            // Auto has learnt that the line does not echo.
            rx.on_transmit(0, &backup);
            tick(&mut rx, 1_000);
            rx.on_transmit(10_000, &backup);
            let heard = run(&mut rx, 13_000, &backup);
            assert_eq!(
                heard,
                [Heard::Echo(Echo::Silent), Heard::Frame(frame(0xEA, &[1]))]
            );
            assert!(!rx.take_collision());
        }
        // Where the line echoes, or is not known yet, the same late read is the echo.
        for known_echo in [false, true] {
            let mut rx = Listener::default();
            if known_echo {
                rx.on_transmit(0, &backup);
                run(&mut rx, 10, &backup);
            }
            rx.on_transmit(10_000, &backup);
            assert_eq!(run(&mut rx, 13_000, &backup), [Heard::Echo(Echo::Whole)]);
        }
    }

    #[test]
    fn own_reply_frame_is_not_taken_for_a_request() {
        let mut rx = Listener::default();
        let reply = frame(0x1A, &[1]);
        rx.on_transmit(0, &reply.to_bytes());
        assert!(heard_frames(&run(&mut rx, 0, &reply.to_bytes())).is_empty());
        let request = frame(0x20, &[]);
        assert_eq!(
            run(&mut rx, 500, &request.to_bytes()),
            [Heard::Frame(request)]
        );
    }

    #[test]
    fn collision_is_reported_on_a_line_that_echoes() {
        let mut rx = Listener::default();
        let reply = frame(0x20, &[0; 12]).to_bytes();
        rx.on_transmit(0, &reply);
        run(&mut rx, 10, &reply);
        assert!(!rx.take_collision());
        rx.on_transmit(1000, &reply);
        let mut garbled = reply.clone();
        garbled[6] ^= 0x10;
        let heard = run(&mut rx, 1010, &garbled);
        assert_eq!(heard.first(), Some(&Heard::Echo(Echo::Differed)));
        assert!(rx.take_collision());
        assert!(!rx.take_collision(), "reported once");
    }

    #[test]
    fn an_echo_that_stops_halfway_is_missing_once_the_grace_is_over() {
        let mut rx = Listener::default();
        let request = frame(0x20, &[]).to_bytes();
        rx.on_transmit(0, &request);
        run(&mut rx, 10, &request);
        rx.on_transmit(1000, &request);
        run(&mut rx, 1010, &request[..2]);
        let end_us = 1000 + 10 * request.len() as u64;
        assert!(tick(&mut rx, end_us + ECHO_GRACE_US - 1).is_empty());
        assert_eq!(
            tick(&mut rx, end_us + ECHO_GRACE_US),
            [Heard::Echo(Echo::Missing)]
        );
        assert!(rx.take_collision());
        assert!(rx.frame_in_progress(), "the held FE FE were released");
    }

    #[test]
    fn on_a_line_known_to_echo_silence_is_a_missing_echo() {
        let mut rx = Listener::new(ListenerConfig::new().with_echo(EchoMode::Present));
        rx.on_transmit(0, &[1, 2, 3, 4, 5]);
        assert!(tick(&mut rx, 50).is_empty(), "no verdict at the end yet");
        assert_eq!(tick(&mut rx, 80), [Heard::Echo(Echo::Missing)]);
        assert!(rx.take_collision());
    }

    #[test]
    fn silence_is_judged_at_the_end_of_the_transmission() {
        let mut rx = Listener::default();
        let request = frame(0x22, &[0; 13]).to_bytes();
        rx.on_transmit(100, &request);
        assert_eq!(rx.quiet_us(150), 0, "still transmitting");
        let end_us = 100 + 10 * request.len() as u64;
        assert!(tick(&mut rx, end_us - 1).is_empty());
        assert_eq!(tick(&mut rx, end_us), [Heard::Echo(Echo::Silent)]);
        // A single byte's echo may still be on its way at its end: it gets the grace.
        rx.on_transmit(1000, &[0x55]);
        assert!(tick(&mut rx, 1010).is_empty());
        assert_eq!(
            run(&mut rx, 1025, &[0x55]),
            [Heard::Echo(Echo::Whole)],
            "a late echo of one byte is still recognised"
        );
    }

    #[test]
    fn without_echo_any_byte_while_transmitting_is_a_collision() {
        let config = ListenerConfig::new()
            .with_echo(EchoMode::Absent)
            .with_bytes(true);
        let mut rx = Listener::new(config);
        rx.on_transmit(0, &[0xFE, 0xFE, 0x02, 0x20, 0xFA]);
        assert_eq!(
            run(&mut rx, 20, &[0xFE]),
            [Heard::Echo(Echo::Differed), Heard::Byte(0xFE)],
            "not held: it cannot be an echo"
        );
        rx.on_transmit(100, &[0xFE, 0xFE, 0x02, 0x20, 0xFA]);
        assert_eq!(tick(&mut rx, 150), [Heard::Echo(Echo::Silent)]);
        assert_eq!(rx.echo_heard(), None, "fixed by the config, not learned");
        assert!(!rx.take_collision());
    }

    #[test]
    fn raw_bytes_come_out_without_the_echo_and_in_order() {
        let mut rx = Listener::new(ListenerConfig::new().with_bytes(true));
        rx.on_transmit(0, &[1, 2, 3]);
        assert_eq!(
            run(&mut rx, 10, &[1, 2, 3, 4]),
            [Heard::Echo(Echo::Whole), Heard::Byte(4)]
        );
        rx.on_transmit(100, &[1, 2, 3]);
        assert_eq!(
            run(&mut rx, 110, &[1, 2, 9]),
            [
                Heard::Echo(Echo::Differed),
                Heard::Byte(1),
                Heard::Byte(2),
                Heard::Byte(9)
            ]
        );
    }

    #[test]
    fn truncated_frame_is_dropped_after_a_quiet_gap() {
        let mut rx = Listener::default();
        assert!(run(&mut rx, 0, &[0xFE, 0xFE, 0x0F, 0x22]).is_empty());
        assert!(rx.frame_in_progress());
        tick(&mut rx, 30 + BUS_FRAME_GAP_US - 1);
        assert!(rx.frame_in_progress());
        tick(&mut rx, 30 + BUS_FRAME_GAP_US);
        assert!(!rx.frame_in_progress());
        let request = frame(0x20, &[]);
        assert_eq!(
            run(&mut rx, 1000, &request.to_bytes()),
            [Heard::Frame(request)]
        );
    }

    #[test]
    fn a_late_read_is_not_a_silence_inside_a_frame() {
        // A station busy for longer than the gap reads the rest of a frame late, stamped with
        // its poll time: the frame still completes.
        let mut rx = Listener::default();
        let request = frame(0x20, &[]).to_bytes();
        run(&mut rx, 0, &request[..2]);
        tick(&mut rx, 10);
        let heard = run(&mut rx, 10 + 5 * BUS_FRAME_GAP_US, &request[2..]);
        assert_eq!(heard, [Heard::Frame(frame(0x20, &[]))]);
    }

    #[test]
    fn a_cut_packet_is_dropped_after_the_packet_gap_and_the_next_one_kept() {
        let mut rx = Listener::default();
        let ping = Instruction::Ping.to_packet(1).unwrap().to_bytes();
        run(&mut rx, 0, &ping[..4]);
        assert!(tick(&mut rx, 30 + BUS_PACKET_GAP_US - 1).is_empty());
        tick(&mut rx, 30 + BUS_PACKET_GAP_US);
        let reply = status(1, &[]);
        assert_eq!(run(&mut rx, 500, &reply.to_bytes()), [Heard::Packet(reply)]);
    }

    #[test]
    fn a_host_link_waits_its_own_gap_and_decodes_frames_only() {
        let config = ListenerConfig::new()
            .with_packets(false)
            .with_frame_gap_us(HOST_FRAME_GAP_US);
        let mut rx = Listener::new(config);
        let ping = Instruction::Ping.to_packet(1).unwrap().to_bytes();
        assert!(run(&mut rx, 0, &ping).is_empty(), "no servo packets");
        run(&mut rx, 100, &[0xFE, 0xFE, 0x03]);
        tick(&mut rx, 120 + BUS_FRAME_GAP_US);
        assert!(rx.frame_in_progress(), "the bus gap is not the host's");
        tick(&mut rx, 120 + HOST_FRAME_GAP_US);
        assert!(!rx.frame_in_progress());
    }

    #[test]
    fn dropped_partials_do_not_swallow_the_answer() {
        let mut rx = Listener::default();
        // A false start with a large LEN would hold the next 48 bytes.
        run(&mut rx, 0, &[0xFE, 0xFE, 0x30]);
        rx.drop_partials();
        let reply = frame(0x20, &[1]);
        assert_eq!(run(&mut rx, 100, &reply.to_bytes()), [Heard::Frame(reply)]);
    }

    #[test]
    fn the_line_is_busy_until_the_own_transmission_ends() {
        let mut rx = Listener::default();
        rx.assume_busy_until(1_000);
        assert_eq!(rx.quiet_us(1_060), 60);
        rx.on_transmit(1_100, &[0; 5]);
        assert_eq!(rx.quiet_us(1_140), 0);
        assert_eq!(rx.quiet_us(1_170), 20);
        assert_eq!(tick(&mut rx, 1_170), [Heard::Echo(Echo::Silent)]);
        // Written while the first is still going out: queued behind it, one verdict for both.
        rx.on_transmit(1_200, &[1]);
        rx.on_transmit(1_200, &[2]);
        assert_eq!(rx.quiet_us(1_220), 0);
        assert_eq!(run(&mut rx, 1_210, &[1, 2]), [Heard::Echo(Echo::Whole)]);
    }

    #[test]
    fn any_time_and_any_bytes_never_panic() {
        let mut rx = Listener::new(ListenerConfig::new().with_bytes(true));
        rx.on_transmit(u64::MAX - 3, &[0xFF; 300]);
        for t in [u64::MAX, 0, 5, u64::MAX - 1] {
            rx.push(t, 0xFF, &mut |_| {});
            rx.on_time(t, &mut |_| {});
        }
        rx.on_transmit(0, &[]);
        assert_eq!(rx.quiet_us(0), 0);
    }
}
