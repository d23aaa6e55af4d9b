//! The host links a request can come from, and the framing of the Atom's own USB serial.

use protocol_core::Frame;
use protocol_core::listener::{Heard, Listener, ListenerConfig};
use protocol_core::timing::HOST_FRAME_GAP_US;

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

/// How the USB link listens: host frames only, a frame cut short by [`HOST_FRAME_GAP_US`] of
/// silence is dropped.
const USB_LISTENER: ListenerConfig = ListenerConfig::new()
    .with_packets(false)
    .with_frame_gap_us(HOST_FRAME_GAP_US);

/// The Atom's USB serial (115200): the host frames arriving on it.
#[derive(Clone, Debug)]
pub struct UsbLink {
    rx: Listener,
}

impl Default for UsbLink {
    fn default() -> Self {
        Self::new()
    }
}

impl UsbLink {
    /// A link with nothing received yet.
    pub fn new() -> Self {
        Self {
            rx: Listener::new(USB_LISTENER),
        }
    }

    /// Takes one byte received at `now_us`; calls `on_frame` with each frame it completes.
    pub fn push(&mut self, now_us: u64, byte: u8, on_frame: &mut impl FnMut(Frame)) {
        self.rx.push(now_us, byte, &mut frames_to(on_frame));
    }

    /// Drops a partial frame once the host has been quiet for [`HOST_FRAME_GAP_US`]; calls
    /// `on_frame` with the real frames the rescan uncovers.
    pub fn on_time(&mut self, now_us: u64, on_frame: &mut impl FnMut(Frame)) {
        self.rx.on_time(now_us, &mut frames_to(on_frame));
    }
}

/// Passes the frames the listener heard on to `on_frame`.
fn frames_to(on_frame: &mut impl FnMut(Frame)) -> impl FnMut(Heard) + '_ {
    |heard| {
        if let Heard::Frame(frame) = heard {
            on_frame(frame);
        }
    }
}
