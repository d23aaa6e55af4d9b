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

use heapless::{Deque, Vec};
use protocol_core::frame::{HEADER, MAX_FRAME_BYTES};
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
    AwaitReply {
        deadline_us: u64,
        heard_any: bool,
        last_fe: bool,
        reply_started: bool,
    },
}

#[derive(Debug)]
struct InFlight {
    request: Request,
    wire: Vec<u8, MAX_FRAME_BYTES>,
    attempts: u8,
    stage: Stage,
}

/// A request given up on whose reply may still come.
#[derive(Debug)]
struct Late {
    request: Request,
    /// After this time a frame with its CMD is no longer taken for its reply.
    until_us: u64,
}

/// The bus forwarder.
#[derive(Debug)]
pub(crate) struct Forwarder {
    current: Option<InFlight>,
    /// Requests given up on, oldest first, whose replies may still come.
    late: Deque<Late, MAX_LATE>,
}

impl Forwarder {
    pub(crate) const fn new() -> Self {
        Self {
            current: None,
            late: Deque::new(),
        }
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
        listener.push(now_us, byte, &mut |heard| {
            self.on_heard(now_us, heard, line, config, &mut on_event);
        });
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
    fn on_heard(
        &mut self,
        now_us: u64,
        heard: Heard,
        line: Line,
        config: &BasicConfig,
        on_event: &mut impl FnMut(Event),
    ) {
        match heard {
            Heard::Echo(echo) => self.on_echo(now_us, echo, line.echoes, config, on_event),
            Heard::Byte(byte) => self.note_reply_byte(byte, line.silence_before),
            Heard::Frame(frame) => self.on_frame(now_us, frame, on_event),
            Heard::Packet(_) => {}
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

    /// Notes a byte heard while waiting for the reply: whether a reply seems to have begun.
    fn note_reply_byte(&mut self, byte: u8, silence_before: bool) {
        if let Some(InFlight {
            stage:
                Stage::AwaitReply {
                    heard_any,
                    last_fe,
                    reply_started,
                    ..
                },
            ..
        }) = &mut self.current
        {
            let starts_transmission = !*heard_any || silence_before;
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
        listener.on_time(now_us, &mut |heard| {
            self.on_heard(now_us, heard, line, config, &mut on_event);
        });
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
            && let Some(done) = self.current.take()
        {
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

    #[test]
    fn only_the_basics_own_requests_are_ever_sent_again() {
        let request = |origin| Request {
            frame: Frame::new(cmd::GET_ANGLES, &[]).unwrap(),
            origin,
            answer: protocol_core::dialect::Answer::AsIs,
            queued_us: 0,
        };
        let client = crate::request::Client::new(crate::request::LinkId::USB, 0);
        assert!(!may_resend(&request(Origin::Host(client))));
        assert!(may_resend(&request(Origin::Probe)));
        assert!(may_resend(&request(Origin::PowerOn)));
    }
}
