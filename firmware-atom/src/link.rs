//! The host links a request can come from, and the framing of the Atom's own USB serial.

use protocol_core::timing::HOST_FRAME_GAP_US;
use protocol_core::{Frame, FrameDecoder};

/// Which host link a request came from (its reply goes back there).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Link {
    /// The shared bus (requests forwarded by the Basic).
    Bus,
    /// The Atom's own USB serial.
    Usb,
}

/// Most bytes taken from a link per poll, so one poll stays short whatever arrives.
pub const READ_BUDGET: usize = 512;

/// The Atom's USB serial (115200): a framer with the host link's quiet-gap rule for frames
/// cut short.
#[derive(Clone, Debug, Default)]
pub struct UsbLink {
    frames: FrameDecoder,
    last_rx_us: u64,
}

impl UsbLink {
    /// A link with nothing received yet.
    pub fn new() -> Self {
        Self::default()
    }

    /// Takes one byte received at `now_us`; calls `on_frame` with each frame it completes.
    pub fn push(&mut self, now_us: u64, byte: u8, on_frame: &mut impl FnMut(Frame)) {
        self.last_rx_us = now_us;
        let mut next = self.frames.push(byte);
        while let Some(frame) = next {
            on_frame(frame);
            next = self.frames.next_frame();
        }
    }

    /// Drops a partial frame once the host has been quiet for [`HOST_FRAME_GAP_US`]; calls
    /// `on_frame` with the real frames the rescan uncovers.
    pub fn on_time(&mut self, now_us: u64, on_frame: &mut impl FnMut(Frame)) {
        if self.frames.has_partial() && now_us.saturating_sub(self.last_rx_us) >= HOST_FRAME_GAP_US
        {
            let mut next = self.frames.on_quiet_line();
            while let Some(frame) = next {
                on_frame(frame);
                next = self.frames.next_frame();
            }
        }
    }
}
