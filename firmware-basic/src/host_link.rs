//! One host link of the transponder (the USB serial, or one network client): hears the
//! client's byte stream through its own [`Listener`] (host frames only, and the link's own quiet
//! gap for truncated frames) and queues bytes for the client without ever blocking the loop.

use heapless::{Deque, Vec};
use protocol_core::command::is_basic_local;
use protocol_core::dialect::Dialect;
use protocol_core::frame::{HEADER, MAX_FRAME_BYTES, MAX_LEN, MIN_FRAME_BYTES, MIN_LEN};
use protocol_core::listener::{Heard, Listener, ListenerConfig};
use protocol_core::{Frame, timing};

/// Bytes waiting for each host link: 44 ms of 115200. In framed mode a link's next request
/// goes to the Atom only while a reply of any size still fits, so replies are never dropped; in
/// transparent mode a busy bus (1 Mbaud) outpaces the host link and the oldest bytes go.
pub const HOST_TX_CAPACITY: usize = 512;
/// Most bytes handed to the host port in one write: well under the ESP32 UART's 128-byte FIFO,
/// so a write into an idle transmitter never waits. It also bounds what a reply passed on as
/// it arrives (`HostLink::stream_open`) hands a busy port since it was last idle, so those
/// writes never wait either.
pub const HOST_WRITE_CHUNK: usize = 64;

/// What stands in the queue for the bytes of a reply passed on as it arrives that are not in
/// yet, and stays there if the reply never completes: neither `FE` (it cannot start a frame)
/// nor `FA` (the last byte of the reply's place is then no frame's end).
pub const STREAM_FILLER: u8 = 0x00;
/// Most bytes taken from one host link per poll, so one poll stays short whatever the clients
/// send.
pub const HOST_READ_BUDGET: usize = 64;

/// Silence inside a frame from a network client (TCP over Wi-Fi) after which the frame was cut
/// short, in microseconds. A client writes a frame in one `send`, which arrives in one segment
/// as a rule; a segment split by the network may come a few milliseconds late, and a half frame
/// of garbage only ever delays its own client's next request, so the gap is generous.
pub const NETWORK_FRAME_GAP_US: u64 = 20_000;

/// Silence after which the bare 0xB0 text from a network client is complete, in microseconds
/// (on the serial line it is the frame gap, 2 ms). pymycobot writes the text in one `send` and
/// reads the answer for only 50 ms, so the gap is short: a segment split by the network arrives
/// within it as a rule, and the answer still leaves well inside pymycobot's read.
pub const NETWORK_TEXT_GAP_US: u64 = 5_000;

/// How long pymycobot's socket client waits for a reply before it sends again, in microseconds
/// (`MyCobot280Socket`: 0.3 s per try; the serial client waits 0.5 s).
pub const NETWORK_REPLY_DEADLINE_US: u64 = 300_000;

/// Most bytes a request may still have to come, at the line's speed, for the bus to be held
/// for it (`HostLink::request_coming`): 8, 0.69 ms at 115200. A `get_angles` (5 bytes) is
/// held for from its first byte; a longer request from its last 8. It bounds how long the
/// Atom's servo refresh waits for one request.
pub const HOLD_MAX_REMAINING_BYTES: usize = 8;

/// What a host link is, which sets its timing.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum LinkKind {
    /// A serial line at 115200 baud (the USB serial): a frame cut by a quiet gap of
    /// [`timing::HOST_FRAME_GAP_US`] is dropped; the client resends after 0.5 s.
    Serial,
    /// A network client (TCP): a frame cut by a quiet gap of [`NETWORK_FRAME_GAP_US`] is
    /// dropped; the client resends after [`NETWORK_REPLY_DEADLINE_US`].
    Network,
    /// A program running on the Basic itself ([`crate::program`]): its requests come whole,
    /// from [`mycobot_api`] in the same loop, with the serial line's timings (the crate waits
    /// 0.5 s for a reply, as the serial client does).
    Program,
}

impl LinkKind {
    /// Silence after which a partial frame from this link was cut short, in microseconds.
    pub const fn frame_gap_us(self) -> u64 {
        match self {
            Self::Serial | Self::Program => timing::HOST_FRAME_GAP_US,
            Self::Network => NETWORK_FRAME_GAP_US,
        }
    }

    /// Silence after which the bare 0xB0 text (`crate::wifi::SetTextCapture`) is complete, in
    /// microseconds: 2 ms on the serial line, [`NETWORK_TEXT_GAP_US`] on a network link.
    pub const fn text_gap_us(self) -> u64 {
        match self {
            Self::Serial | Self::Program => timing::HOST_FRAME_GAP_US,
            Self::Network => NETWORK_TEXT_GAP_US,
        }
    }

    /// How long this link's client waits for a reply before it sends the request again, in
    /// microseconds. A request that has waited this long for its turn is dropped unsent: its
    /// client has given up on it, and a command that old must not move the arm (nor its late
    /// reply be taken for the answer to the client's next request).
    pub const fn client_deadline_us(self) -> u64 {
        match self {
            Self::Serial | Self::Program => timing::HOST_REPLY_DEADLINE_US,
            Self::Network => NETWORK_REPLY_DEADLINE_US,
        }
    }

    /// How the Basic hears a link of this kind: host frames only, cut short by its gap.
    const fn listener(self) -> ListenerConfig {
        ListenerConfig::new()
            .with_packets(false)
            .with_frame_gap_us(self.frame_gap_us())
    }
}

/// Most frames one host byte (or one quiet gap) can complete: the framer holds at most
/// [`MAX_FRAME_BYTES`] bytes, and a frame takes at least `3 + MIN_LEN` of them.
pub const MAX_FRAMES_AT_ONCE: usize = MAX_FRAME_BYTES / (3 + MIN_LEN as usize);

/// The frames one host byte or one quiet gap completed, in order.
pub(crate) type HostFrames = Vec<Frame, MAX_FRAMES_AT_ONCE>;

/// FNV-1a's starting value.
const FNV_OFFSET: u32 = 0x811C_9DC5;

/// `bytes` folded into `hash` by FNV-1a: what the bytes of a reply passed on are checked by,
/// without keeping them.
fn digest(hash: u32, bytes: &[u8]) -> u32 {
    bytes
        .iter()
        .fold(hash, |h, &b| (h ^ u32::from(b)).wrapping_mul(0x0100_0193))
}

/// A host link: a listener for what arrives and a bounded queue for what leaves.
#[derive(Debug)]
pub(crate) struct HostLink {
    kind: LinkKind,
    rx: Listener,
    /// The dialect its frames are read in ([`Self::adopt`]).
    dialect: Dialect,
    tx: Deque<u8, HOST_TX_CAPACITY>,
    /// The place in `tx` of a reply passed on as it arrives, until its last byte has left.
    stream: Option<Stream>,
    /// Bytes handed to the port since it was last seen idle.
    since_idle: usize,
}

/// The place of a reply passed on to the client as it arrives on the bus (cut-through): its
/// whole length is reserved in the queue when it opens, so nothing queued later can get into
/// it, and the port is handed only the part that has arrived. See [`HostLink::stream_open`].
#[derive(Debug)]
struct Stream {
    /// Bytes queued ahead of it.
    ahead: usize,
    /// Its bytes still in the queue.
    len: usize,
    /// How many of those are ready for the port (the rest are [`STREAM_FILLER`] standing in
    /// for bytes still to come).
    ready: usize,
    /// How many of its bytes were given so far, and their digest ([`digest`]), to check the
    /// frame that completes it against.
    given: usize,
    given_digest: u32,
    /// Its whole length.
    total: usize,
    /// Still taking bytes (neither completed nor cut).
    open: bool,
}

impl HostLink {
    /// A link of `kind` that has heard and sent nothing.
    pub(crate) const fn new(kind: LinkKind) -> Self {
        Self {
            kind,
            rx: Listener::new(kind.listener()),
            dialect: Dialect::Pymycobot,
            tx: Deque::new(),
            stream: None,
            since_idle: 0,
        }
    }

    /// What the link is.
    pub(crate) fn kind(&self) -> LinkKind {
        self.kind
    }

    /// Takes one byte `byte` from the client at `now_us`; the frames it completes go into
    /// `frames`.
    pub(crate) fn hear(&mut self, now_us: u64, byte: u8, frames: &mut HostFrames) {
        self.rx
            .push(now_us, byte, &mut |heard| collect(heard, frames));
    }

    /// Microseconds since the last host byte arrived.
    pub(crate) fn quiet_for_us(&self, now_us: u64) -> u64 {
        self.rx.quiet_us(now_us)
    }

    /// True if a request for the Atom seems to be arriving on this link at `now_us`, with at
    /// most [`HOLD_MAX_REMAINING_BYTES`] still to come: a serial link in pymycobot's dialect
    /// whose frame in progress has a header that can be a frame's (`FE`, `FE FE`, a LEN from
    /// `MIN_LEN` to `MAX_LEN`, a CMD that is not one of the Basic's own), whose last byte came
    /// within two byte times (the client is still sending it, back to back), and whose LEN (a
    /// shortest frame while it is not in yet) leaves few bytes to come. The Basic holds the bus
    /// for it ([`crate::forwarder::Forwarder::hold`]).
    pub(crate) fn request_coming(&self, now_us: u64) -> bool {
        if self.kind != LinkKind::Serial || self.dialect != Dialect::Pymycobot {
            return false;
        }
        let (_, partial) = self.rx.frame_partial();
        let length = match partial {
            [HEADER] | [HEADER, HEADER] => MIN_FRAME_BYTES,
            [HEADER, HEADER, len, rest @ ..] if (MIN_LEN..=MAX_LEN).contains(len) => {
                if rest.first().is_some_and(|&cmd| is_basic_local(cmd)) {
                    return false;
                }
                3 + usize::from(*len)
            }
            _ => return false,
        };
        let byte_us = timing::wire_time_us(1, timing::HOST_BAUD);
        self.rx.quiet_us(now_us) <= 2 * byte_us
            && length.saturating_sub(partial.len()) <= HOLD_MAX_REMAINING_BYTES
    }

    /// Drops a partial frame once the client has been quiet for the link's gap (it was cut
    /// short); real frames uncovered by the rescan go into `frames`.
    #[inline]
    pub(crate) fn check_gap(&mut self, now_us: u64, frames: &mut HostFrames) {
        self.rx.on_time(now_us, &mut |heard| collect(heard, frames));
    }

    /// The dialect this link's frames are read in.
    pub(crate) fn dialect(&self) -> Dialect {
        self.dialect
    }

    /// Reads this link's frames in `dialect` from now on, if no frame is in progress (one
    /// begun is read whole in the dialect it began in); true if the link speaks `dialect` now.
    pub(crate) fn adopt(&mut self, dialect: Dialect) -> bool {
        if self.dialect != dialect && !self.rx.frame_in_progress() {
            self.dialect = dialect;
            self.rx.set_frame_lengths(dialect.frame_lengths());
        }
        self.dialect == dialect
    }

    /// Forgets any partial frame (when the mode changes).
    pub(crate) fn reset_framer(&mut self) {
        self.rx.drop_partials();
    }

    /// True if a reply frame of any size still fits in the queue.
    pub(crate) fn has_room_for_frame(&self) -> bool {
        HOST_TX_CAPACITY - self.tx.len() >= MAX_FRAME_BYTES
    }

    /// Queues a frame for the host, whole or not at all; false if there was no room.
    pub(crate) fn send_frame(&mut self, frame: &Frame) -> bool {
        let mut buf = [0u8; MAX_FRAME_BYTES];
        match frame.encode(&mut buf).and_then(|n| buf.get(..n)) {
            Some(bytes) => self.send_bytes(bytes),
            None => false,
        }
    }

    /// Queues bytes for the host, all or none; false if there was no room.
    pub(crate) fn send_bytes(&mut self, bytes: &[u8]) -> bool {
        if HOST_TX_CAPACITY - self.tx.len() < bytes.len() {
            return false;
        }
        for &b in bytes {
            // Cannot fail: room was checked above.
            let _ = self.tx.push_back(b);
        }
        true
    }

    /// Queues one raw byte (transparent mode), dropping the oldest queued byte if the queue is
    /// full: a raw tool needs the newest traffic (its servo's answer), not the stale backlog.
    /// False if a byte was dropped.
    pub(crate) fn send_raw(&mut self, byte: u8) -> bool {
        let dropped = self.tx.is_full() && self.pop_front().is_some();
        // Cannot fail: there is room now.
        let _ = self.tx.push_back(byte);
        !dropped
    }

    /// Forgets every byte not yet handed to the host port.
    pub(crate) fn clear_tx(&mut self) {
        self.tx.clear();
        self.stream = None;
    }

    /// Starts passing a reply on as it arrives (cut-through): `head`, its first bytes, are
    /// queued now, and its whole length `len` (`FE FE LEN` + LEN) is reserved behind them, so
    /// what is queued later waits behind the whole reply. The port gets its bytes as they are
    /// given ([`Self::stream_more`]), up to the last one, which only [`Self::stream_finish`]
    /// writes once the whole frame is known good. A reply that never completes
    /// ([`Self::stream_cut`]) leaves [`STREAM_FILLER`] in the rest of its place, so the client
    /// sees a frame whose last byte is not `FA`: no frame. Serial links only (a network client
    /// takes one segment as a whole reply). False, and nothing queued, if that cannot be: not a
    /// serial link, another reply still open, `head` not shorter than `len`, no room.
    pub(crate) fn stream_open(&mut self, head: &[u8], len: usize) -> bool {
        let fits = HOST_TX_CAPACITY - self.tx.len() >= len;
        if self.kind != LinkKind::Serial
            || self.stream.as_ref().is_some_and(|s| s.open)
            || head.len() >= len
            || len > MAX_FRAME_BYTES
            || !fits
        {
            return false;
        }
        // The last one, completed but not all gone yet, is just bytes in the queue now.
        self.stream = None;
        let ahead = self.tx.len();
        for i in 0..len {
            // Cannot fail: room was checked above.
            let _ = self
                .tx
                .push_back(head.get(i).copied().unwrap_or(STREAM_FILLER));
        }
        self.stream = Some(Stream {
            ahead,
            len,
            ready: head.len(),
            given: head.len(),
            given_digest: digest(FNV_OFFSET, head),
            total: len,
            open: true,
        });
        true
    }

    /// Gives the open reply its next bytes (never its last one: the place of that byte is left
    /// to [`Self::stream_finish`]); no-op without an open reply.
    pub(crate) fn stream_more(&mut self, bytes: &[u8]) {
        let Some(stream) = self.stream.as_mut().filter(|s| s.open) else {
            return;
        };
        for &b in bytes {
            if stream.given + 1 >= stream.total {
                break;
            }
            // The reply's bytes still queued: its first `len` of `total` are the last ones.
            let index = stream.ahead + stream.ready;
            if let Some(slot) = self.tx.get_mut(index) {
                *slot = b;
            }
            stream.ready += 1;
            stream.given += 1;
            stream.given_digest = digest(stream.given_digest, &[b]);
        }
    }

    /// Completes the open reply with `frame`, the frame it turned out to be: true if its bytes
    /// so far were `frame`'s first bytes (the rest goes into its place). False, with the reply
    /// cut ([`Self::stream_cut`]), if they were not, or if no reply is open: the caller queues
    /// `frame` whole.
    pub(crate) fn stream_finish(&mut self, frame: &Frame) -> bool {
        let Some(stream) = self.stream.as_mut().filter(|s| s.open) else {
            return false;
        };
        let bytes = frame.to_bytes();
        let given = bytes.get(..stream.given).unwrap_or_default();
        if bytes.len() != stream.total || digest(FNV_OFFSET, given) != stream.given_digest {
            self.stream_cut();
            return false;
        }
        let done = stream.total - stream.len;
        for (i, &b) in bytes.iter().enumerate().skip(stream.given) {
            // The reply's byte i is at queue index ahead + (i - done) while it is queued.
            if let Some(slot) = i
                .checked_sub(done)
                .and_then(|k| self.tx.get_mut(stream.ahead + k))
            {
                *slot = b;
            }
        }
        stream.ready = stream.len;
        stream.open = false;
        true
    }

    /// Ends the open reply without its end: what was not given stays [`STREAM_FILLER`], so the
    /// client decodes no frame from it (no `FE FE` was given inside it: see the forwarder).
    pub(crate) fn stream_cut(&mut self) {
        if let Some(stream) = self.stream.as_mut().filter(|s| s.open) {
            stream.ready = stream.len;
            stream.open = false;
        }
    }

    /// Takes the oldest queued byte, keeping the open reply's place in step.
    fn pop_front(&mut self) -> Option<u8> {
        let byte = self.tx.pop_front()?;
        if let Some(stream) = self.stream.as_mut() {
            if stream.ahead > 0 {
                stream.ahead -= 1;
            } else {
                stream.len = stream.len.saturating_sub(1);
                stream.ready = stream.ready.saturating_sub(1);
            }
            if stream.len == 0 {
                // All of it has left (or was pushed out): nothing to keep in step any more.
                self.stream = None;
            }
        }
        Some(byte)
    }

    /// Takes up to [`HOST_WRITE_CHUNK`] queued bytes for the port, once its transmitter is
    /// `idle`; `None` if there is nothing to hand over now. A reply passed on as it arrives
    /// ([`Self::stream_open`]) is handed over only as far as it has arrived, and once it is at
    /// the front of the queue its bytes follow each other into a busy port too, up to
    /// [`HOST_WRITE_CHUNK`] bytes since the port was last idle (the UART's FIFO takes them
    /// without waiting, and the wire carries them without a gap).
    pub(crate) fn next_chunk(&mut self, idle: bool) -> Option<Vec<u8, HOST_WRITE_CHUNK>> {
        if idle {
            self.since_idle = 0;
        }
        // What may go now, and how much of it into a busy port: the reply's bytes once
        // everything ahead of it has gone.
        let (ready, busy_ok) = match &self.stream {
            Some(s) if s.open => (s.ahead + s.ready, if s.ahead == 0 { s.ready } else { 0 }),
            Some(s) => (self.tx.len(), if s.ahead == 0 { s.len } else { 0 }),
            None => (self.tx.len(), 0),
        };
        let allowed = if idle {
            HOST_WRITE_CHUNK
        } else {
            busy_ok.min(HOST_WRITE_CHUNK.saturating_sub(self.since_idle))
        };
        let n = ready.min(allowed);
        if n == 0 {
            return None;
        }
        let mut chunk = Vec::new();
        for _ in 0..n {
            match self.pop_front() {
                // Cannot fail: n <= HOST_WRITE_CHUNK, the chunk's capacity.
                Some(b) => {
                    let _ = chunk.push(b);
                }
                None => break,
            }
        }
        self.since_idle += chunk.len();
        Some(chunk)
    }
}

/// Keeps the frames a host listener heard (it hears nothing else).
fn collect(heard: Heard, frames: &mut HostFrames) {
    if let Heard::Frame(frame) = heard {
        // Cannot fail: one byte or one gap completes at most MAX_FRAMES_AT_ONCE frames.
        let _ = frames.push(frame);
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// `GET_ANGLES` (0x20), as pymycobot sends it.
    const GET_ANGLES: [u8; 5] = [0xFE, 0xFE, 0x02, 0x20, 0xFA];

    /// Hears `bytes` from the client, one every 87 us (115200 baud) from `start_us`; returns
    /// the frames they completed.
    fn hear_all(link: &mut HostLink, start_us: u64, bytes: &[u8]) -> std::vec::Vec<Frame> {
        let mut heard = std::vec::Vec::new();
        for (i, &byte) in bytes.iter().enumerate() {
            let mut frames = HostFrames::new();
            link.hear(start_us + 87 * i as u64, byte, &mut frames);
            heard.extend(frames);
        }
        heard
    }

    /// What `link` hands the port, chunk by chunk, until its queue is empty.
    fn drain(link: &mut HostLink) -> std::vec::Vec<u8> {
        let mut out = std::vec::Vec::new();
        while let Some(chunk) = link.next_chunk(true) {
            assert!(!chunk.is_empty() && chunk.len() <= HOST_WRITE_CHUNK);
            out.extend_from_slice(&chunk);
        }
        out
    }

    #[test]
    fn only_host_frames_are_heard_not_servo_packets_or_noise() {
        let mut link = HostLink::new(LinkKind::Serial);
        // A servo ping (a transparent-mode tool's bytes sent in framed mode), then line noise.
        let ping = [0xFF, 0xFF, 0x01, 0x02, 0x01, 0xFB];
        assert!(hear_all(&mut link, 0, &ping).is_empty());
        assert!(hear_all(&mut link, 1_000, &[0x00, 0xFA, 0x13]).is_empty());
        let heard = hear_all(&mut link, 2_000, &GET_ANGLES);
        assert_eq!(heard.len(), 1, "{heard:?}");
        assert_eq!(heard.first().map(Frame::cmd), Some(0x20));
    }

    #[test]
    fn a_pause_inside_a_frame_cuts_it_on_a_serial_line_but_not_over_the_network() {
        // The client writes the first half, stalls 5 ms, then writes the rest: longer than the
        // serial line's gap, shorter than a network link's.
        let pause_us = 5_000;
        let (first, rest) = GET_ANGLES.split_at(2);
        for (kind, whole) in [(LinkKind::Serial, false), (LinkKind::Network, true)] {
            let mut link = HostLink::new(kind);
            assert!(hear_all(&mut link, 0, first).is_empty());
            let mut frames = HostFrames::new();
            link.check_gap(pause_us, &mut frames);
            assert!(frames.is_empty());
            let heard = hear_all(&mut link, pause_us, rest);
            assert_eq!(heard.len() == 1, whole, "{kind:?}: {heard:?}");
        }
    }

    #[test]
    fn a_frame_inside_one_cut_short_comes_out_after_the_gap() {
        let mut link = HostLink::new(LinkKind::Serial);
        // A header that announces 16 bytes (a client killed mid-write), then a whole request:
        // it is read as part of the first until the line has been quiet for the gap.
        let mut bytes = std::vec![0xFE, 0xFE, 0x10];
        bytes.extend_from_slice(&GET_ANGLES);
        assert!(hear_all(&mut link, 0, &bytes).is_empty());
        let mut frames = HostFrames::new();
        link.check_gap(1_000, &mut frames);
        assert!(frames.is_empty(), "not quiet long enough yet");
        link.check_gap(1_000 + timing::HOST_FRAME_GAP_US, &mut frames);
        assert_eq!(frames.len(), 1, "{frames:?}");
        assert_eq!(frames.first().map(Frame::cmd), Some(0x20));
    }

    #[test]
    fn a_mode_change_forgets_a_partial_frame() {
        let mut link = HostLink::new(LinkKind::Serial);
        let (first, rest) = GET_ANGLES.split_at(3);
        assert!(hear_all(&mut link, 0, first).is_empty());
        link.reset_framer();
        assert!(hear_all(&mut link, 300, rest).is_empty());
        assert_eq!(hear_all(&mut link, 600, &GET_ANGLES).len(), 1);
    }

    #[test]
    fn a_new_dialect_is_adopted_between_frames_only() {
        // The manual's set speed with its LEN miscounted (02 for one data byte).
        let seed_set_speed = [0xFE, 0xFE, 0x02, 0x41, 0x32, 0xFA];
        let mut link = HostLink::new(LinkKind::Serial);
        assert!(
            hear_all(&mut link, 0, &seed_set_speed).is_empty(),
            "pymycobot's LEN"
        );
        let mut link = HostLink::new(LinkKind::Serial);
        let (first, rest) = GET_ANGLES.split_at(3);
        assert!(hear_all(&mut link, 0, first).is_empty());
        assert!(!link.adopt(Dialect::Seed), "a frame is in progress");
        assert_eq!(hear_all(&mut link, 300, rest).len(), 1);
        assert!(link.adopt(Dialect::Seed));
        assert_eq!(link.dialect(), Dialect::Seed);
        let heard = hear_all(&mut link, 1_000, &seed_set_speed);
        assert_eq!(heard.first().map(Frame::data), Some(&[0x32][..]));
    }

    #[test]
    fn replies_are_queued_whole_or_not_at_all() {
        let mut link = HostLink::new(LinkKind::Serial);
        let filler = [0x55; HOST_TX_CAPACITY - MAX_FRAME_BYTES + 1];
        assert!(link.send_bytes(&filler));
        assert!(!link.has_room_for_frame(), "a frame of any size must fit");
        let angles = Frame::new(0x20, &[0; 12]).unwrap();
        let room = MAX_FRAME_BYTES - 1;
        let long = Frame::new(0x20, &[0; protocol_core::frame::MAX_DATA]).unwrap();
        assert!(long.to_bytes().len() > room);
        assert!(!link.send_frame(&long), "a frame that does not fit");
        assert!(link.send_frame(&angles), "one that does");
        let sent = drain(&mut link);
        let (head, tail) = sent.split_at(filler.len());
        assert_eq!(head, filler, "nothing of the refused frame");
        assert_eq!(tail, angles.to_bytes().as_slice());
        assert!(link.has_room_for_frame(), "empty again");
    }

    #[test]
    fn raw_bytes_push_out_the_oldest_when_the_queue_is_full() {
        let mut link = HostLink::new(LinkKind::Serial);
        let bytes = (0..=HOST_TX_CAPACITY).map(|i| i as u8);
        let kept: std::vec::Vec<bool> = bytes.clone().map(|b| link.send_raw(b)).collect();
        assert_eq!(kept.iter().filter(|&&k| !k).count(), 1, "one byte dropped");
        assert_eq!(kept.last(), Some(&false), "by the last one sent");
        let expected: std::vec::Vec<u8> = bytes.skip(1).collect();
        assert_eq!(
            drain(&mut link),
            expected,
            "the oldest went, the newest stayed"
        );
    }

    #[test]
    fn a_request_is_coming_while_a_plausible_frame_arrives_with_few_bytes_to_go() {
        let byte = timing::wire_time_us(1, timing::HOST_BAUD);
        // Each prefix of a frame, heard at line speed: is a request coming right after it?
        let coming_after = |bytes: &[u8], kind: LinkKind| {
            let mut link = HostLink::new(kind);
            hear_all(&mut link, 0, bytes);
            let last = byte * (bytes.len() as u64 - 1);
            link.request_coming(last + byte)
        };
        for n in 1..GET_ANGLES.len() {
            assert!(
                coming_after(&GET_ANGLES[..n], LinkKind::Serial),
                "{n} bytes in"
            );
            assert!(
                !coming_after(&GET_ANGLES[..n], LinkKind::Network),
                "a network link"
            );
        }
        assert!(
            !coming_after(&GET_ANGLES, LinkKind::Serial),
            "in: no longer coming"
        );
        // The Basic's own command (0xC1), and a LEN no frame has.
        assert!(!coming_after(&[0xFE, 0xFE, 0x02, 0xC1], LinkKind::Serial));
        assert!(!coming_after(&[0xFE, 0xFE, 0x41], LinkKind::Serial));
        // A long frame: only its last 8 bytes.
        let mut send_angles = std::vec![0xFE, 0xFE, 0x0F, 0x22];
        send_angles.extend_from_slice(&[0; 13]);
        assert!(!coming_after(&send_angles[..9], LinkKind::Serial));
        assert!(coming_after(&send_angles[..10], LinkKind::Serial));
        // A client that stopped sending mid-frame.
        let mut link = HostLink::new(LinkKind::Serial);
        hear_all(&mut link, 0, &GET_ANGLES[..2]);
        assert!(link.request_coming(byte * 2));
        assert!(
            !link.request_coming(byte * 4),
            "quiet for over two byte times"
        );
        // Another dialect reads other lengths.
        let mut link = HostLink::new(LinkKind::Serial);
        assert!(link.adopt(Dialect::Seed));
        hear_all(&mut link, 0, &GET_ANGLES[..2]);
        assert!(!link.request_coming(byte * 2));
    }

    /// `get_angles`' reply as the Atom sends it.
    fn angles_reply() -> std::vec::Vec<u8> {
        Frame::new(
            0x20,
            &[0, 100, 0xFF, 0x9C, 0, 0, 0, 0, 0x12, 0x34, 0xFE, 0xFA],
        )
        .unwrap()
        .to_bytes()
        .to_vec()
    }

    #[test]
    fn a_reply_passed_on_as_it_arrives_goes_out_only_as_far_as_it_has_arrived() {
        let mut link = HostLink::new(LinkKind::Serial);
        let reply = angles_reply();
        assert!(link.stream_open(&reply[..4], reply.len()));
        assert_eq!(drain(&mut link), reply[..4], "the head at once");
        link.stream_more(&reply[4..10]);
        assert_eq!(drain(&mut link), reply[4..10]);
        // Never the last byte: only the frame, once known whole, completes it.
        link.stream_more(&reply[10..]);
        assert_eq!(drain(&mut link), reply[10..reply.len() - 1]);
        let frame = Frame::new(0x20, &reply[4..reply.len() - 1]).unwrap();
        assert!(link.stream_finish(&frame));
        assert_eq!(drain(&mut link), [0xFA]);
        assert!(link.next_chunk(true).is_none());
    }

    #[test]
    fn what_is_queued_behind_a_reply_passed_on_waits_for_its_end() {
        let mut link = HostLink::new(LinkKind::Serial);
        let reply = angles_reply();
        assert!(link.stream_open(&reply[..4], reply.len()));
        // An answer of the Basic's own to the same client, queued meanwhile.
        let own = Frame::new(0xC1, &[10]).unwrap();
        assert!(link.send_frame(&own));
        let mut got = drain(&mut link);
        assert_eq!(got, reply[..4], "not into the middle of the reply");
        link.stream_more(&reply[4..]);
        assert!(link.stream_finish(&Frame::new(0x20, &reply[4..reply.len() - 1]).unwrap()));
        got.extend(drain(&mut link));
        let mut expected = reply.clone();
        expected.extend_from_slice(&own.to_bytes());
        assert_eq!(got, expected);
    }

    #[test]
    fn a_reply_cut_short_leaves_the_client_no_frame() {
        let reply = angles_reply();
        for cut_after in 4..reply.len() - 1 {
            let mut link = HostLink::new(LinkKind::Serial);
            assert!(link.stream_open(&reply[..4], reply.len()));
            link.stream_more(&reply[4..cut_after]);
            link.stream_cut();
            // What follows is the next reply.
            assert!(link.send_bytes(&reply));
            let got = drain(&mut link);
            assert_eq!(got.len(), 2 * reply.len(), "its whole place, then the next");
            assert_eq!(got[..cut_after], reply[..cut_after]);
            assert!(
                got[cut_after..reply.len()]
                    .iter()
                    .all(|&b| b == STREAM_FILLER),
                "{got:02x?}"
            );
            let mut frames = std::vec::Vec::new();
            protocol_core::FrameDecoder::new().feed(&got, |f| frames.push(f));
            assert_eq!(frames.len(), 1, "cut after {cut_after}: {frames:?}");
            assert_eq!(frames[0].to_bytes().as_slice(), reply.as_slice());
        }
    }

    #[test]
    fn a_reply_that_turns_out_another_frame_is_cut_and_the_frame_goes_whole() {
        let mut link = HostLink::new(LinkKind::Serial);
        let reply = angles_reply();
        assert!(link.stream_open(&reply[..4], reply.len()));
        link.stream_more(&reply[4..8]);
        let other = Frame::new(0x20, &[9; 12]).unwrap();
        assert!(!link.stream_finish(&other), "its start differs");
        assert!(link.send_frame(&other));
        let got = drain(&mut link);
        assert_eq!(got[reply.len()..], other.to_bytes()[..]);
        assert!(!link.stream_finish(&other), "nothing open any more");
    }

    #[test]
    fn a_reply_is_passed_on_only_on_a_serial_link_and_only_one_at_a_time() {
        let reply = angles_reply();
        let mut link = HostLink::new(LinkKind::Network);
        assert!(
            !link.stream_open(&reply[..4], reply.len()),
            "a segment is a reply"
        );
        let mut link = HostLink::new(LinkKind::Serial);
        assert!(
            !link.stream_open(&reply, reply.len()),
            "the head is not the whole"
        );
        assert!(link.stream_open(&reply[..4], reply.len()));
        assert!(!link.stream_open(&reply[..4], reply.len()));
        link.stream_cut();
        assert!(link.stream_open(&reply[..4], reply.len()), "after the cut");
        let mut full = HostLink::new(LinkKind::Serial);
        assert!(full.send_bytes(&[0x55; HOST_TX_CAPACITY - 10]));
        assert!(
            !full.stream_open(&reply[..4], reply.len()),
            "no room for its place"
        );
    }

    #[test]
    fn a_reply_passed_on_follows_itself_into_a_busy_port_but_nothing_else_does() {
        let mut link = HostLink::new(LinkKind::Serial);
        let reply = angles_reply();
        assert!(link.send_bytes(&[1, 2, 3]));
        assert!(link.stream_open(&reply[..4], reply.len()));
        // The port is busy before anything was handed to it since it was idle: wait.
        assert!(link.next_chunk(false).is_none());
        let first = link.next_chunk(true).unwrap();
        assert_eq!(
            first.as_slice(),
            &[&[1, 2, 3][..], &reply[..4]].concat()[..]
        );
        link.stream_more(&reply[4..6]);
        let more = link
            .next_chunk(false)
            .expect("the reply goes on into the busy port");
        assert_eq!(more.as_slice(), &reply[4..6]);
        link.stream_more(&reply[6..]);
        assert!(link.stream_finish(&Frame::new(0x20, &reply[4..reply.len() - 1]).unwrap()));
        assert!(link.send_bytes(&[7]));
        let rest = link.next_chunk(false).unwrap();
        assert_eq!(rest.as_slice(), &reply[6..], "its end too");
        assert!(
            link.next_chunk(false).is_none(),
            "what follows waits for an idle port"
        );
        assert_eq!(link.next_chunk(true).unwrap().as_slice(), &[7]);
    }

    #[test]
    fn a_busy_port_is_handed_at_most_a_chunk_since_it_was_last_idle() {
        let mut link = HostLink::new(LinkKind::Serial);
        let long = Frame::new(0x20, &[7; protocol_core::frame::MAX_DATA]).unwrap();
        let bytes = long.to_bytes();
        assert!(link.stream_open(&bytes[..4], bytes.len()));
        let mut handed = link.next_chunk(true).unwrap().len();
        link.stream_more(&bytes[4..]);
        while let Some(chunk) = link.next_chunk(false) {
            handed += chunk.len();
        }
        assert_eq!(handed, HOST_WRITE_CHUNK, "the FIFO never fills");
        assert!(link.next_chunk(true).is_some(), "the rest once idle");
    }

    #[test]
    fn the_port_gets_small_chunks_and_only_while_its_transmitter_is_idle() {
        let mut link = HostLink::new(LinkKind::Serial);
        let bytes: std::vec::Vec<u8> = (0..100).collect();
        assert!(link.send_bytes(&bytes));
        assert!(link.next_chunk(false).is_none(), "transmitter busy");
        let first = link.next_chunk(true).unwrap();
        assert_eq!(first.as_slice(), &bytes[..HOST_WRITE_CHUNK]);
        link.clear_tx();
        assert!(link.next_chunk(true).is_none(), "cleared");
    }
}
