//! The myCobot 280 M5 Basic firmware: the transponder between the host's links (the USB serial
//! at 115200, and network clients) and the arm's shared 1 Mbaud bus, as a host-tested library
//! of poll-driven state machines.
//!
//! The Basic makes the arm feel like one device to each client: every request reaches the Atom
//! once, its reply reaches the client that asked once, and nothing else leaks (servo packets,
//! its own echo, replies to its internal requests or to other clients). The board layer
//! (esp-hal binary) and the virtual robot bind [`BasicIo`], the bus
//! [`BytePort`](protocol_core::BytePort) and the host links ([`HostPorts`]; a single UART is
//! one) and call [`Basic::poll`] in a tight loop.
//!
//! # What each part does
//!
//! * [`router`]: the host links, each with its own framer, request queue and output queue; the
//!   USB link is always open, network clients come and go ([`Basic::open_link`],
//!   [`Basic::close_link`], at most [`MAX_HOST_LINKS`]). The bus serves the links round robin,
//!   and each reply goes to the client that asked.
//! * [`local`]: the commands the Basic answers itself (0xA0, 0xA1, 0xB0..0xB2, 0xC0..0xC3), at
//!   once, to the client that asked, even while the Atom is silent or a flood fills a queue.
//! * [`wifi`]: the Wi-Fi settings (0xB0..0xB2, kept in the flash store the board lends through
//!   [`BasicIo::wifi_store`]) and the station machine; [`Basic::wifi_mut`] is how the board's
//!   network layer drives the station. 0xB0's bare text is caught per link (a
//!   [`wifi::SetTextCapture`] before that link's framer). A settings change is written to flash
//!   when the bus is quiet (a flash erase stalls the CPU), at most
//!   [`wifi::WIFI_WRITE_WAIT_US`] after it arrived ([`wifi::SettingsWrites`]). A board that
//!   lends no store has no Wi-Fi: 0xB0/0xB2 are refused with `00`, 0xB1 reports empty
//!   credentials in the text form pymycobot parses.
//! * [`clients`]: the network clients (TCP) as the board's sockets and the virtual robot's
//!   streams both use them: a link each, bounded buffers both ways, the client limit.
//! * [`forwarder`]: everything else goes onto the bus, one request at a time, into a quiet
//!   wire, echo checked (heard or not: [`EchoMode::Auto`] finds out on the first send),
//!   collisions the echo proves retried; a client's request is otherwise never sent twice.
//!   Only the reply with the request's CMD comes back, a request the Atom does not answer is
//!   given up after [`BasicConfig::reply_timeout_us`] (below pymycobot's 0.5 s resend), and
//!   its late reply is dropped, never taken for another request's. While a request is still
//!   arriving on a serial link, the Basic holds the bus with a `00` byte early in each of the
//!   Atom's gaps ([`forwarder::HOLD_BYTE`]), so the request goes as soon as it is in. A serial
//!   client's reply
//!   is passed on as it arrives (cut-through, all but its last byte before it is whole); one
//!   cut short leaves the client a frame header whose frame ends in filler, no frame.
//! * [`transparent`]: after `0xC2 01` raw bytes go both ways (the Basic's echo removed)
//!   between the bus and the client that switched, until it sends exactly
//!   `FE FE 03 C2 00 FA` (or leaves); only that and the exact mode frames `FE FE 03 C2 01 FA`
//!   and `FE FE 02 C3 FA` are still answered by the Basic then. The other clients are still
//!   heard in framed mode: the Basic's own commands are answered (0xC3 says transparent),
//!   0xC2 is refused with `00`, and requests for the Atom are dropped unanswered (any answer
//!   the Basic made up could be read as a value). The switch waits for the request on the bus
//!   to be answered; requests still waiting are dropped.
//! * [`host_link`]: one link's framing (a frame cut by its link's quiet gap is dropped) and a
//!   bounded output queue written only into an idle transmitter (or, for a reply passed on as
//!   it arrives, at most [`host_link::HOST_WRITE_CHUNK`] bytes since it was last idle), so
//!   `poll` never blocks.
//! * Every link is heard through `protocol_core`'s timed
//!   [`Listener`](protocol_core::listener::Listener): each host link for its frames, the bus
//!   (one listener for framed and transparent mode) for the Atom's replies, raw bytes, the
//!   Basic's own echo and how quiet the wire is.
//! * The `supervisor`: at boot the Basic makes sure the Atom is powered, like the vendor
//!   transponder, but without its side effect: it asks (0x12) and powers on (0x10) only an
//!   Atom that says it is off, so a move the host already started is never cut short (0x10
//!   makes the Atom hold the arm where it is). Afterwards it probes the Atom (0x12) whenever it
//!   has been silent for [`BasicConfig::probe_interval_us`]; the replies to these internal
//!   requests never reach a client (the router delivers them to nobody), they feed
//!   [`Basic::status`] (what the LCD shows). A press of button A powers the Atom on, once (a
//!   button read as pressed from boot counts only after a release).
//!
//! # The parts, bottom up
//!
//! Each part imports only parts listed before it (none imports one that imports it back,
//! tests included), so each can be read without the ones after it:
//!
//! * [`config`], [`host_link`], [`request`]: the settings; one link's framing and output
//!   queue; who asked (link ids, clients, requests and their origin, what became of a reply).
//!   They import nothing of the crate.
//! * [`wifi`], a facade over its own parts (`config`, `store`, `connection`, `commands`,
//!   `writes`): the settings, their flash store, the station, the answers to 0xB0..0xB2 and
//!   the changes waiting for a quiet bus. It imports nothing else of the crate.
//! * [`io`], [`status`]: what the board lends, what the LCD shows (they name `wifi`'s store
//!   and errors).
//! * [`local`]: the Basic's own commands (`io`, `status`, `wifi`).
//! * [`router`]: the host links, the turn on the bus, and where a reply goes (`host_link`,
//!   `request`, `wifi`'s text capture).
//! * [`forwarder`]: one request at a time on the bus, and how the Basic hears it (`config`,
//!   `request`).
//! * [`transparent`]: raw bytes both ways (`forwarder`'s rule for a free wire).
//! * `supervisor`: watches what becomes of requests for the status, and keeps the Atom's
//!   power and the probe's timing (`config`, `forwarder`'s events, `io`, `request`,
//!   `status`); it decides nothing about where a reply goes.
//! * [`Basic`] (`basic`): owns one of each and runs them in [`Basic::poll`].
//! * [`clients`]: the network clients over a [`Basic`] (`basic`, `host_link`, `io`,
//!   `request`, `router`'s [`HostPorts`]).
//!
//! How the ports are used, for whoever implements them: the Basic reads with
//! [`BytePort::read_byte`](protocol_core::BytePort::read_byte) / [`HostPorts::read_from`]
//! until it returns `None` (at most [`BUS_READ_BUDGET`] bus and [`host_link::HOST_READ_BUDGET`]
//! bytes per host link per poll), and writes only into an idle transmitter, at most 67 bytes
//! to the bus and 64 to a host link at a time (a reply passed on as it arrives: 64 since the
//! link's transmitter was last idle), so a write never waits on a 128-byte UART FIFO. Timing
//! comes only from `now_us`.
//!
//! Latency (bench `latency`, virtual time): the Basic adds one poll period host -> bus on an
//! idle wire, beyond the frame's own wire time; bus -> host its reply is on its way before it
//! has ended on the bus (cut-through). Several clients (bench `router`): no
//! reply crossed or lost, the bus shared round robin.
#![cfg_attr(not(test), no_std)]
#![forbid(unsafe_code)]

mod basic;
pub mod clients;
pub mod config;
pub mod dialect;
pub mod forwarder;
pub mod host_link;
pub mod io;
pub mod local;
pub mod program;
pub mod request;
pub mod router;
pub mod status;
mod supervisor;
pub mod teach;
pub mod transparent;
pub mod wifi;

pub use basic::{BUS_READ_BUDGET, Basic};
pub use clients::{NetClient, NetworkClients};
pub use config::{BasicConfig, ConfigError, EchoMode};
pub use dialect::DialectStore;
pub use host_link::LinkKind;
pub use io::{BasicIo, Buttons, NullIo};
pub use program::{Arm, Program, Programmed};
pub use request::{LinkId, MAX_HOST_LINKS};
pub use router::{HostPorts, LinksFull};
pub use status::{AtomLink, BasicError, BasicStatus, TransponderMode};
