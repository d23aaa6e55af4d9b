//! What the transponder reports about itself: the contents of the Basic's LCD.

pub use protocol_core::command::TransponderMode;

use crate::wifi::WifiError;

/// Whether the Atom answers.
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
    /// Request `cmd` from the host was dropped unsent: the request queue was full, or it
    /// waited in the queue until the client had given up on it (0.5 s).
    QueueFull {
        /// The request's command byte.
        cmd: u8,
    },
    /// Request `cmd` for the Atom was dropped unanswered: the bus is in transparent mode for
    /// another client.
    TransparentElsewhere {
        /// The request's command byte.
        cmd: u8,
    },
    /// A 0xA0/0xA1 request named a pin the Basic does not have.
    InvalidPin {
        /// The pin number asked for.
        pin: u8,
    },
    /// Bytes for the host were dropped because the host link could not keep up (in
    /// transparent mode a busy bus outpaces the 115200 host link; the oldest bytes go).
    HostOverflow,
    /// The dialect could not be written to flash: it is in force until power-off.
    SettingNotSaved,
    /// A Wi-Fi command was refused or its flash write failed (the client got `00`; nothing
    /// changed).
    Wifi(WifiError),
}

/// What the Basic shows on its LCD.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct BasicStatus {
    /// The Basic's firmware version, times ten.
    pub version_x10: u8,
    /// Framed (host frames checked, own commands answered, the rest forwarded one request at
    /// a time) or transparent (raw bytes both ways until `FE FE 03 C2 00 FA`).
    pub mode: TransponderMode,
    /// The dialect the clients speak (`docs/protocol.md`, "Dialects").
    pub dialect: protocol_core::dialect::Dialect,
    /// Whether the Atom answers.
    pub atom: AtomLink,
    /// The Atom's power state from its last 0x10/0x11/0x12 answer, if known.
    pub atom_powered: Option<bool>,
    /// Whether the bus echoes the Basic's transmissions, once known.
    pub echo_heard: Option<bool>,
    /// The last thing that went wrong.
    pub last_error: Option<BasicError>,
    /// Host frames received in framed mode on every link (own commands and forwarded). Wraps.
    pub host_frames: u32,
    /// Replies from the Atom passed to the clients that asked. Wraps.
    pub replies_forwarded: u32,
    /// Requests the Atom did not answer in time. Wraps.
    pub timeouts: u32,
    /// Replies that came after their request was given up on: dropped, never given to a
    /// client. Wraps.
    pub late_replies: u32,
    /// Requests sent again (or given up) because they or their reply collided on the bus.
    /// Wraps.
    pub collisions: u32,
    /// Host bytes dropped in transparent mode because the bus could not take them. Wraps.
    pub transparent_dropped: u32,
}

impl Default for BasicStatus {
    fn default() -> Self {
        Self {
            version_x10: 0,
            mode: TransponderMode::Framed,
            dialect: protocol_core::dialect::Dialect::Pymycobot,
            atom: AtomLink::Unknown,
            atom_powered: None,
            echo_heard: None,
            last_error: None,
            host_frames: 0,
            replies_forwarded: 0,
            timeouts: 0,
            late_replies: 0,
            collisions: 0,
            transparent_dropped: 0,
        }
    }
}
