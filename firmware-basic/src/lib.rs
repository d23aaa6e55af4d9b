//! The myCobot 280 M5 Basic firmware: the transponder between the host's USB serial (115200)
//! and the arm's shared 1 Mbaud bus, as a host-tested library of poll-driven state machines.
//!
//! The Basic makes the arm feel like one device: every host request reaches the Atom once,
//! every reply reaches the host once, and nothing else leaks (servo packets, its own echo,
//! replies to its internal requests). The board layer (esp-hal binary) binds [`BasicIo`] and
//! two [`BytePort`]s and calls [`Basic::poll`] in a tight loop.
//!
//! * [`local`]: the commands the Basic answers itself (0xA0, 0xA1, 0xB0..0xB2, 0xC0..0xC3),
//!   at once, even while the Atom is silent.
//! * [`forwarder`]: everything else goes onto the bus, one request at a time, into a quiet
//!   wire, echo checked, collisions retried; only the matching reply comes back.
//! * [`transparent`]: raw bytes both ways after 0xC2 1, until `FE FE 03 C2 00 FA`.
//! * At boot the Basic powers the Atom on (0x10, like the vendor transponder) and afterwards
//!   probes it (0x12) whenever it has been silent for a while; the replies to these internal
//!   requests never reach the host. Button A powers the Atom on again.
#![cfg_attr(not(test), no_std)]
#![forbid(unsafe_code)]

pub mod config;
pub mod forwarder;
pub mod host_link;
pub mod io;
pub mod local;
pub mod status;
pub mod transparent;

pub use config::{BasicConfig, EchoMode};
pub use io::{BasicIo, Buttons, NullIo};
pub use status::{AtomLink, BasicError, BasicStatus, TransponderMode};

use forwarder::{Event, Forwarder, Origin, Request};
use host_link::{HOST_READ_BUDGET, HostLink};
use protocol_core::{BytePort, Frame};
use transparent::Transparent;

/// Most bus bytes taken per poll: a poll stays short, and 256 bytes is 2.5 ms of bus time,
/// far more than arrives between two polls of a board's loop.
pub const BUS_READ_BUDGET: usize = 256;

/// Atom command codes the transponder itself uses or watches.
mod atom_cmd {
    /// Power on: torque on, servos ready.
    pub const POWER_ON: u8 = 0x10;
    /// Power off.
    pub const POWER_OFF: u8 = 0x11;
    /// Is powered on: 1 byte.
    pub const IS_POWERED_ON: u8 = 0x12;
    /// Release all servos.
    pub const RELEASE_ALL_SERVOS: u8 = 0x13;
}

/// The Basic's transponder: one per board, polled forever.
#[derive(Debug)]
pub struct Basic {
    config: BasicConfig,
    status: BasicStatus,
    host: HostLink,
    forwarder: Forwarder,
    transparent: Transparent,
    /// The first poll (the Basic's boot) has happened.
    booted: bool,
    /// The boot power-on (0x10) has not been answered yet.
    power_on_pending: bool,
    /// Earliest time of the next internal request.
    next_internal_us: u64,
    /// When the Atom last answered anything.
    last_answer_us: u64,
    buttons: Buttons,
}

impl Basic {
    /// A transponder that has just been powered up.
    pub fn new(config: BasicConfig) -> Self {
        Self {
            config,
            status: BasicStatus {
                version_x10: config.version_x10,
                ..BasicStatus::default()
            },
            host: HostLink::new(),
            forwarder: Forwarder::new(),
            transparent: Transparent::default(),
            booted: false,
            power_on_pending: config.power_on_at_boot,
            next_internal_us: 0,
            last_answer_us: 0,
            buttons: Buttons::default(),
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
            self.forwarder.note_activity(now_us);
            self.last_answer_us = now_us;
            self.next_internal_us = now_us.saturating_add(self.config.boot_power_on_delay_us);
        }
        self.read_bus(now_us, bus);
        self.read_host(now_us, host, io);
        match self.status.mode {
            TransponderMode::Framed => {
                self.schedule_internal(now_us, io);
                let mut events: heapless::Vec<Event, 4> = heapless::Vec::new();
                self.forwarder.poll(now_us, bus, &self.config, |e| {
                    let _ = events.push(e);
                });
                for event in events {
                    self.on_event(now_us, event);
                }
            }
            TransponderMode::Transparent => {
                let quiet_us = self.forwarder.quiet_for_us(now_us);
                let echo = self.echo_expected();
                self.transparent.poll(now_us, quiet_us, bus, echo);
            }
        }
        self.host.flush(host);
    }

    /// What the LCD shows.
    pub fn status(&self) -> BasicStatus {
        BasicStatus {
            echo_heard: self.forwarder.echo_heard(),
            ..self.status
        }
    }

    /// Whether the Basic should expect its own bytes back from the bus.
    fn echo_expected(&self) -> bool {
        match self.config.echo {
            EchoMode::Present => true,
            EchoMode::Absent => false,
            EchoMode::Auto => self.forwarder.echo_heard() == Some(true),
        }
    }

    fn read_bus<B: BytePort>(&mut self, now_us: u64, bus: &mut B) {
        for _ in 0..BUS_READ_BUDGET {
            let Some(byte) = bus.read_byte() else {
                break;
            };
            match self.status.mode {
                TransponderMode::Framed => {
                    let mut events: heapless::Vec<Event, 2> = heapless::Vec::new();
                    self.forwarder.on_bus_byte(now_us, byte, &self.config, |e| {
                        let _ = events.push(e);
                    });
                    for event in events {
                        self.on_event(now_us, event);
                    }
                }
                TransponderMode::Transparent => {
                    self.forwarder.note_activity(now_us);
                    if let Some(b) = self.transparent.bus_byte(byte)
                        && !self.host.send_bytes(&[b])
                    {
                        self.status.last_error = Some(BasicError::HostOverflow);
                    }
                }
            }
        }
    }

    fn read_host<H: BytePort, I: BasicIo>(&mut self, now_us: u64, host: &mut H, io: &mut I) {
        for _ in 0..HOST_READ_BUDGET {
            let Some(byte) = self.host.read_byte(now_us, host) else {
                break;
            };
            match self.status.mode {
                TransponderMode::Framed => {
                    let mut frames: heapless::Vec<Frame, 2> = heapless::Vec::new();
                    self.host.frame_byte(byte, |f| {
                        let _ = frames.push(f);
                    });
                    for frame in frames {
                        self.on_host_frame(now_us, frame, io);
                    }
                }
                TransponderMode::Transparent => {
                    if self.transparent.host_byte(byte) {
                        self.leave_transparent();
                    }
                }
            }
        }
        let quiet_us = self.host.quiet_for_us(now_us);
        match self.status.mode {
            TransponderMode::Framed => {
                let mut frames: heapless::Vec<Frame, 2> = heapless::Vec::new();
                self.host.check_gap(now_us, |f| {
                    let _ = frames.push(f);
                });
                for frame in frames {
                    self.on_host_frame(now_us, frame, io);
                }
            }
            TransponderMode::Transparent => self.transparent.host_quiet(quiet_us),
        }
    }

    fn on_host_frame<I: BasicIo>(&mut self, _now_us: u64, frame: Frame, io: &mut I) {
        self.status.host_frames = self.status.host_frames.wrapping_add(1);
        if self.status.mode == TransponderMode::Transparent {
            // A second frame completed by the same byte after an exit: forward it raw.
            for &b in frame.to_bytes().iter() {
                if self.transparent.host_byte(b) {
                    self.leave_transparent();
                }
            }
            return;
        }
        if let Some(answer) = local::answer(&frame, io, self.config.version_x10, self.status.mode) {
            let sent = match &answer.reply {
                local::Reply::Frame(reply) => self.host.send_frame(reply),
                local::Reply::Raw(bytes) => self.host.send_bytes(bytes),
            };
            if !sent {
                self.status.last_error = Some(BasicError::HostOverflow);
            }
            if let Some(error) = answer.error {
                self.status.last_error = Some(error);
            }
            if answer.new_mode == Some(TransponderMode::Transparent) {
                self.enter_transparent();
            }
            return;
        }
        let cmd = frame.cmd();
        if matches!(cmd, atom_cmd::POWER_OFF | atom_cmd::RELEASE_ALL_SERVOS) {
            // The host has taken charge of the arm's power: do not power it on behind its back.
            self.power_on_pending = false;
        }
        let request = Request {
            frame,
            origin: Origin::Host,
        };
        if self.forwarder.enqueue(request).is_err() {
            self.status.last_error = Some(BasicError::QueueFull { cmd });
        }
    }

    fn enter_transparent(&mut self) {
        self.status.mode = TransponderMode::Transparent;
        self.forwarder.clear();
        self.host.reset_framer();
        self.transparent = Transparent::default();
    }

    fn leave_transparent(&mut self) {
        self.status.mode = TransponderMode::Framed;
        self.host.reset_framer();
        self.transparent = Transparent::default();
        // Cannot fail to build: one data byte.
        let ack = Frame::new(local::code::SET_TRANSPONDER_MODE, &[1]).unwrap_or_default();
        if !self.host.send_frame(&ack) {
            self.status.last_error = Some(BasicError::HostOverflow);
        }
    }

    /// Powers the Atom on after boot and probes it when it has been silent for a while.
    fn schedule_internal<I: BasicIo>(&mut self, now_us: u64, io: &mut I) {
        let buttons = io.buttons();
        if buttons.a && !self.buttons.a {
            self.power_on_pending = true;
            self.next_internal_us = now_us;
        }
        self.buttons = buttons;
        if self.forwarder.busy() || now_us < self.next_internal_us {
            return;
        }
        let interval_us = self.config.probe_interval_us;
        let (cmd, origin) = if self.power_on_pending {
            (atom_cmd::POWER_ON, Origin::PowerOn)
        } else if interval_us > 0 && now_us.saturating_sub(self.last_answer_us) >= interval_us {
            (atom_cmd::IS_POWERED_ON, Origin::Probe)
        } else {
            return;
        };
        if interval_us == 0 && origin == Origin::PowerOn {
            // Without probing, the power-on is tried once.
            self.power_on_pending = false;
        }
        self.next_internal_us = now_us.saturating_add(interval_us.max(1));
        // Cannot fail: no data; the queue is empty (not busy).
        let frame = Frame::new(cmd, &[]).unwrap_or_default();
        let _ = self.forwarder.enqueue(Request { frame, origin });
    }

    fn on_event(&mut self, now_us: u64, event: Event) {
        let status = &mut self.status;
        match event {
            Event::Reply { request, reply } => {
                status.atom = AtomLink::Answering;
                self.last_answer_us = now_us;
                let done = reply.data() == [1];
                match (request.frame.cmd(), reply.data()) {
                    (atom_cmd::POWER_ON, _) if done => {
                        status.atom_powered = Some(true);
                        self.power_on_pending = false;
                    }
                    (atom_cmd::POWER_OFF, _) if done => status.atom_powered = Some(false),
                    (atom_cmd::IS_POWERED_ON, &[state]) => status.atom_powered = Some(state == 1),
                    _ => {}
                }
                if request.origin == Origin::Host {
                    if self.host.send_frame(&reply) {
                        status.replies_forwarded = status.replies_forwarded.wrapping_add(1);
                    } else {
                        status.last_error = Some(BasicError::HostOverflow);
                    }
                }
            }
            Event::Timeout(request) => {
                status.atom = AtomLink::Silent;
                status.timeouts = status.timeouts.wrapping_add(1);
                status.last_error = Some(BasicError::ReplyTimeout {
                    cmd: request.frame.cmd(),
                });
            }
            Event::GaveUp(request) => {
                status.collisions = status.collisions.wrapping_add(1);
                status.last_error = Some(BasicError::BusCollisions {
                    cmd: request.frame.cmd(),
                });
            }
            Event::Collision => status.collisions = status.collisions.wrapping_add(1),
            Event::Unsolicited => {}
        }
    }
}
