//! The bus side of the transponder: sends one request at a time onto the shared wire and
//! returns the one reply that answers it.
//!
//! The forwarder hears the bus through the Basic's [`Listener`], which it is lent for each
//! byte and each poll. A request is transmitted only into a quiet wire
//! ([`timing::BUS_QUIET_BEFORE_SEND_US`]), early enough in the Atom's gap between servo
//! transactions that the Atom hears it before it would start its next one
//! ([`LATEST_START_IN_GAP_US`]), or once the gap has visibly ended with nobody talking
//! ([`ATOM_START_SEEN_US`]). The listener reads its echo back and judges it ([`Echo`]). A
//! collision that the echo proves (the line is known to echo, and what came back differed: the
//! Atom heard the same garbled bytes) is retransmitted after a growing back-off, at most
//! [`BasicConfig::max_send_attempts`] times. Nothing else makes the Basic send a client's
//! request again: an echo that is missing or cut short, another station's bytes heard while
//! transmitting on a line not known to echo, a reply that comes garbled or late - the request
//! may have reached the Atom, and a client's request reaches the Atom at most once
//! (`may_resend`). The client resends if it wants (pymycobot after 0.5 s).
//!
//! Then only a complete `FE FE` frame with the request's CMD counts as the reply; servo
//! packets, other frames and late replies are dropped, and a request that gets no reply is
//! given up after its deadline so the next one can go. The next request is the caller's choice
//! (the [`crate::router`]'s turn, or the Basic's own), started only while the forwarder has
//! none in flight.
//!
//! **Late replies.** A request given up after its deadline may still be answered (a slow
//! Atom; under emulation, any Atom). The Atom answers one request at a time, in order, so the
//! forwarder keeps the last few requests it gave up on ([`MAX_LATE`], for
//! [`LATE_REPLY_WINDOW_US`]) and takes a frame with one of their CMDs for the oldest such
//! request's reply: that reply goes to nobody but the status (`Event::Late`), and is never
//! taken for the reply to the request now in flight, nor for a garbled one. Only when the
//! request in flight asks the same as the late one, for the same client (its resend), does the
//! late reply answer it.
//!
//! The Basic's own requests (0x12, and 0x10 to an Atom that said it is off) are asked again
//! at once when their reply comes garbled or their echo is missing: asking twice does no harm.
//!
//! **Cut-through.** A serial client's reply is reported as it arrives (`Event::ReplyHead`,
//! `Event::ReplyMore`), from the moment its first four bytes show it is the reply, all but its
//! last byte ([`streamable_prefix`]); the frame completes it (`Event::Reply`), a candidate
//! dropped cuts it (`Event::ReplyCut`). Which reply counts is decided exactly as before, on
//! the whole frame.
//!
//! **Holding the bus.** While a request is still arriving on a host link and nothing is in
//! flight, `Forwarder::hold` keeps the Atom's next servo transaction back with a
//! [`HOLD_BYTE`] early in each of its gaps, so the request goes as soon as it is in.

use heapless::{Deque, Vec};
use protocol_core::frame::{HEADER, MAX_FRAME_BYTES, MAX_REPLY_DATA, MIN_LEN};
use protocol_core::listener::{Echo, Heard, Listener, ListenerConfig};
use protocol_core::{BytePort, Frame, timing};

use crate::config::{BasicConfig, EchoMode};
use crate::request::{Origin, Request};
/// Bytes received further apart than this had silence between them (a new transmission
/// began), in microseconds: one byte time and the reaction time.
const BURST_GAP_US: u64 = timing::wire_time_us(1, timing::BUS_BAUD) + REACTION_US;
/// Longest back-off after a collision, in microseconds.
pub const MAX_BACKOFF_US: u64 = 2_000;
/// How late a station may act on what the wire did (its poll period, receiver latency), in
/// microseconds.
const REACTION_US: u64 = 10;
/// Quiet time from which the Basic no longer starts a frame: the Atom may start its next
/// transaction at [`timing::ATOM_TRANSACTION_GAP_US`] of quiet, and must hear our first byte
/// before that (one byte time, and its reaction time) to hold back.
pub const LATEST_START_IN_GAP_US: u64 =
    timing::ATOM_TRANSACTION_GAP_US - timing::wire_time_us(1, timing::BUS_BAUD) - REACTION_US;
/// Quiet time after which the Atom has visibly not started a transaction at the end of its
/// gap (its first byte would have been heard by now), so the wire is free again.
pub const ATOM_START_SEEN_US: u64 =
    timing::ATOM_TRANSACTION_GAP_US + timing::wire_time_us(2, timing::BUS_BAUD) + REACTION_US;

/// True if the Basic may start transmitting after the wire has been quiet for `quiet_us`:
/// past any servo's turnaround, and either early in the Atom's gap or once the gap has
/// visibly passed. Carrier sense sees a byte only once it is complete, so starting late in
/// the gap, both stations would start before hearing each other.
pub fn may_start_after_quiet(quiet_us: u64) -> bool {
    (timing::BUS_QUIET_BEFORE_SEND_US..LATEST_START_IN_GAP_US).contains(&quiet_us)
        || quiet_us >= ATOM_START_SEEN_US
}

/// True if the forwarder may send `request` again when it cannot tell whether the Atom got it
/// (missing echo, garbled reply): only the Basic's own requests, which ask (0x12) or power on
/// an Atom that said it is off (0x10). A client's request reaches the Atom at most once; the
/// client resends if it wants.
pub(crate) fn may_resend(request: &Request) -> bool {
    !matches!(request.origin, Origin::Host(_))
}

/// How the Basic hears the bus: host frames (the Atom's replies) and every byte that is not its
/// own echo (transparent mode passes them on, and they show a reply that began garbled);
/// servo packets are none of its business.
pub(crate) fn bus_listener(echo: EchoMode) -> Listener {
    Listener::new(
        ListenerConfig::new()
            .with_packets(false)
            .with_bytes(true)
            .with_echo(echo),
    )
}

/// How long after a request was given up on a frame with its CMD is still taken for its late
/// reply, in microseconds: a client's deadline (pymycobot's 0.5 s resend).
pub const LATE_REPLY_WINDOW_US: u64 = timing::HOST_REPLY_DEADLINE_US;

/// Requests given up on whose late replies are recognised: more than a client's deadline's
/// worth of timeouts of the Basic's own requests (50 ms each) would be needed to push one out.
pub const MAX_LATE: usize = 8;

/// What happened to a request, for the caller to act on.
#[derive(Debug, PartialEq, Eq)]
pub(crate) enum Event {
    /// `reply` answers `request`.
    Reply { request: Request, reply: Frame },
    /// The Atom did not answer `request` in time.
    Timeout(Request),
    /// `request` collided on every attempt and was given up.
    GaveUp(Request),
    /// `request` waited for its turn longer than its client waits for a reply, and was
    /// dropped unsent.
    Expired(Request),
    /// A transmission collided and will be repeated.
    Collision,
    /// `reply` answers `request`, which was given up on (timed out) before it came. Its
    /// client, if any, has been told nothing and is not given it (it may have asked something
    /// else since).
    Late { request: Request, reply: Frame },
    /// A frame from the bus answered nothing outstanding and was dropped.
    Unsolicited,
    /// The reply to a request from `origin` has begun on the bus and is passed on as it
    /// arrives (cut-through, [`Request::cut_through`]): `head`, its first bytes, of a frame
    /// `len` bytes long. Its next bytes follow ([`Event::ReplyMore`]); the frame itself ends
    /// it ([`Event::Reply`], whose frame completes what was passed on), or [`Event::ReplyCut`].
    ReplyHead {
        origin: Origin,
        head: Vec<u8, MAX_FRAME_BYTES>,
        len: usize,
    },
    /// The next bytes of the reply being passed on.
    ReplyMore {
        origin: Origin,
        bytes: Vec<u8, MAX_FRAME_BYTES>,
    },
    /// The reply being passed on did not complete (cut short by silence, not a frame after
    /// all): the client must not find a frame in what it was given.
    ReplyCut { origin: Origin },
}

impl Event {
    /// Who asked for the request this event is about, if it is about one.
    pub(crate) fn origin(&self) -> Option<Origin> {
        match self {
            Self::Reply { request, .. }
            | Self::Late { request, .. }
            | Self::Timeout(request)
            | Self::GaveUp(request)
            | Self::Expired(request) => Some(request.origin),
            Self::ReplyHead { origin, .. }
            | Self::ReplyMore { origin, .. }
            | Self::ReplyCut { origin } => Some(*origin),
            Self::Collision | Self::Unsolicited => None,
        }
    }
}

#[derive(Debug)]
enum Stage {
    /// Waiting for the wire to be quiet (and any back-off to pass).
    WaitQuiet { not_before_us: u64 },
    /// On the wire, until the listener's verdict on its echo; `collided` once the echo
    /// differed (acted on when the transmitter is idle).
    Transmitting { collided: bool },
    /// Sent; waiting for the reply until `deadline_us`. `reply_started` is whether a reply
    /// seems to have come but not as a valid frame with our CMD: an `FE` that begins a
    /// transmission (the first byte heard, or one after a silence; servo packets begin with
    /// `FF`), `FE FE` anywhere, or a valid frame for another command. `heard_any` and
    /// `last_fe` track what came before.
    /// `burst_fe` is the stream position of the last `FE` that began a transmission: only a
    /// reply starting there is passed on as it arrives.
    AwaitReply {
        deadline_us: u64,
        heard_any: bool,
        last_fe: bool,
        reply_started: bool,
        burst_fe: Option<u64>,
    },
}

#[derive(Debug)]
struct InFlight {
    request: Request,
    wire: Vec<u8, MAX_FRAME_BYTES>,
    attempts: u8,
    stage: Stage,
    /// The reply being passed on as it arrives, if it is.
    stream: Option<Streamed>,
}

/// A reply being passed on as it arrives: the frame candidate the listener is hearing.
#[derive(Debug)]
struct Streamed {
    /// The stream position of its first byte ([`Listener::frame_partial`]).
    start: u64,
    /// How many of its bytes have been passed on.
    given: usize,
    /// Its whole length.
    len: usize,
}

/// Longest reply passed on as it arrives: pymycobot's longest (it reads no LEN above 30, and
/// would take a larger LEN byte for something else).
pub const MAX_STREAMED_LEN: u8 = MAX_REPLY_DATA as u8 + 2;

/// How many leading bytes of `candidate`, a frame `len` bytes long, may be given to the client
/// before the frame is complete: never its last byte (the `FA` that makes it a frame), and
/// nothing from the second `FE` of an `FE FE` inside it on. So a reply cut short leaves the
/// client a frame header whose frame never ends, with no other frame header inside it.
pub fn streamable_prefix(candidate: &[u8], len: usize) -> usize {
    let end = candidate.len().min(len.saturating_sub(1));
    (3..end)
        .find(|&i| candidate.get(i) == Some(&HEADER) && candidate.get(i - 1) == Some(&HEADER))
        .unwrap_or(end)
}

/// A request given up on whose reply may still come.
#[derive(Debug)]
struct Late {
    request: Request,
    /// After this time a frame with its CMD is no longer taken for its reply.
    until_us: u64,
}

/// What the Basic sends to hold the bus for a request still arriving (`Forwarder::hold`):
/// neither a host frame's first byte (`FE`) nor a servo packet's (`FF`), so every station's
/// decoder skips it; it only keeps the wire from going quiet for the Atom's transaction gap.
pub const HOLD_BYTE: u8 = 0x00;

/// The bus forwarder.
#[derive(Debug)]
pub(crate) struct Forwarder {
    current: Option<InFlight>,
    /// Requests given up on, oldest first, whose replies may still come.
    late: Deque<Late, MAX_LATE>,
    /// The bus is being held for a request still arriving.
    holding: bool,
    /// Another station's byte was heard since the last hold began: the next may begin.
    heard_other: bool,
}

impl Forwarder {
    pub(crate) const fn new() -> Self {
        Self {
            current: None,
            late: Deque::new(),
            holding: false,
            heard_other: true,
        }
    }

    /// Holds the bus for a request still arriving on a host link (`coming`,
    /// `Router::request_coming`), so that it can go as soon as it is in instead of waiting for
    /// the Atom's next gap between servo transactions: while the forwarder is idle, a
    /// [`HOLD_BYTE`] is sent early in each gap, where the Basic may start any transmission
    /// ([`may_start_after_quiet`]: quiet for [`timing::BUS_QUIET_BEFORE_SEND_US`], before
    /// [`LATEST_START_IN_GAP_US`]), so the wire is never quiet for the Atom's transaction gap
    /// and the Atom waits; the request then goes at the first start the rule allows after it
    /// is in. A wire quiet for longer has no transaction coming (the Atom would have started
    /// it): no hold, and the request goes at once when it is in. A hold begins only after
    /// another station's byte has been heard since the last one began (the Atom's reply, or
    /// the servo transaction the Atom starts once a hold ends without a request), so holds
    /// alternate with the Atom's turns on the bus and a client sending headers that never
    /// become frames cannot starve the servo refresh.
    pub(crate) fn hold<B: BytePort>(
        &mut self,
        now_us: u64,
        bus: &mut B,
        listener: &mut Listener,
        coming: bool,
        config: &BasicConfig,
    ) {
        if !(config.bus_hold && coming && self.idle()) {
            self.holding = false;
            return;
        }
        if !self.holding {
            if !self.heard_other {
                return;
            }
            self.holding = true;
            self.heard_other = false;
        }
        // Only early in the Atom's gap: a wire quiet for longer has no transaction coming (the
        // Atom would have started it), and the request goes at once when it is in.
        let quiet_us = listener.quiet_us(now_us);
        let early_in_gap =
            (timing::BUS_QUIET_BEFORE_SEND_US..LATEST_START_IN_GAP_US).contains(&quiet_us);
        if !early_in_gap || !bus.tx_idle() || listener.echo_pending() {
            return;
        }
        bus.write(&[HOLD_BYTE]);
        listener.on_transmit(now_us, &[HOLD_BYTE]);
    }

    /// True when no request is in flight: the next may start.
    pub(crate) fn idle(&self) -> bool {
        self.current.is_none()
    }

    /// Takes `request` in flight; it goes onto the wire as soon as the wire allows. Call only
    /// while [`Self::idle`]; a request in flight is never replaced.
    pub(crate) fn start(&mut self, request: Request) {
        if self.current.is_some() {
            return;
        }
        let mut wire = Vec::new();
        let mut buf = [0u8; MAX_FRAME_BYTES];
        if let Some(bytes) = request.frame.encode(&mut buf).and_then(|n| buf.get(..n)) {
            // Cannot fail: a frame's encoding fits MAX_FRAME_BYTES.
            let _ = wire.extend_from_slice(bytes);
        }
        self.current = Some(InFlight {
            request,
            wire,
            attempts: 0,
            stage: Stage::WaitQuiet { not_before_us: 0 },
            stream: None,
        });
    }

    /// Handles one byte heard on the bus at `now_us`, passing it through `listener`.
    pub(crate) fn on_bus_byte(
        &mut self,
        now_us: u64,
        byte: u8,
        listener: &mut Listener,
        config: &BasicConfig,
        mut on_event: impl FnMut(Event),
    ) {
        let line = Line::now(now_us, listener);
        // Stream positions of the bytes given out, in order.
        let mut position = listener.frames_heard();
        listener.push(now_us, byte, &mut |heard| {
            let at = position;
            if matches!(heard, Heard::Byte(_)) {
                position = position.wrapping_add(1);
            }
            self.on_heard(now_us, heard, at, line, config, &mut on_event);
        });
        self.follow_stream(listener, config, &mut on_event);
        let garbled = matches!(
            &self.current,
            Some(InFlight { stage: Stage::AwaitReply { reply_started: true, .. }, request, .. })
                if may_resend(request)
        ) && !listener.frame_in_progress();
        if garbled {
            self.on_collision(now_us, config, &mut on_event);
        }
    }

    /// Acts on what the listener heard; `line` is what the line was like before the byte
    /// (or the time) that brought it.
    /// `position` is the stream position of a [`Heard::Byte`].
    fn on_heard(
        &mut self,
        now_us: u64,
        heard: Heard,
        position: u64,
        line: Line,
        config: &BasicConfig,
        on_event: &mut impl FnMut(Event),
    ) {
        match heard {
            Heard::Echo(echo) => self.on_echo(now_us, echo, line.echoes, config, on_event),
            Heard::Byte(byte) => {
                self.heard_other = true;
                self.note_reply_byte(byte, position, line.silence_before);
            }
            Heard::Frame(frame) => self.on_frame(now_us, frame, on_event),
            Heard::Packet(_) => {}
        }
    }

    /// Passes the reply on to the client as it arrives, for a request that allows it
    /// ([`Request::cut_through`], and [`BasicConfig::cut_through`]). The reply is the frame candidate the listener is hearing
    /// that began a transmission while the request waits for its reply, with the request's
    /// CMD, a LEN pymycobot reads (up to [`MAX_STREAMED_LEN`]), and no CMD of a request given
    /// up on (its late reply is told apart only once complete). Its bytes are passed on as
    /// far as [`streamable_prefix`] allows; the frame completing ends it (the reply event
    /// carries it), a candidate dropped cuts it ([`Event::ReplyCut`]).
    fn follow_stream(
        &mut self,
        listener: &Listener,
        config: &BasicConfig,
        on_event: &mut impl FnMut(Event),
    ) {
        let Some(flight) = self.current.as_mut() else {
            return;
        };
        let (start, candidate) = listener.frame_partial();
        let origin = flight.request.origin;
        if let Some(stream) = flight.stream.as_mut() {
            if stream.start != start || candidate.is_empty() {
                // Dropped without completing as the reply.
                flight.stream = None;
                on_event(Event::ReplyCut { origin });
                return;
            }
            let upto = streamable_prefix(candidate, stream.len);
            if upto > stream.given
                && let Some(bytes) = candidate.get(stream.given..upto)
            {
                stream.given = upto;
                on_event(Event::ReplyMore {
                    origin,
                    bytes: Vec::from_slice(bytes).unwrap_or_default(),
                });
            }
            return;
        }
        let Stage::AwaitReply { burst_fe, .. } = flight.stage else {
            return;
        };
        let cmd = flight.request.frame.cmd();
        let &[HEADER, HEADER, len, code, ..] = candidate else {
            return;
        };
        if !(config.cut_through && flight.request.cut_through)
            || burst_fe != Some(start)
            || code != cmd
            || !(MIN_LEN..=MAX_STREAMED_LEN).contains(&len)
            || self.late.iter().any(|late| late.request.frame.cmd() == cmd)
        {
            return;
        }
        let len = usize::from(len) + 3;
        let upto = streamable_prefix(candidate, len);
        let Some(head) = candidate.get(..upto) else {
            return;
        };
        flight.stream = Some(Streamed {
            start,
            given: upto,
            len,
        });
        on_event(Event::ReplyHead {
            origin,
            head: Vec::from_slice(head).unwrap_or_default(),
            len,
        });
    }

    /// Ends the reply being passed on, if any, without its end.
    fn cut_stream(&mut self, on_event: &mut impl FnMut(Event)) {
        if let Some(flight) = self.current.as_mut()
            && flight.stream.take().is_some()
        {
            on_event(Event::ReplyCut {
                origin: flight.request.origin,
            });
        }
    }

    /// Follows the transmission in flight to its end, as the listener judged its echo;
    /// `echoes`: the line is known to echo, so a differing echo proves a collision.
    fn on_echo(
        &mut self,
        now_us: u64,
        echo: Echo,
        echoes: bool,
        config: &BasicConfig,
        on_event: &mut impl FnMut(Event),
    ) {
        let Some(InFlight {
            request,
            stage: Stage::Transmitting { collided },
            ..
        }) = &mut self.current
        else {
            return;
        };
        let resend = may_resend(request);
        match echo {
            // The whole echo came back, or none (the wiring does not echo, as the listener
            // now knows): what arrives from now on is the Atom's.
            Echo::Whole | Echo::Silent => self.start_waiting(now_us, config),
            // The echo differed on a line that echoes: the Atom heard the same garbled bytes,
            // not the request. Sent again once our transmitter is idle.
            Echo::Differed if echoes => *collided = true,
            // Another station's bytes while ours went out, on a line not known to echo: an
            // answer (early, or late to an earlier request) as likely as a collision, and the
            // request may have arrived whole. Sent once: what comes now is the Atom's.
            Echo::Differed => self.start_waiting(now_us, config),
            // The echo is missing or cut short: the frame may still have reached the Atom
            // (bytes lost on our receive side). Sent again only if that is harmless.
            Echo::Missing if resend => self.on_collision(now_us, config, on_event),
            Echo::Missing => self.start_waiting(now_us, config),
        }
    }

    /// Notes a byte heard while waiting for the reply, at stream position `position`: whether
    /// a reply seems to have begun.
    fn note_reply_byte(&mut self, byte: u8, position: u64, silence_before: bool) {
        if let Some(InFlight {
            stage:
                Stage::AwaitReply {
                    heard_any,
                    last_fe,
                    reply_started,
                    burst_fe,
                    ..
                },
            ..
        }) = &mut self.current
        {
            let starts_transmission = !*heard_any || silence_before;
            if byte == HEADER && starts_transmission {
                *burst_fe = Some(position);
            }
            *reply_started |= byte == HEADER && (starts_transmission || *last_fe);
            *last_fe = byte == HEADER && !*last_fe;
            *heard_any = true;
        }
    }

    /// Lets time pass in `listener` (echo verdicts, frames cut short), checks deadlines and
    /// the transmitter. Call after the bytes that arrived have been passed to
    /// [`Self::on_bus_byte`]; then [`Self::start`] the next request if idle, then
    /// [`Self::try_send`].
    pub(crate) fn on_time<B: BytePort>(
        &mut self,
        now_us: u64,
        bus: &B,
        listener: &mut Listener,
        config: &BasicConfig,
        mut on_event: impl FnMut(Event),
    ) {
        let line = Line::now(now_us, listener);
        let mut position = listener.frames_heard();
        listener.on_time(now_us, &mut |heard| {
            let at = position;
            if matches!(heard, Heard::Byte(_)) {
                position = position.wrapping_add(1);
            }
            self.on_heard(now_us, heard, at, line, config, &mut on_event);
        });
        self.follow_stream(listener, config, &mut on_event);
        while self
            .late
            .front()
            .is_some_and(|late| now_us >= late.until_us)
        {
            self.late.pop_front();
        }
        if matches!(
            self.current,
            Some(InFlight {
                stage: Stage::Transmitting { collided: true },
                ..
            })
        ) && bus.tx_idle()
        {
            // The echo differed: the Atom heard the same garbled bytes.
            self.on_collision(now_us, config, &mut on_event);
        }
        if let Some(InFlight {
            stage:
                Stage::AwaitReply {
                    deadline_us,
                    reply_started,
                    ..
                },
            ..
        }) = &self.current
            && now_us >= *deadline_us
            && let answer_heard = *reply_started
        {
            self.cut_stream(&mut on_event);
            let Some(done) = self.current.take() else {
                return;
            };
            // Unless a garbled answer was heard, its reply may still come: recognised as
            // late, never taken for another's.
            if answer_heard {
                on_event(Event::Timeout(done.request));
                return;
            }
            if self.late.is_full() {
                self.late.pop_front();
            }
            let late = Late {
                request: done.request.clone(),
                until_us: now_us.saturating_add(LATE_REPLY_WINDOW_US),
            };
            // Cannot fail: there is room.
            let _ = self.late.push_back(late);
            on_event(Event::Timeout(done.request));
        }
    }

    fn on_collision(
        &mut self,
        now_us: u64,
        config: &BasicConfig,
        on_event: &mut impl FnMut(Event),
    ) {
        self.cut_stream(on_event);
        let Some(flight) = &mut self.current else {
            return;
        };
        flight.attempts = flight.attempts.saturating_add(1);
        if flight.attempts >= config.max_send_attempts.max(1) {
            if let Some(done) = self.current.take() {
                on_event(Event::GaveUp(done.request));
            }
            return;
        }
        on_event(Event::Collision);
        // Back off a little longer each time, so a station that keeps talking gets its turn.
        let backoff_us =
            (timing::BUS_QUIET_BEFORE_SEND_US << flight.attempts.min(6)).min(MAX_BACKOFF_US);
        flight.stage = Stage::WaitQuiet {
            not_before_us: now_us.saturating_add(backoff_us),
        };
    }

    fn start_waiting(&mut self, now_us: u64, config: &BasicConfig) {
        if let Some(flight) = &mut self.current {
            let timeout_us = match flight.request.origin {
                Origin::Host(_) => config.reply_timeout_us,
                Origin::PowerOn | Origin::Probe => config.probe_timeout_us,
            };
            flight.stage = Stage::AwaitReply {
                deadline_us: now_us.saturating_add(timeout_us),
                heard_any: false,
                last_fe: false,
                reply_started: false,
                burst_fe: None,
            };
        }
    }

    /// Transmits the request in flight if the wire is free.
    pub(crate) fn try_send<B: BytePort>(
        &mut self,
        now_us: u64,
        bus: &mut B,
        listener: &mut Listener,
    ) {
        let quiet_us = listener.quiet_us(now_us);
        let Some(flight) = &mut self.current else {
            return;
        };
        let Stage::WaitQuiet { not_before_us } = flight.stage else {
            return;
        };
        if now_us < not_before_us || !may_start_after_quiet(quiet_us) || !bus.tx_idle() {
            return;
        }
        // The wire is quiet: a partial frame in the decoder can no longer complete, and must not
        // swallow the reply.
        listener.drop_partials();
        bus.write(&flight.wire);
        listener.on_transmit(now_us, &flight.wire);
        flight.stage = Stage::Transmitting { collided: false };
    }

    fn on_frame(&mut self, now_us: u64, frame: Frame, on_event: &mut impl FnMut(Event)) {
        if self.take_late_reply(now_us, &frame, on_event) {
            return;
        }
        // While waiting to send again, a reply to an earlier copy still answers the request.
        let answers = matches!(
            &self.current,
            Some(InFlight { request, stage: Stage::AwaitReply { .. }, .. })
                if request.frame.cmd() == frame.cmd()
        ) || matches!(
            &self.current,
            Some(InFlight { request, stage: Stage::WaitQuiet { .. }, attempts, .. })
                if *attempts > 0 && request.frame.cmd() == frame.cmd()
        );
        if answers && let Some(done) = self.current.take() {
            on_event(Event::Reply {
                request: done.request,
                reply: frame,
            });
        } else {
            if let Some(InFlight {
                stage: Stage::AwaitReply { reply_started, .. },
                ..
            }) = &mut self.current
            {
                // The Atom sends frames only to answer the Basic: another command's frame now
                // is our reply with its CMD byte garbled (or a reply too late to matter).
                *reply_started = true;
            }
            on_event(Event::Unsolicited);
        }
    }

    /// Takes `frame` for the late reply to a request given up on, if it has the CMD of one
    /// (the oldest: the Atom answers in order, so those before it will not be answered now).
    /// The request in flight gets it too only if it asks the same for the same client.
    fn take_late_reply(
        &mut self,
        now_us: u64,
        frame: &Frame,
        on_event: &mut impl FnMut(Event),
    ) -> bool {
        let Some(position) = self
            .late
            .iter()
            .position(|late| late.request.frame.cmd() == frame.cmd() && now_us < late.until_us)
        else {
            return false;
        };
        let same_question = self.current.as_ref().is_some_and(|flight| {
            matches!(flight.stage, Stage::AwaitReply { .. })
                && self.late.get(position).is_some_and(|late| {
                    late.request.frame == flight.request.frame
                        && late.request.origin == flight.request.origin
                })
        });
        if same_question {
            // A resend of the question the late reply answers: it is the answer. The reply to
            // the resend, still to come, then counts as the late one.
            if let Some(done) = self.current.take() {
                on_event(Event::Reply {
                    request: done.request,
                    reply: frame.clone(),
                });
            }
            return true;
        }
        for _ in 0..position {
            self.late.pop_front();
        }
        let Some(late) = self.late.pop_front() else {
            return false;
        };
        if let Some(InFlight {
            stage: Stage::AwaitReply { reply_started, .. },
            ..
        }) = &mut self.current
        {
            // Its first byte looked like the start of our reply; it was not.
            *reply_started = false;
        }
        on_event(Event::Late {
            request: late.request,
            reply: frame.clone(),
        });
        true
    }
}

/// What the line was like when a byte arrived (or time passed), before the listener acted on
/// it.
#[derive(Clone, Copy, Debug)]
struct Line {
    /// The line had been quiet: the byte begins a transmission.
    silence_before: bool,
    /// The line is known to echo, or the echo of this transmission has begun to come back: a
    /// differing echo proves a collision.
    echoes: bool,
}

impl Line {
    fn now(now_us: u64, listener: &Listener) -> Self {
        Self {
            silence_before: listener.quiet_us(now_us) > BURST_GAP_US,
            echoes: listener.echo_required() || listener.echo_coming_back(),
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use protocol_core::command::cmd;

    #[test]
    fn the_basic_starts_only_early_in_a_gap_or_after_it() {
        let starts: std::vec::Vec<u64> = (0..200).filter(|&q| may_start_after_quiet(q)).collect();
        // Never while a servo may still answer, never late in the Atom's 100 us gap.
        assert_eq!(starts.first(), Some(&timing::BUS_QUIET_BEFORE_SEND_US));
        assert!(starts.contains(&(LATEST_START_IN_GAP_US - 1)));
        assert!(
            !starts
                .iter()
                .any(|q| (LATEST_START_IN_GAP_US..ATOM_START_SEEN_US).contains(q))
        );
        assert!(starts.contains(&ATOM_START_SEEN_US));
        const { assert!(LATEST_START_IN_GAP_US > timing::BUS_QUIET_BEFORE_SEND_US) };
    }

    /// A bus port that takes anything and is always idle.
    #[derive(Default)]
    struct Port(std::vec::Vec<u8>);

    impl BytePort for Port {
        fn read_byte(&mut self) -> Option<u8> {
            None
        }
        fn write(&mut self, bytes: &[u8]) {
            self.0.extend_from_slice(bytes);
        }
        fn tx_idle(&self) -> bool {
            true
        }
    }

    /// A forwarder whose request (`cmd`, a client's, passed on as it arrives if `cut_through`)
    /// is on the bus and waits for its reply, on a line without echo; the time then, in us.
    struct Waiting {
        forwarder: Forwarder,
        listener: Listener,
        config: BasicConfig,
        now_us: u64,
        events: std::vec::Vec<Event>,
    }

    impl Waiting {
        fn new(cmd: u8, cut_through: bool) -> Self {
            let mut waiting = Self::on_line(EchoMode::Absent);
            waiting.ask(cmd, cut_through);
            waiting
        }

        /// A forwarder with nothing in flight on a line with `echo`.
        fn on_line(echo: EchoMode) -> Self {
            Self {
                forwarder: Forwarder::new(),
                listener: bus_listener(echo),
                config: BasicConfig {
                    echo,
                    ..BasicConfig::default()
                },
                now_us: 1_000,
                events: std::vec::Vec::new(),
            }
        }

        /// Sends a client's request `cmd` on a quiet wire and lets its transmission end.
        fn ask(&mut self, cmd: u8, cut_through: bool) {
            self.send(cmd, cut_through);
            self.idle(100);
        }

        /// Sends a client's request `cmd` on a quiet wire, and polls no more.
        fn send(&mut self, cmd: u8, cut_through: bool) {
            let client = crate::request::Client::new(crate::request::LinkId::USB, 0);
            self.forwarder.start(Request {
                frame: Frame::new(cmd, &[]).unwrap(),
                origin: Origin::Host(client),
                answer: protocol_core::dialect::Answer::AsIs,
                queued_us: 0,
                cut_through,
            });
            self.now_us += ATOM_START_SEEN_US;
            let mut port = Port::default();
            self.forwarder
                .try_send(self.now_us, &mut port, &mut self.listener);
            assert_eq!(port.0.len(), 5, "sent");
        }

        /// Bytes from the Atom, one per byte time at 1 Mbaud.
        fn hear(&mut self, bytes: &[u8]) {
            for &b in bytes {
                self.now_us += 10;
                let events = &mut self.events;
                self.forwarder
                    .on_bus_byte(self.now_us, b, &mut self.listener, &self.config, |e| {
                        events.push(e)
                    });
            }
        }

        /// `us` of quiet.
        fn idle(&mut self, us: u64) {
            self.now_us += us;
            let events = &mut self.events;
            self.forwarder.on_time(
                self.now_us,
                &Port::default(),
                &mut self.listener,
                &self.config,
                |e| events.push(e),
            );
        }

        /// What was passed on to the client before the reply's end, and how that ended: the
        /// bytes given, and whether the reply completed it (`Some(true)`) or it was cut.
        fn passed_on(&self) -> (std::vec::Vec<u8>, Option<bool>) {
            let mut given = std::vec::Vec::new();
            let mut end = None;
            let mut open = false;
            for e in &self.events {
                match e {
                    Event::ReplyHead { head, len, .. } => {
                        assert_eq!(*len, usize::from(head[2]) + 3);
                        given.extend_from_slice(head);
                        open = true;
                    }
                    Event::ReplyMore { bytes, .. } => {
                        assert!(open, "more without a head");
                        given.extend_from_slice(bytes);
                    }
                    Event::ReplyCut { .. } if open => (end, open) = (Some(false), false),
                    Event::Reply { .. } if open => (end, open) = (Some(true), false),
                    _ => {}
                }
            }
            (given, end)
        }

        fn replies(&self) -> std::vec::Vec<Frame> {
            self.events
                .iter()
                .filter_map(|e| match e {
                    Event::Reply { reply, .. } => Some(reply.clone()),
                    _ => None,
                })
                .collect()
        }
    }

    fn angles() -> std::vec::Vec<u8> {
        Frame::new(
            cmd::GET_ANGLES,
            &[0, 100, 0xFF, 0x9C, 0, 0, 0, 0, 0x12, 0x34, 0xFE, 0xFA],
        )
        .unwrap()
        .to_bytes()
        .to_vec()
    }

    #[test]
    fn a_reply_is_passed_on_from_its_cmd_on_but_its_last_byte_only_as_the_frame() {
        let mut w = Waiting::new(cmd::GET_ANGLES, true);
        let reply = angles();
        w.hear(&reply[..3]);
        assert!(w.events.is_empty(), "nothing before the CMD is known");
        w.hear(&reply[3..4]);
        assert!(
            matches!(&w.events[..], [Event::ReplyHead { head, len: 17, .. }] if head[..] == reply[..4])
        );
        w.hear(&reply[4..]);
        let (given, end) = w.passed_on();
        assert_eq!(
            given,
            reply[..reply.len() - 1],
            "all but the FA before the frame"
        );
        assert_eq!(end, Some(true));
        assert_eq!(w.replies().len(), 1);
    }

    #[test]
    fn a_reply_that_repeats_the_request_is_passed_on_after_a_stall() {
        // The emulated C3 Basic: its loop stood still from its request to the Atom's answer,
        // byte for byte the request (as `01` to a backup of servo 1 is), on a line that does
        // not echo; the answer was dropped as the request's echo and the client got nothing.
        let mut w = Waiting::on_line(EchoMode::Auto);
        w.listener.on_transmit(w.now_us, &[HOLD_BYTE]);
        w.idle(1_000);
        assert_eq!(w.listener.echo_heard(), Some(false), "learnt: no echo");
        w.send(cmd::GET_ANGLES, false);
        w.now_us += 3_000;
        w.hear(&Frame::new(cmd::GET_ANGLES, &[]).unwrap().to_bytes());
        assert_eq!(w.replies(), [Frame::new(cmd::GET_ANGLES, &[]).unwrap()]);
    }

    #[test]
    fn a_reply_cut_short_by_silence_or_not_ending_in_fa_is_cut() {
        let reply = angles();
        let mut w = Waiting::new(cmd::GET_ANGLES, true);
        w.hear(&reply[..9]);
        w.idle(timing::BUS_FRAME_GAP_US);
        assert_eq!(w.passed_on(), (reply[..9].to_vec(), Some(false)));
        let mut w = Waiting::new(cmd::GET_ANGLES, true);
        let mut garbled = reply.clone();
        garbled[16] = 0x00;
        w.hear(&garbled);
        assert_eq!(w.passed_on(), (reply[..16].to_vec(), Some(false)));
        assert!(w.replies().is_empty());
        // The Atom sends it again (its own echo showed the collision): passed on afresh.
        w.idle(timing::BUS_QUIET_BEFORE_SEND_US);
        w.hear(&reply);
        assert_eq!(w.replies().len(), 1);
        assert_eq!(
            w.events
                .iter()
                .filter(|e| matches!(e, Event::ReplyHead { .. }))
                .count(),
            2
        );
    }

    #[test]
    fn nothing_of_an_fe_fe_inside_the_reply_is_passed_on_before_the_frame() {
        assert_eq!(
            streamable_prefix(&[0xFE, 0xFE, 0x04, 0x20, 0x01, 0xFE], 7),
            6
        );
        assert_eq!(
            streamable_prefix(&[0xFE, 0xFE, 0x06, 0x20, 0x01, 0xFE, 0xFE, 0x02], 9),
            6
        );
        assert_eq!(streamable_prefix(&[0xFE, 0xFE, 0x03, 0xFE, 0xFE], 6), 4);
        assert_eq!(
            streamable_prefix(&[0xFE, 0xFE, 0x02, 0x20, 0xFA], 5),
            4,
            "never the FA"
        );
        let mut w = Waiting::new(cmd::GET_ANGLES, true);
        let reply = Frame::new(
            cmd::GET_ANGLES,
            &[1, 0xFE, 0xFE, 0x02, 0x20, 0xFA, 0, 0, 0, 0, 0, 0],
        )
        .unwrap()
        .to_bytes();
        w.hear(&reply);
        let (given, end) = w.passed_on();
        assert_eq!(given, reply[..6], "up to the first FE of the pair");
        assert_eq!(end, Some(true));
    }

    #[test]
    fn only_a_reply_that_may_and_can_be_is_passed_on_as_it_arrives() {
        let reply = angles();
        // A request whose client may not get it so (a network link, another dialect).
        let mut w = Waiting::new(cmd::GET_ANGLES, false);
        w.hear(&reply);
        assert_eq!(w.passed_on(), (std::vec::Vec::new(), None));
        assert_eq!(w.replies().len(), 1);
        // Cut-through off in the config.
        let mut w = Waiting::new(cmd::GET_ANGLES, true);
        w.config.cut_through = false;
        w.hear(&reply);
        assert_eq!(w.passed_on(), (std::vec::Vec::new(), None));
        // Another command's frame, a LEN pymycobot does not read.
        let mut w = Waiting::new(cmd::GET_ANGLES, true);
        w.hear(&Frame::new(cmd::IS_POWER_ON, &[1]).unwrap().to_bytes());
        let long = Frame::new(cmd::GET_ANGLES, &[0; 29]).unwrap().to_bytes();
        w.idle(100);
        w.hear(&long);
        assert_eq!(w.passed_on(), (std::vec::Vec::new(), None));
        // A frame that does not begin a transmission (right behind other bytes).
        let mut w = Waiting::new(cmd::GET_ANGLES, true);
        let mut behind = std::vec![0x11, 0x22];
        behind.extend_from_slice(&reply);
        w.hear(&behind);
        assert_eq!(w.passed_on(), (std::vec::Vec::new(), None));
        assert_eq!(w.replies().len(), 1, "still the reply, whole");
    }

    #[test]
    fn a_reply_that_may_be_a_late_one_is_not_passed_on_before_it_is_whole() {
        let mut w = Waiting::new(cmd::GET_ANGLES, true);
        w.idle(BasicConfig::default().reply_timeout_us);
        assert!(matches!(w.events.last(), Some(Event::Timeout(_))));
        // The next request asks the same; the first one's answer comes now.
        w.ask(cmd::GET_ANGLES, true);
        w.events.clear();
        w.hear(&angles());
        assert_eq!(w.passed_on(), (std::vec::Vec::new(), None));
        assert_eq!(
            w.replies().len(),
            1,
            "a resend of the same question: its answer"
        );
    }

    /// An idle forwarder whose listener last heard another station's byte at `t_us`.
    fn idle_after_a_byte_at(t_us: u64) -> (Forwarder, Listener, BasicConfig) {
        let mut forwarder = Forwarder::new();
        let mut listener = bus_listener(EchoMode::Absent);
        let config = BasicConfig::default();
        forwarder.on_bus_byte(t_us, 0xFF, &mut listener, &config, |_| {});
        (forwarder, listener, config)
    }

    #[test]
    fn the_bus_is_held_only_early_in_the_atoms_gap() {
        for quiet_us in 0..200 {
            let (mut forwarder, mut listener, config) = idle_after_a_byte_at(1_000);
            let mut port = Port::default();
            forwarder.hold(1_000 + quiet_us, &mut port, &mut listener, true, &config);
            let early =
                (timing::BUS_QUIET_BEFORE_SEND_US..LATEST_START_IN_GAP_US).contains(&quiet_us);
            let expected: &[u8] = if early { &[HOLD_BYTE] } else { &[] };
            assert_eq!(port.0, expected, "quiet {quiet_us} us");
        }
    }

    #[test]
    fn the_bus_is_held_only_for_a_request_coming_while_idle_and_if_configured() {
        let early = 1_000 + timing::BUS_QUIET_BEFORE_SEND_US;
        let (mut forwarder, mut listener, config) = idle_after_a_byte_at(1_000);
        let mut port = Port::default();
        forwarder.hold(early, &mut port, &mut listener, false, &config);
        let off = BasicConfig {
            bus_hold: false,
            ..config
        };
        forwarder.hold(early, &mut port, &mut listener, true, &off);
        assert!(port.0.is_empty(), "nothing coming, or holding off");
        let mut w = Waiting::new(cmd::GET_ANGLES, true);
        let quiet_since = w.now_us;
        w.forwarder.hold(
            quiet_since + 65,
            &mut port,
            &mut w.listener,
            true,
            &w.config,
        );
        assert!(port.0.is_empty(), "a request in flight");
    }

    #[test]
    fn holds_alternate_with_another_stations_turn() {
        let (mut forwarder, mut listener, config) = idle_after_a_byte_at(1_000);
        let mut port = Port::default();
        // A poll at `t`: time passes (echo verdicts), then the hold.
        let poll = |t: u64, coming: bool, f: &mut Forwarder, l: &mut Listener, p: &mut Port| {
            f.on_time(t, &*p, l, &config, |_| {});
            f.hold(t, p, l, coming, &config);
        };
        // A hold: a byte early in each gap while the request comes.
        poll(1_065, true, &mut forwarder, &mut listener, &mut port);
        poll(1_140, true, &mut forwarder, &mut listener, &mut port);
        assert_eq!(port.0, [HOLD_BYTE; 2]);
        // It was no request after all (the frame failed): the hold ends. The next one waits
        // for another station's turn on the bus.
        poll(1_215, false, &mut forwarder, &mut listener, &mut port);
        poll(1_290, true, &mut forwarder, &mut listener, &mut port);
        poll(1_365, true, &mut forwarder, &mut listener, &mut port);
        assert_eq!(port.0.len(), 2, "no hold before the Atom had its turn");
        forwarder.on_bus_byte(1_400, 0xFF, &mut listener, &config, |_| {});
        poll(1_465, true, &mut forwarder, &mut listener, &mut port);
        assert_eq!(port.0.len(), 3, "after it");
    }

    #[test]
    fn only_the_basics_own_requests_are_ever_sent_again() {
        let request = |origin| Request {
            frame: Frame::new(cmd::GET_ANGLES, &[]).unwrap(),
            origin,
            answer: protocol_core::dialect::Answer::AsIs,
            queued_us: 0,
            cut_through: false,
        };
        let client = crate::request::Client::new(crate::request::LinkId::USB, 0);
        assert!(!may_resend(&request(Origin::Host(client))));
        assert!(may_resend(&request(Origin::Probe)));
        assert!(may_resend(&request(Origin::PowerOn)));
    }
}
