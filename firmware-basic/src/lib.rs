//! The myCobot 280 M5 Basic firmware: the transponder between the host's USB serial (115200)
//! and the arm's shared 1 Mbaud bus, as a host-tested library of poll-driven state machines.
//!
//! The Basic makes the arm feel like one device: every host request reaches the Atom once,
//! every reply reaches the host once, and nothing else leaks (servo packets, its own echo,
//! replies to its internal requests). The board layer (esp-hal binary) and the virtual robot
//! bind [`BasicIo`] and two [`BytePort`]s and call [`Basic::poll`] in a tight loop.
//!
//! * [`local`]: the commands the Basic answers itself (0xA0, 0xA1, 0xB0..0xB2, 0xC0..0xC3),
//!   at once, even while the Atom is silent or a flood fills the queue. The Basic has no Wi-Fi:
//!   0xB0/0xB2 are refused with `00`, 0xB1 reports empty credentials in the text form
//!   pymycobot parses.
//! * [`forwarder`]: everything else goes onto the bus, one request at a time, into a quiet
//!   wire, echo checked (heard or not: [`EchoMode::Auto`] finds out on the first send),
//!   collisions and garbled replies retried; only the reply with the request's CMD comes back,
//!   and a request the Atom does not answer is given up after
//!   [`BasicConfig::reply_timeout_us`] (below pymycobot's 0.5 s resend).
//! * [`transparent`]: after `0xC2 01` raw bytes go both ways (the Basic's echo removed),
//!   until the host sends exactly `FE FE 03 C2 00 FA`; only that and the exact mode frames
//!   `FE FE 03 C2 01 FA` and `FE FE 02 C3 FA` are still answered by the Basic then.
//! * [`host_link`]: framing of the host stream (a frame cut by a 2 ms gap is dropped) and a
//!   bounded output queue written only into an idle transmitter, so `poll` never blocks.
//! * Both links are heard through `protocol_core`'s timed [`Listener`]: the host link for its
//!   frames, the bus (one listener for framed and transparent mode) for the Atom's replies,
//!   raw bytes, the Basic's own echo and how quiet the wire is.
//! * At boot the Basic powers the Atom on (0x10, like the vendor transponder) and afterwards
//!   probes it (0x12) whenever it has been silent for [`BasicConfig::probe_interval_us`]; the
//!   replies to these internal requests never reach the host, they feed [`Basic::status`]
//!   (what the LCD shows). Button A powers the Atom on again.
//!
//! How the ports are used, for whoever implements them: the Basic reads with
//! [`BytePort::read_byte`] until it returns `None` (at most [`BUS_READ_BUDGET`] bus and
//! [`host_link::HOST_READ_BUDGET`] host bytes per poll), and writes only into an idle
//! transmitter ([`BytePort::tx_idle`]), at most 67 bytes to the bus and 64 to the host at a
//! time, so a write never waits on a 128-byte UART FIFO. Timing comes only from `now_us`.
//!
//! Latency (bench `latency`, virtual time): the Basic adds one poll period to each direction
//! on an idle wire, beyond the frame's own wire time.
#![cfg_attr(not(test), no_std)]
#![forbid(unsafe_code)]

pub mod config;
pub mod forwarder;
pub mod host_link;
pub mod io;
pub mod local;
pub mod status;
mod supervisor;
pub mod transparent;
pub mod wifi;

pub use config::{BasicConfig, ConfigError, EchoMode};
pub use io::{BasicIo, Buttons, NullIo};
pub use status::{AtomLink, BasicError, BasicStatus, TransponderMode};

use forwarder::{Forwarder, Origin, Request};
use host_link::{HOST_READ_BUDGET, HostFrames, HostLink};
use protocol_core::command::{Reply, cmd};
use protocol_core::listener::{Listener, ListenerConfig};
use protocol_core::{BytePort, Frame};
use supervisor::Supervisor;
use transparent::{Intercepted, Transparent};

/// Most bus bytes taken per poll: a poll stays short, and 256 bytes is 2.5 ms of bus time,
/// far more than arrives between two polls of a board's loop.
pub const BUS_READ_BUDGET: usize = 256;

/// How the Basic hears the bus: host frames (the Atom's replies) and every byte that is not its
/// own echo (transparent mode passes them on, and they show a reply that began garbled);
/// servo packets are none of its business.
fn bus_listener(echo: EchoMode) -> Listener {
    Listener::new(
        ListenerConfig::new()
            .with_packets(false)
            .with_bytes(true)
            .with_echo(echo),
    )
}

/// The Basic's transponder: one per board, polled forever.
#[derive(Debug)]
pub struct Basic {
    config: BasicConfig,
    mode: TransponderMode,
    host: HostLink,
    /// The bus as the Basic hears it, lent to the forwarder or the transparent pipe.
    bus: Listener,
    forwarder: Forwarder,
    transparent: Transparent,
    supervisor: Supervisor,
    /// The first poll (the Basic's boot) has happened.
    booted: bool,
}

impl Basic {
    /// A transponder that has just been powered up. `config` should have passed
    /// [`BasicConfig::validate`]; an invalid one still never panics (0 send attempts act as 1).
    pub fn new(config: BasicConfig) -> Self {
        Self {
            config,
            mode: TransponderMode::Framed,
            host: HostLink::new(),
            bus: bus_listener(config.echo),
            forwarder: Forwarder::new(),
            transparent: Transparent::default(),
            supervisor: Supervisor::new(&config),
            booted: false,
        }
    }

    /// Does all pending work at time `now_us` (monotonic microseconds): reads what arrived on
    /// the host link and the bus, answers or forwards, checks deadlines. Never blocks; call it
    /// often (every few microseconds of bus time) and whenever bytes arrive.
    pub fn poll<H: BytePort, B: BytePort, I: BasicIo>(
        &mut self,
        now_us: u64,
        host: &mut H,
        bus: &mut B,
        io: &mut I,
    ) {
        if !self.booted {
            self.booted = true;
            // Whatever the wire was doing before we booted, give it a quiet time first.
            self.bus.assume_busy_until(now_us);
            self.supervisor.boot(now_us, &self.config);
        }
        self.read_bus(now_us, bus);
        self.read_host(now_us, host, io);
        match self.mode {
            TransponderMode::Framed => {
                let idle = !self.forwarder.busy();
                if let Some(request) =
                    self.supervisor
                        .next_internal(now_us, &self.config, io.buttons(), idle)
                {
                    // Cannot fail: the queue is empty.
                    let _ = self.forwarder.enqueue(request);
                }
                let room_for_reply = self.host.has_room_for_frame();
                let (supervisor, link) = (&mut self.supervisor, &mut self.host);
                self.forwarder.poll(
                    now_us,
                    bus,
                    &mut self.bus,
                    &self.config,
                    room_for_reply,
                    |e| supervisor.on_event(now_us, e, link),
                );
            }
            TransponderMode::Transparent => {
                let (supervisor, link) = (&mut self.supervisor, &mut self.host);
                self.transparent.poll(now_us, bus, &mut self.bus, |b| {
                    send_raw(link, supervisor, b)
                });
            }
        }
        self.host.flush(host);
    }

    /// What the LCD shows.
    pub fn status(&self) -> BasicStatus {
        BasicStatus {
            mode: self.mode,
            echo_heard: self.bus.echo_heard(),
            transparent_dropped: self.transparent.dropped,
            ..self.supervisor.status
        }
    }

    fn read_bus<B: BytePort>(&mut self, now_us: u64, bus: &mut B) {
        for _ in 0..BUS_READ_BUDGET {
            let Some(byte) = bus.read_byte() else {
                break;
            };
            let (supervisor, link) = (&mut self.supervisor, &mut self.host);
            match self.mode {
                TransponderMode::Framed => {
                    self.forwarder
                        .on_bus_byte(now_us, byte, &mut self.bus, &self.config, |e| {
                            supervisor.on_event(now_us, e, link)
                        });
                }
                TransponderMode::Transparent => {
                    Transparent::bus_byte(now_us, byte, &mut self.bus, |b| {
                        send_raw(link, supervisor, b)
                    });
                }
            }
        }
    }

    fn read_host<H: BytePort, I: BasicIo>(&mut self, now_us: u64, host: &mut H, io: &mut I) {
        for _ in 0..HOST_READ_BUDGET {
            let mut frames = HostFrames::new();
            let Some(byte) = self.host.read_byte(now_us, host, &mut frames) else {
                break;
            };
            match self.mode {
                TransponderMode::Framed => {
                    for frame in frames.drain(..) {
                        self.on_host_frame(now_us, frame, io);
                    }
                }
                TransponderMode::Transparent => {
                    if let Some(hit) = self.transparent.host_byte(byte) {
                        self.on_intercepted(hit);
                    }
                }
            }
        }
        match self.mode {
            TransponderMode::Framed => {
                let mut frames = HostFrames::new();
                self.host.check_gap(now_us, &mut frames);
                if !frames.is_empty() {
                    for frame in frames.drain(..) {
                        self.on_host_frame(now_us, frame, io);
                    }
                }
            }
            TransponderMode::Transparent => {
                self.transparent.host_quiet(self.host.quiet_for_us(now_us));
            }
        }
    }

    fn on_host_frame<I: BasicIo>(&mut self, now_us: u64, frame: Frame, io: &mut I) {
        if self.mode == TransponderMode::Transparent {
            // A frame completed by the same byte as the one that entered transparent mode:
            // it is raw data now.
            for &b in frame.to_bytes().iter() {
                if let Some(hit) = self.transparent.host_byte(b) {
                    self.on_intercepted(hit);
                }
            }
            return;
        }
        let cmd = frame.cmd();
        self.supervisor.on_host_request(cmd);
        if let Some(answer) = local::answer(&frame, io, self.config.version_x10, self.mode) {
            let sent = match &answer.reply {
                local::Reply::Frame(reply) => self.host.send_frame(reply),
                local::Reply::Raw(bytes) => self.host.send_bytes(bytes),
            };
            if !sent {
                self.supervisor.error(BasicError::HostOverflow);
            }
            if let Some(error) = answer.error {
                self.supervisor.error(error);
            }
            if answer.new_mode == Some(TransponderMode::Transparent) {
                self.enter_transparent();
            }
            return;
        }
        let request = Request {
            frame,
            origin: Origin::Host,
            queued_us: now_us,
        };
        if self.forwarder.enqueue(request).is_err() {
            self.supervisor.error(BasicError::QueueFull { cmd });
        }
    }

    fn enter_transparent(&mut self) {
        self.mode = TransponderMode::Transparent;
        self.forwarder.clear();
        self.bus.drop_partials();
        self.host.reset_framer();
        self.transparent = Transparent::default();
    }

    /// Answers a frame the Basic still handles in transparent mode. Raw traffic still queued
    /// for the host is dropped so the answer is not lost behind a backlog of bus bytes.
    fn on_intercepted(&mut self, hit: Intercepted) {
        self.host.clear_tx();
        let reply = match hit {
            Intercepted::SetFramed => {
                self.mode = TransponderMode::Framed;
                self.host.reset_framer();
                self.transparent = Transparent::default();
                Reply::Ack.to_frame(cmd::SET_TRANSPONDER_MODE)
            }
            Intercepted::SetTransparent => Reply::Ack.to_frame(cmd::SET_TRANSPONDER_MODE),
            Intercepted::GetMode => {
                Reply::Byte(TransponderMode::Transparent as u8).to_frame(cmd::GET_TRANSPONDER_MODE)
            }
        };
        if !self.host.send_frame(&reply) {
            self.supervisor.error(BasicError::HostOverflow);
        }
    }
}

/// Queues one raw byte for the host, noting an overflow.
fn send_raw(host: &mut HostLink, supervisor: &mut Supervisor, byte: u8) {
    if !host.send_raw(byte) {
        supervisor.error(BasicError::HostOverflow);
    }
}
