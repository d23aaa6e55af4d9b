//! The host side of the transponder: hears the host's byte stream through a [`Listener`] (host
//! frames only, and the host link's quiet gap for truncated frames) and queues bytes for the
//! host without ever blocking the loop.

use heapless::{Deque, Vec};
use protocol_core::frame::{MAX_FRAME_BYTES, MIN_LEN};
use protocol_core::listener::{Heard, Listener, ListenerConfig};
use protocol_core::{BytePort, Frame, timing};

/// Bytes waiting for the host link: 44 ms of 115200. In framed mode the forwarder starts a
/// request only while a reply of any size still fits, so replies are never dropped; in
/// transparent mode a busy bus (1 Mbaud) outpaces the host link and the oldest bytes go.
pub const HOST_TX_CAPACITY: usize = 512;
/// Most bytes handed to the host port in one write: well under the ESP32 UART's 128-byte FIFO,
/// so a write into an idle transmitter never waits.
pub const HOST_WRITE_CHUNK: usize = 64;
/// Most host bytes taken per poll, so one poll stays short whatever the host sends.
pub const HOST_READ_BUDGET: usize = 64;

/// How the Basic hears its host link: host frames only, cut short by the host link's gap.
const HOST_LISTENER: ListenerConfig = ListenerConfig::new()
    .with_packets(false)
    .with_frame_gap_us(timing::HOST_FRAME_GAP_US);

/// Most frames one host byte (or one quiet gap) can complete: the framer holds at most
/// [`MAX_FRAME_BYTES`] bytes, and a frame takes at least `3 + MIN_LEN` of them.
pub const MAX_FRAMES_AT_ONCE: usize = MAX_FRAME_BYTES / (3 + MIN_LEN as usize);

/// The frames one host byte or one quiet gap completed, in order.
pub(crate) type HostFrames = Vec<Frame, MAX_FRAMES_AT_ONCE>;

/// The host link: a listener for what arrives and a bounded queue for what leaves.
#[derive(Debug)]
pub(crate) struct HostLink {
    rx: Listener,
    tx: Deque<u8, HOST_TX_CAPACITY>,
}

impl HostLink {
    pub(crate) const fn new() -> Self {
        Self {
            rx: Listener::new(HOST_LISTENER),
            tx: Deque::new(),
        }
    }

    /// Takes one byte from the host at `now_us`; the frames it completes go into `frames`.
    pub(crate) fn read_byte<H: BytePort>(
        &mut self,
        now_us: u64,
        host: &mut H,
        frames: &mut HostFrames,
    ) -> Option<u8> {
        let byte = host.read_byte()?;
        self.rx
            .push(now_us, byte, &mut |heard| collect(heard, frames));
        Some(byte)
    }

    /// Microseconds since the last host byte arrived.
    pub(crate) fn quiet_for_us(&self, now_us: u64) -> u64 {
        self.rx.quiet_us(now_us)
    }

    /// Drops a partial frame once the host has been quiet for [`timing::HOST_FRAME_GAP_US`]
    /// (it was cut short); real frames uncovered by the rescan go into `frames`.
    #[inline]
    pub(crate) fn check_gap(&mut self, now_us: u64, frames: &mut HostFrames) {
        self.rx.on_time(now_us, &mut |heard| collect(heard, frames));
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
        let dropped = self.tx.is_full() && self.tx.pop_front().is_some();
        // Cannot fail: there is room now.
        let _ = self.tx.push_back(byte);
        !dropped
    }

    /// Forgets every byte not yet handed to the host port.
    pub(crate) fn clear_tx(&mut self) {
        self.tx.clear();
    }

    /// Hands queued bytes to the host port once its transmitter is idle.
    pub(crate) fn flush<H: BytePort>(&mut self, host: &mut H) {
        if self.tx.is_empty() || !host.tx_idle() {
            return;
        }
        let mut chunk = [0u8; HOST_WRITE_CHUNK];
        let mut n = 0;
        for slot in chunk.iter_mut() {
            match self.tx.pop_front() {
                Some(b) => {
                    *slot = b;
                    n += 1;
                }
                None => break,
            }
        }
        if let Some(bytes) = chunk.get(..n) {
            host.write(bytes);
        }
    }
}

/// Keeps the frames a host listener heard (it hears nothing else).
fn collect(heard: Heard, frames: &mut HostFrames) {
    if let Heard::Frame(frame) = heard {
        // Cannot fail: one byte or one gap completes at most MAX_FRAMES_AT_ONCE frames.
        let _ = frames.push(frame);
    }
}
