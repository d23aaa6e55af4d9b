//! The bus side of the transponder: sends one request at a time onto the shared wire and
//! returns the one reply that answers it.
//!
//! The forwarder hears the bus through the Basic's [`Listener`], which it is lent for each
//! byte and each poll. A request is transmitted only into a quiet wire
//! ([`timing::BUS_QUIET_BEFORE_SEND_US`]), early enough in the Atom's gap between servo
//! transactions that the Atom hears it before it would start its next one
//! ([`LATEST_START_IN_GAP_US`]), or once the gap has visibly ended with nobody talking
//! ([`ATOM_START_SEEN_US`]). The listener reads its echo back and judges it ([`Echo`]); a
//! collision (echo differs, or a foreign byte while transmitting) is retransmitted after a
//! growing back-off, at most [`BasicConfig::max_send_attempts`] times. An echo that is missing
//! or cut short proves nothing (the frame may have gone out and only our receiver missed it),
//! so it is retransmitted only if repeating the request is harmless.
//! Then only a complete `FE FE` frame with the request's CMD byte counts as the reply; servo
//! packets, other frames and late duplicates are dropped, and a request that gets no reply is
//! given up after its deadline so the next one can go. The next request is the caller's choice
//! (the [`crate::router`]'s turn, or the Basic's own), started only while the forwarder has
//! none in flight.
//!
//! A reply garbled on the wire (the start of a frame heard but no valid frame, or a frame for
//! another command) is lost for good: the Atom does not know. The Basic then sends the request again at once, instead of
//! leaving the host to wait 0.5 s and resend it itself - unless repeating it could move the
//! arm twice or act twice otherwise ([`is_repeatable`]: the incremental jogs 0x33 and 0x34, the
//! next drag-teaching point 0xF3, move round 0xD4).

use heapless::Vec;
use protocol_core::command::cmd;
use protocol_core::frame::{HEADER, MAX_FRAME_BYTES};
use protocol_core::listener::{Echo, Heard, Listener};
use protocol_core::{BytePort, Frame, timing};

use crate::config::BasicConfig;
use crate::router::Client;
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

/// True if sending `request` to the Atom twice does no harm: everything but the incremental
/// jogs (0x33 jog increment angle, 0x34 jog increment coord / jog stop), which would move the
/// arm twice as far, reading the next drag-teaching point (0xF3), which would skip one, and
/// move round (0xD4), which would turn the dispenser twice.
pub fn is_repeatable(request: &Frame) -> bool {
    !matches!(
        request.cmd(),
        cmd::JOG_INCREMENT_ANGLE
            | cmd::JOG_INCREMENT_COORD
            | cmd::DRAG_GET_RECORD_DATA
            | cmd::MOVE_ROUND
    )
}

/// Who asked for a request, and so where its reply goes.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub(crate) enum Origin {
    /// A client on a host link: the reply goes to that client.
    Host(Client),
    /// The Basic's boot power-on (0x10): the reply is consumed.
    PowerOn,
    /// The Basic's liveness probe (0x12): the reply is consumed.
    Probe,
}

/// A request to the Atom.
#[derive(Clone, Debug, PartialEq, Eq)]
pub(crate) struct Request {
    pub(crate) frame: Frame,
    pub(crate) origin: Origin,
    /// When it arrived (or was made), in microseconds.
    pub(crate) queued_us: u64,
}

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
    /// A frame from the bus answered nothing outstanding and was dropped.
    Unsolicited,
}

impl Event {
    /// Who asked for the request this event is about, if it is about one.
    pub(crate) fn origin(&self) -> Option<Origin> {
        match self {
            Self::Reply { request, .. }
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

/// The bus forwarder.
#[derive(Debug)]
pub(crate) struct Forwarder {
    current: Option<InFlight>,
}

impl Forwarder {
    pub(crate) const fn new() -> Self {
        Self { current: None }
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
        let silence_before = listener.quiet_us(now_us) > BURST_GAP_US;
        listener.push(now_us, byte, &mut |heard| {
            self.on_heard(now_us, heard, silence_before, config, &mut on_event);
        });
        let garbled = matches!(
            &self.current,
            Some(InFlight { stage: Stage::AwaitReply { reply_started: true, .. }, request, .. })
                if is_repeatable(&request.frame)
        ) && !listener.frame_in_progress();
        if garbled {
            self.on_collision(now_us, config, &mut on_event);
        }
    }

    /// Acts on what the listener heard; `silence_before` is whether the line was quiet
    /// before the byte that brought it.
    fn on_heard(
        &mut self,
        now_us: u64,
        heard: Heard,
        silence_before: bool,
        config: &BasicConfig,
        on_event: &mut impl FnMut(Event),
    ) {
        match heard {
            Heard::Echo(echo) => self.on_echo(now_us, echo, config, on_event),
            Heard::Byte(byte) => self.note_reply_byte(byte, silence_before),
            Heard::Frame(frame) => self.on_frame(frame, on_event),
            Heard::Packet(_) => {}
        }
    }

    /// Follows the transmission in flight to its end, as the listener judged its echo.
    fn on_echo(
        &mut self,
        now_us: u64,
        echo: Echo,
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
        let repeatable = is_repeatable(&request.frame);
        match echo {
            // The whole echo came back, or none (the wiring does not echo, as the listener
            // now knows): what arrives from now on is the Atom's.
            Echo::Whole | Echo::Silent => self.start_waiting(now_us, config),
            // The echo differed: the Atom heard the same garbled bytes. Sent again once our
            // transmitter is idle.
            Echo::Differed => *collided = true,
            // The echo is missing or cut short: the frame may still have reached the Atom
            // (bytes lost on our receive side). Send it again only if that is harmless.
            Echo::Missing if repeatable => self.on_collision(now_us, config, on_event),
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
        let silence_before = listener.quiet_us(now_us) > BURST_GAP_US;
        listener.on_time(now_us, &mut |heard| {
            self.on_heard(now_us, heard, silence_before, config, &mut on_event);
        });
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
            stage: Stage::AwaitReply { deadline_us, .. },
            ..
        }) = &self.current
            && now_us >= *deadline_us
            && let Some(done) = self.current.take()
        {
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

    fn on_frame(&mut self, frame: Frame, on_event: &mut impl FnMut(Event)) {
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
}

#[cfg(test)]
mod tests {
    use super::*;

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
    fn only_requests_that_act_twice_are_never_repeated() {
        let frame = |cmd: u8, data: &[u8]| Frame::new(cmd, data).unwrap();
        assert!(!is_repeatable(&frame(
            cmd::JOG_INCREMENT_ANGLE,
            &[1, 0, 100, 50]
        )));
        assert!(!is_repeatable(&frame(
            cmd::JOG_INCREMENT_COORD,
            &[1, 0, 100, 50]
        )));
        assert!(!is_repeatable(&frame(cmd::DRAG_GET_RECORD_DATA, &[])));
        assert!(!is_repeatable(&frame(cmd::MOVE_ROUND, &[])));
        assert!(is_repeatable(&frame(cmd::GET_ANGLES, &[])));
        assert!(is_repeatable(&frame(cmd::SEND_ANGLES, &[0; 13])));
    }
}
