//! The Basic's transponder as one value: [`Basic`] owns the parts (the host links' router,
//! the bus forwarder, the transparent pipe, the supervisor, the Wi-Fi) and its
//! [`Basic::poll`] runs them in order: read the bus, read the host links, write waiting Wi-Fi
//! settings, forward or pass raw bytes, flush the host links. See the [crate doc](crate) for
//! what a client sees.

use protocol_core::command::{Reply, cmd, is_basic_local};
use protocol_core::dialect;
use protocol_core::listener::Listener;
use protocol_core::{BytePort, Frame};

use crate::config::BasicConfig;
use crate::dialect::DialectSetting;
use crate::forwarder::{self, Event, Forwarder};
use crate::host_link::{HOST_READ_BUDGET, HostFrames, LinkKind};
use crate::io::BasicIo;
use crate::local;
use crate::request::{Client, LinkId, MAX_HOST_LINKS, Origin};
use crate::router::{HostPorts, LinksFull, Router};
use crate::status::{BasicError, BasicStatus, TransponderMode};
use crate::supervisor::Supervisor;
use crate::transparent::{Intercepted, Transparent};
use crate::wifi::{self, SettingsChange, SettingsWrites, Wifi, WifiStatus};

/// Most bus bytes taken per poll: a poll stays short, and 256 bytes is 2.5 ms of bus time,
/// far more than arrives between two polls of a board's loop.
pub const BUS_READ_BUDGET: usize = 256;

/// What the bus carries.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
enum Mode {
    /// Host frames, one request at a time, for every link.
    Framed,
    /// Raw bytes between the bus and `owner`, the link that switched (once the request that
    /// was on the bus then has been answered).
    Transparent { owner: LinkId },
}

/// The Basic's transponder: one per board, polled forever.
#[derive(Debug)]
pub struct Basic {
    config: BasicConfig,
    mode: Mode,
    router: Router,
    /// The bus as the Basic hears it, lent to the forwarder or the transparent pipe.
    bus: Listener,
    forwarder: Forwarder,
    transparent: Transparent,
    supervisor: Supervisor,
    /// The first poll (the Basic's boot) has happened.
    booted: bool,
    /// The dialect the clients speak.
    dialect: DialectSetting,
    /// The Wi-Fi, on a board that lends a settings store (from the first poll on).
    wifi: Option<Wifi>,
    /// Wi-Fi settings changes waiting for a quiet bus (at most one per link: a client waits
    /// for its answer).
    wifi_writes: SettingsWrites<Client, MAX_HOST_LINKS>,
}

impl Basic {
    /// A transponder that has just been powered up, with only its USB link open. `config`
    /// should have passed [`BasicConfig::validate`]; an invalid one still never panics (0 send
    /// attempts act as 1).
    pub fn new(config: BasicConfig) -> Self {
        Self {
            config,
            mode: Mode::Framed,
            router: Router::new(),
            bus: forwarder::bus_listener(config.echo),
            forwarder: Forwarder::new(),
            transparent: Transparent::default(),
            supervisor: Supervisor::new(&config),
            booted: false,
            dialect: DialectSetting::new(),
            wifi: None,
            wifi_writes: SettingsWrites::new(),
        }
    }

    /// The Wi-Fi (settings and station), on a board that lends a settings store
    /// ([`BasicIo::wifi_store`]), from the first poll on.
    pub fn wifi(&self) -> Option<&Wifi> {
        self.wifi.as_ref()
    }

    /// The Wi-Fi, for the board's network layer: it feeds the station the driver's events
    /// ([`Wifi::on_event`]) and carries out its actions ([`Wifi::poll`]).
    pub fn wifi_mut(&mut self) -> Option<&mut Wifi> {
        self.wifi.as_mut()
    }

    /// What the LCD shows about Wi-Fi, with `clients` network clients connected; `None` on a
    /// board without Wi-Fi.
    pub fn wifi_status(&self, clients: u8) -> Option<WifiStatus> {
        self.wifi.as_ref().map(|w| w.status(clients))
    }

    /// Opens a host link for a new client of `kind` (a TCP connection: [`LinkKind::Network`]),
    /// with its own framer, queue and turn on the bus. [`LinksFull`] if [`MAX_HOST_LINKS`]
    /// links are open: the transport turns the client away.
    pub fn open_link(&mut self, kind: LinkKind) -> Result<LinkId, LinksFull> {
        self.router.open(kind)
    }

    /// Closes `link`, whose client has gone: its partial frame, waiting requests and queued
    /// output are dropped, and the reply to its request on the bus (if any) will be too. If it
    /// had switched the bus to transparent mode, the bus is framed again. Closing the USB link
    /// (always open) starts it afresh.
    pub fn close_link(&mut self, link: LinkId) {
        self.router.close(link);
        if self.mode == (Mode::Transparent { owner: link }) {
            self.leave_transparent();
        }
    }

    /// Does all pending work at time `now_us` (monotonic microseconds): reads what arrived on
    /// the host links and the bus, answers or forwards, checks deadlines. Never blocks; call it
    /// often (every few microseconds of bus time) and whenever bytes arrive. `hosts` are the
    /// host links' ports: a single [`BytePort`] is the USB link alone.
    pub fn poll<H: HostPorts, B: BytePort, I: BasicIo>(
        &mut self,
        now_us: u64,
        hosts: &mut H,
        bus: &mut B,
        io: &mut I,
    ) {
        if !self.booted {
            self.booted = true;
            // Whatever the wire was doing before we booted, give it a quiet time first.
            self.bus.assume_busy_until(now_us);
            self.supervisor.boot(now_us, &self.config);
            self.wifi = io.wifi_store().map(|store| Wifi::start(now_us, store));
            self.dialect.boot(self.config.dialect, io.dialect_store());
            self.router.set_dialect(self.dialect.get());
        }
        self.read_bus(now_us, bus);
        self.read_hosts(now_us, hosts, io);
        self.write_wifi_settings(now_us, io);
        let buttons = io.buttons();
        if self.dialect.on_button(now_us, buttons.c) {
            self.router.set_dialect(self.dialect.get());
        }
        let quiet = self.forwarder.idle() && !self.router.has_requests();
        if let Some(Err(_)) = self.dialect.save_when_quiet(quiet, io.dialect_store()) {
            self.supervisor.error(BasicError::SettingNotSaved);
        }
        match self.mode {
            Mode::Transparent { owner } if self.forwarder.idle() => {
                let (supervisor, router) = (&mut self.supervisor, &mut self.router);
                self.transparent.poll(now_us, bus, &mut self.bus, |b| {
                    send_raw(router, owner, supervisor, b)
                });
            }
            mode => {
                let (supervisor, router) = (&mut self.supervisor, &mut self.router);
                self.forwarder
                    .on_time(now_us, bus, &mut self.bus, &self.config, |e| {
                        deliver(now_us, e, supervisor, router)
                    });
                // The Basic's own requests only on a framed bus nobody else is using.
                let idle =
                    mode == Mode::Framed && self.forwarder.idle() && !self.router.has_requests();
                let internal = self
                    .supervisor
                    .next_internal(now_us, &self.config, buttons, idle);
                // A settings change waiting for the quiet bus goes first.
                if mode == Mode::Framed && self.forwarder.idle() && self.wifi_writes.is_empty() {
                    let (supervisor, router) = (&mut self.supervisor, &mut self.router);
                    let next = internal.or_else(|| {
                        // An expired request has no reply to give.
                        router.next_request(now_us, |expired| {
                            supervisor.on_event(now_us, &Event::Expired(expired));
                        })
                    });
                    if let Some(request) = next {
                        self.forwarder.start(request);
                    }
                }
                self.forwarder.try_send(now_us, bus, &mut self.bus);
                // Nothing to send: hold the bus for a request about to be in.
                let coming = mode == Mode::Framed
                    && self.forwarder.idle()
                    && !self.router.has_requests()
                    && self.wifi_writes.is_empty()
                    && self.router.request_coming(now_us);
                self.forwarder
                    .hold(now_us, bus, &mut self.bus, coming, &self.config);
            }
        }
        self.router.flush(hosts);
    }

    /// What the LCD shows.
    pub fn status(&self) -> BasicStatus {
        BasicStatus {
            mode: match self.mode {
                Mode::Framed => TransponderMode::Framed,
                Mode::Transparent { .. } => TransponderMode::Transparent,
            },
            echo_heard: self.bus.echo_heard(),
            dialect: self.dialect.get(),
            transparent_dropped: self.transparent.dropped,
            ..self.supervisor.status
        }
    }

    fn read_bus<B: BytePort>(&mut self, now_us: u64, bus: &mut B) {
        for _ in 0..BUS_READ_BUDGET {
            let Some(byte) = bus.read_byte() else {
                break;
            };
            let (supervisor, router) = (&mut self.supervisor, &mut self.router);
            match self.mode {
                Mode::Transparent { owner } if self.forwarder.idle() => {
                    Transparent::bus_byte(now_us, byte, &mut self.bus, |b| {
                        send_raw(router, owner, supervisor, b)
                    });
                }
                _ => {
                    self.forwarder
                        .on_bus_byte(now_us, byte, &mut self.bus, &self.config, |e| {
                            deliver(now_us, e, supervisor, router)
                        });
                }
            }
        }
    }

    fn read_hosts<H: HostPorts, I: BasicIo>(&mut self, now_us: u64, hosts: &mut H, io: &mut I) {
        for link in self.router.open_links() {
            self.read_host(now_us, hosts, link, io);
        }
    }

    /// Reads what arrived on `link` (at most [`HOST_READ_BUDGET`] bytes) and acts on it.
    fn read_host<H: HostPorts, I: BasicIo>(
        &mut self,
        now_us: u64,
        hosts: &mut H,
        link: LinkId,
        io: &mut I,
    ) {
        for _ in 0..HOST_READ_BUDGET {
            let mut frames = HostFrames::new();
            let Some(byte) = self.router.read_byte(now_us, hosts, link, &mut frames) else {
                break;
            };
            if self.is_owner(link) {
                if let Some(hit) = self.transparent.host_byte(byte) {
                    self.on_intercepted(link, hit);
                }
            } else {
                for frame in frames.drain(..) {
                    self.on_host_frame(now_us, link, frame, io);
                }
                self.router.adopt_dialect(link);
            }
        }
        if self.is_owner(link) {
            let quiet_us = self.router.quiet_for_us(now_us, link);
            self.transparent.host_quiet(quiet_us);
        } else {
            if let Some(end) = self.router.poll_capture(now_us, link) {
                self.queue_wifi_write(now_us, link, SettingsChange::Text(end));
            }
            let mut frames = HostFrames::new();
            self.router.check_gap(now_us, link, &mut frames);
            for frame in frames.drain(..) {
                self.on_host_frame(now_us, link, frame, io);
            }
            self.router.adopt_dialect(link);
        }
    }

    /// True if `link` switched the bus to transparent mode: its bytes are raw.
    fn is_owner(&self, link: LinkId) -> bool {
        self.mode == (Mode::Transparent { owner: link })
    }

    fn on_host_frame<I: BasicIo>(&mut self, now_us: u64, link: LinkId, frame: Frame, io: &mut I) {
        if self.is_owner(link) {
            // A frame completed by the same byte as the one that entered transparent mode:
            // it is raw data now.
            for &b in frame.to_bytes().iter() {
                if let Some(hit) = self.transparent.host_byte(b) {
                    self.on_intercepted(link, hit);
                }
            }
            return;
        }
        // The client's dialect ends here: the rest of the Basic, and the Atom, read pymycobot's.
        let dialect = self.router.link_dialect(link);
        let dialect::Translated { frame, answer } = dialect.translate(&frame);
        let code = frame.cmd();
        if let Mode::Transparent { .. } = self.mode {
            // The bus is another client's: the Basic's own commands are still answered (0xC3
            // says why the rest is not), 0xC2 is that client's to send.
            if code == cmd::SET_TRANSPONDER_MODE {
                if let Some(refusal) = dialect::refusal(dialect, code) {
                    self.send_frame(link, &refusal);
                }
                return;
            }
            if !is_basic_local(code) {
                self.supervisor
                    .error(BasicError::TransparentElsewhere { cmd: code });
                return;
            }
        }
        self.supervisor.on_host_request(code);
        if self.wifi.is_some() && wifi::writes_settings(&frame) {
            self.queue_wifi_write(now_us, link, SettingsChange::Frame(frame));
            return;
        }
        if let Some(local) = local::answer(&frame, io, self.local_context(now_us)) {
            let answer = local.in_dialect(answer);
            self.send_answer(link, &answer);
            if let Some(new) = answer.new_dialect
                && self.dialect.set(new)
            {
                self.router.set_dialect(new);
            }
            if answer.capture_text {
                self.router.start_capture(now_us, link);
            }
            if answer.new_mode == Some(TransponderMode::Transparent) && self.mode == Mode::Framed {
                self.enter_transparent(link);
            }
            return;
        }
        let Some(client) = self.router.client(link) else {
            return;
        };
        if self.router.push(client, frame, answer, now_us).is_err() {
            self.supervisor.error(BasicError::QueueFull { cmd: code });
        }
    }

    /// What the Basic's own commands read or change, at `now_us`.
    fn local_context(&mut self, now_us: u64) -> local::Context<'_> {
        local::Context {
            version_x10: self.config.version_x10,
            mode: self.status().mode,
            dialect: self.dialect.get(),
            wifi: self.wifi.as_mut(),
            now_us,
        }
    }

    /// Queues the answer to one of the Basic's own commands for `link`, noting what went wrong.
    fn send_answer(&mut self, link: LinkId, answer: &local::LocalAnswer) {
        let sent = match &answer.body {
            local::AnswerBody::Frame(frame) => self.router.send_frame(link, frame),
            local::AnswerBody::Text(bytes) => self.router.send_bytes(link, bytes),
            local::AnswerBody::Nothing => true,
        };
        if !sent {
            self.supervisor.error(BasicError::HostOverflow);
        }
        if let Some(error) = answer.error {
            self.supervisor.error(error);
        }
    }

    /// Keeps a Wi-Fi settings change from `link` until the bus is quiet.
    fn queue_wifi_write(&mut self, now_us: u64, link: LinkId, change: SettingsChange) {
        let Some(client) = self.router.client(link) else {
            return;
        };
        if let Err(change) = self.wifi_writes.push(now_us, client, change) {
            // A link has at most one change waiting unless its client does not wait for its
            // answers: refuse that one.
            self.send_frame(link, &Reply::Byte(0).to_frame(change.cmd()));
        }
    }

    /// Writes the waiting Wi-Fi settings changes once no request is on the bus (or they have
    /// waited [`WIFI_WRITE_WAIT_US`](wifi::WIFI_WRITE_WAIT_US)), and answers each client that
    /// asked.
    fn write_wifi_settings<I: BasicIo>(&mut self, now_us: u64, io: &mut I) {
        while let Some((client, change)) = self.wifi_writes.next_due(now_us, !self.forwarder.idle())
        {
            let answer = match change {
                SettingsChange::Frame(frame) => {
                    // 0xB0 and 0xB2 are the same frame in both dialects; whether the client
                    // gets an answer is its dialect's to say.
                    let wanted = self
                        .router
                        .link_dialect(client.link)
                        .translate(&frame)
                        .answer;
                    local::answer(&frame, io, self.local_context(now_us))
                        .map(|a| a.in_dialect(wanted))
                }
                SettingsChange::Text(end) => {
                    local::answer_set_text(end, io, self.wifi.as_mut(), now_us)
                }
            };
            // The client may have gone meanwhile (its link closed or reused): then nobody is
            // answered, but the change stands.
            if let Some(answer) = answer
                && self.router.client(client.link) == Some(client)
            {
                self.send_answer(client.link, &answer);
            }
        }
    }

    /// Queues `frame` for `link`, noting an overflow.
    fn send_frame(&mut self, link: LinkId, frame: &Frame) {
        if !self.router.send_frame(link, frame) {
            self.supervisor.error(BasicError::HostOverflow);
        }
    }

    /// `owner` switched the bus to transparent mode: requests still waiting are dropped (their
    /// clients would get the raw bytes of the reply otherwise); the one on the bus is answered
    /// first.
    fn enter_transparent(&mut self, owner: LinkId) {
        self.mode = Mode::Transparent { owner };
        self.router.clear_requests();
        self.router.reset_framer(owner);
        self.transparent = Transparent::default();
    }

    /// Back to framed mode.
    fn leave_transparent(&mut self) {
        if let Mode::Transparent { owner } = self.mode {
            self.router.reset_framer(owner);
        }
        self.mode = Mode::Framed;
        self.transparent = Transparent::default();
        self.bus.drop_partials();
    }

    /// Answers a frame the Basic still handles in transparent mode, from the owner `link`.
    /// Raw traffic still queued for it is dropped so the answer is not lost behind a backlog of
    /// bus bytes.
    fn on_intercepted(&mut self, link: LinkId, hit: Intercepted) {
        self.router.clear_tx(link);
        let reply = match hit {
            Intercepted::SetFramed => {
                self.leave_transparent();
                Reply::Ack.to_frame(cmd::SET_TRANSPONDER_MODE)
            }
            Intercepted::SetTransparent => Reply::Ack.to_frame(cmd::SET_TRANSPONDER_MODE),
            Intercepted::GetMode => {
                Reply::Byte(TransponderMode::Transparent as u8).to_frame(cmd::GET_TRANSPONDER_MODE)
            }
        };
        self.send_frame(link, &reply);
    }
}

/// Acts on what happened to a request: the supervisor watches it (status for the display),
/// and a reply goes where the router says (the client that asked, or nobody), as the
/// client's dialect wants it; an unanswered request gets what its dialect says then.
fn deliver(now_us: u64, event: Event, supervisor: &mut Supervisor, router: &mut Router) {
    supervisor.on_event(now_us, &event);
    let (origin, reply) = match event {
        Event::Reply { request, reply } => (request.origin, request.answer.reply(&reply)),
        Event::Timeout(request) | Event::GaveUp(request) => {
            (request.origin, request.answer.unanswered())
        }
        // A reply passed on as it arrives (only ever a client's, as it is).
        Event::ReplyHead {
            origin: Origin::Host(client),
            head,
            len,
        } => {
            router.stream_open(client, &head, len);
            return;
        }
        Event::ReplyMore {
            origin: Origin::Host(client),
            bytes,
        } => {
            router.stream_more(client, &bytes);
            return;
        }
        Event::ReplyCut {
            origin: Origin::Host(client),
        } => {
            router.stream_cut(client);
            return;
        }
        _ => return,
    };
    if let Some(reply) = reply
        && let Some(delivery) = router.deliver(origin, &reply)
    {
        supervisor.on_delivery(delivery);
    }
}

/// Queues one raw byte for `link`, noting an overflow.
fn send_raw(router: &mut Router, link: LinkId, supervisor: &mut Supervisor, byte: u8) {
    if !router.send_raw(link, byte) {
        supervisor.error(BasicError::HostOverflow);
    }
}

#[cfg(test)]
mod tests {
    use std::collections::VecDeque;
    use std::vec::Vec;

    use super::*;
    use crate::config::EchoMode;
    use crate::io::NullIo;

    /// The bus: what the Basic wrote, and bytes for it to read. No echo.
    #[derive(Default)]
    struct Bus {
        rx: VecDeque<u8>,
        sent: Vec<u8>,
    }

    impl BytePort for Bus {
        fn read_byte(&mut self) -> Option<u8> {
            self.rx.pop_front()
        }

        fn write(&mut self, bytes: &[u8]) {
            self.sent.extend_from_slice(bytes);
        }

        fn tx_idle(&self) -> bool {
            true
        }
    }

    /// Every host link's bytes both ways.
    #[derive(Default)]
    struct Hosts {
        rx: [VecDeque<u8>; MAX_HOST_LINKS],
        tx: [Vec<u8>; MAX_HOST_LINKS],
    }

    impl HostPorts for Hosts {
        fn read_from(&mut self, link: LinkId) -> Option<u8> {
            self.rx[link.index()].pop_front()
        }

        fn write_to(&mut self, link: LinkId, bytes: &[u8]) {
            self.tx[link.index()].extend_from_slice(bytes);
        }

        fn tx_idle_on(&self, _link: LinkId) -> bool {
            true
        }
    }

    /// Test bench: the Basic, its ports and the time.
    struct Bench {
        basic: Basic,
        hosts: Hosts,
        bus: Bus,
        now_us: u64,
    }

    impl Bench {
        /// A Basic that sends nothing of its own (no boot power-on, no probing), on a line
        /// without echo.
        fn new() -> Self {
            let config = BasicConfig {
                echo: EchoMode::Absent,
                power_on_at_boot: false,
                probe_interval_us: 0,
                ..BasicConfig::default()
            };
            Self {
                basic: Basic::new(config),
                hosts: Hosts::default(),
                bus: Bus::default(),
                now_us: 0,
            }
        }

        /// A booted Basic with a network client connected.
        fn with_network_client() -> (Self, LinkId) {
            let mut bench = Self::new();
            bench.run_us(100);
            let net = bench.basic.open_link(LinkKind::Network).unwrap();
            (bench, net)
        }

        fn run_us(&mut self, us: u64) {
            let end = self.now_us + us;
            while self.now_us < end {
                self.now_us += 10;
                let (hosts, bus) = (&mut self.hosts, &mut self.bus);
                self.basic.poll(self.now_us, hosts, bus, &mut NullIo);
            }
        }

        fn host_sends(&mut self, link: LinkId, frame: &Frame) {
            self.hosts.rx[link.index()].extend(frame.to_bytes().iter());
        }

        fn host_got(&mut self, link: LinkId) -> Vec<u8> {
            core::mem::take(&mut self.hosts.tx[link.index()])
        }
    }

    fn frame(code: u8, data: &[u8]) -> Frame {
        Frame::new(code, data).unwrap()
    }

    fn bytes(frame: &Frame) -> Vec<u8> {
        frame.to_bytes().to_vec()
    }

    #[test]
    fn its_own_commands_are_answered_to_the_asker_and_never_reach_the_bus() {
        let (mut bench, net) = Bench::with_network_client();
        bench.host_sends(net, &frame(cmd::GET_BASIC_VERSION, &[]));
        bench.run_us(5_000);
        assert_eq!(
            bench.host_got(net),
            bytes(&frame(cmd::GET_BASIC_VERSION, &[10]))
        );
        assert!(bench.host_got(LinkId::USB).is_empty());
        assert!(bench.bus.sent.is_empty());
        assert_eq!(bench.basic.status().host_frames, 1);
    }

    #[test]
    fn a_request_goes_onto_the_bus_and_its_reply_to_the_client_that_asked_only() {
        let (mut bench, net) = Bench::with_network_client();
        let request = frame(cmd::GET_ANGLES, &[]);
        bench.host_sends(net, &request);
        bench.run_us(5_000);
        assert_eq!(bench.bus.sent, bytes(&request));
        let reply = frame(cmd::GET_ANGLES, &[0; 12]);
        bench.bus.rx.extend(bytes(&reply));
        bench.run_us(5_000);
        assert_eq!(bench.host_got(net), bytes(&reply));
        assert!(bench.host_got(LinkId::USB).is_empty());
        assert_eq!(bench.basic.status().replies_forwarded, 1);
    }

    #[test]
    fn a_seed_check_connection_with_the_atom_silent_answers_not_connected() {
        let (mut bench, net) = Bench::with_network_client();
        bench.host_sends(LinkId::USB, &frame(cmd::DIALECT, &[2]));
        bench.run_us(5_000);
        assert_eq!(
            bench.host_got(LinkId::USB),
            bytes(&frame(cmd::DIALECT, &[2]))
        );
        bench.host_sends(net, &frame(0x50, &[]));
        bench.run_us(5_000);
        assert_eq!(
            bench.bus.sent,
            bytes(&frame(cmd::IS_CONTROLLER_CONNECTED, &[]))
        );
        assert!(bench.host_got(net).is_empty(), "the Atom has 400 ms");
        bench.run_us(450_000);
        assert_eq!(bench.host_got(net), bytes(&frame(0x50, &[0])));
        // Anything else unanswered stays unanswered.
        bench.host_sends(net, &frame(cmd::GET_ANGLES, &[]));
        bench.run_us(450_000);
        assert!(bench.host_got(net).is_empty());
    }

    #[test]
    fn a_reply_for_a_client_that_left_reaches_nobody() {
        let (mut bench, net) = Bench::with_network_client();
        bench.host_sends(net, &frame(cmd::GET_ANGLES, &[]));
        bench.run_us(5_000);
        bench.basic.close_link(net);
        assert_eq!(bench.basic.open_link(LinkKind::Network), Ok(net));
        bench
            .bus
            .rx
            .extend(bytes(&frame(cmd::GET_ANGLES, &[0; 12])));
        bench.run_us(5_000);
        assert!(bench.host_got(net).is_empty(), "not the newcomer's");
        assert_eq!(bench.basic.status().replies_forwarded, 0);
    }

    #[test]
    fn transparent_mode_belongs_to_the_link_that_switched_until_it_leaves() {
        let (mut bench, net) = Bench::with_network_client();
        bench.host_sends(net, &frame(cmd::SET_TRANSPONDER_MODE, &[1]));
        bench.run_us(5_000);
        assert_eq!(
            bench.host_got(net),
            bytes(&frame(cmd::SET_TRANSPONDER_MODE, &[1]))
        );
        assert_eq!(bench.basic.status().mode, TransponderMode::Transparent);
        // Another client: 0xC2 refused, a request for the Atom dropped unanswered.
        bench.host_sends(LinkId::USB, &frame(cmd::SET_TRANSPONDER_MODE, &[0]));
        bench.host_sends(LinkId::USB, &frame(cmd::GET_ANGLES, &[]));
        bench.run_us(5_000);
        assert_eq!(
            bench.host_got(LinkId::USB),
            bytes(&frame(cmd::SET_TRANSPONDER_MODE, &[0]))
        );
        assert!(bench.bus.sent.is_empty());
        assert_eq!(
            bench.basic.status().last_error,
            Some(BasicError::TransparentElsewhere {
                cmd: cmd::GET_ANGLES
            })
        );
        // The owner leaves: framed again.
        bench.basic.close_link(net);
        assert_eq!(bench.basic.status().mode, TransponderMode::Framed);
    }
}
