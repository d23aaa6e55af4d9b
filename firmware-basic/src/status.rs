//! What the transponder reports about itself: the contents of the Basic's LCD.

/// How the host link is used.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub enum TransponderMode {
    /// Host frames are checked, the Basic's own commands answered, the rest forwarded one
    /// request at a time, and only the matching reply returned (mode 0 of 0xC2).
    #[default]
    Framed,
    /// Raw bytes both ways (mode 1 of 0xC2), for tools that talk to the servos directly. The
    /// only thing still recognised is the frame `FE FE 03 C2 00 FA`, which returns to framed
    /// mode.
    Transparent,
}

impl TransponderMode {
    /// The mode byte of 0xC2/0xC3.
    pub fn code(self) -> u8 {
        match self {
            Self::Framed => 0,
            Self::Transparent => 1,
        }
    }

    /// The mode for a 0xC2 mode byte; `None` for an unknown mode.
    pub fn from_code(code: u8) -> Option<Self> {
        match code {
            0 => Some(Self::Framed),
            1 => Some(Self::Transparent),
            _ => None,
        }
    }
}

/// Whether the Atom answers on the bus.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub enum AtomLink {
    /// Nothing asked of it has been answered yet (booting).
    #[default]
    Unknown,
    /// Its last expected reply arrived.
    Answering,
    /// Its last expected reply did not arrive in time.
    Silent,
}

/// Something that went wrong, kept for the display until something else goes wrong.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum BasicError {
    /// The Atom did not answer request `cmd` in time.
    ReplyTimeout {
        /// The request's command byte.
        cmd: u8,
    },
    /// Request `cmd` collided on the bus every time it was sent and was given up.
    BusCollisions {
        /// The request's command byte.
        cmd: u8,
    },
    /// The request queue was full; request `cmd` from the host was dropped.
    QueueFull {
        /// The request's command byte.
        cmd: u8,
    },
    /// A 0xA0/0xA1 request named a pin the Basic does not have.
    InvalidPin {
        /// The pin number asked for.
        pin: u8,
    },
    /// Bytes for the host were dropped because the host link could not keep up.
    HostOverflow,
}

/// What the Basic shows on its LCD.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct BasicStatus {
    /// The Basic's firmware version, times ten.
    pub version_x10: u8,
    /// Framed or transparent.
    pub mode: TransponderMode,
    /// Whether the Atom answers.
    pub atom: AtomLink,
    /// The Atom's power state from its last 0x12/0x10 answer, if known.
    pub atom_powered: Option<bool>,
    /// Whether the bus echoes the Basic's transmissions, once known.
    pub echo_heard: Option<bool>,
    /// The last thing that went wrong.
    pub last_error: Option<BasicError>,
    /// Host frames received in framed mode (own commands and forwarded). Wraps.
    pub host_frames: u32,
    /// Replies from the Atom passed to the host. Wraps.
    pub replies_forwarded: u32,
    /// Requests the Atom did not answer in time. Wraps.
    pub timeouts: u32,
    /// Bus transmissions that collided and were repeated. Wraps.
    pub collisions: u32,
    /// Host bytes dropped in transparent mode because the bus could not take them. Wraps.
    pub transparent_dropped: u32,
}
