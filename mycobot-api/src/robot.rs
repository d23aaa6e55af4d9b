//! [`MyCobot`]: one request at a time over a byte port, each waited for until a deadline.

use protocol_core::command::{ErrorCode, Reply, ReplyKind, Request};
use protocol_core::dialect::{Answer, Dialect};
use protocol_core::frame::{Frame, FrameDecoder};
use protocol_core::port::BytePort;
use protocol_core::timing::HOST_REPLY_DEADLINE_US;
use protocol_core::units::Decideg;

use crate::error::Error;

/// A monotonic clock in microseconds, given by the caller: a hardware timer on a board,
/// `std::time::Instant` on a PC, a fake in a test. Any `FnMut() -> u64` is one.
pub trait Clock {
    /// Microseconds since any fixed start; never goes backwards.
    fn now_us(&mut self) -> u64;
}

impl<F: FnMut() -> u64> Clock for F {
    fn now_us(&mut self) -> u64 {
        self()
    }
}

/// Silence inside a reply after which what came of it is dropped, in microseconds: 20 ms. A
/// sender may pause inside a reply (a USB-serial bridge's latency timer, 16 ms on FTDI's by
/// default; a busy PC relaying TCP; the virtual robot on a loaded machine), and a reply dropped
/// for a pause is lost. What the gap is for is garbage: a false frame start whose LEN runs past
/// the real reply hides it until the gap ends, which then costs the call 20 ms. (The serial
/// line's own 2 ms gap, `HOST_FRAME_GAP_US`, is the firmware's rule for cutting a request
/// short.)
pub const REPLY_FRAME_GAP_US: u64 = 20_000;

/// How long a call waits for its reply unless told otherwise: 500 ms, pymycobot's deadline
/// and the seed manual's.
pub const DEFAULT_REPLY_TIMEOUT_US: u64 = HOST_REPLY_DEADLINE_US;

/// A myCobot 280 on the far end of a host link: the Basic's USB serial, its Wi-Fi server, the
/// virtual robot, or the Atom's own USB port (pymycobot's dialect only).
///
/// Each call writes one request, in the [`Dialect`] given, and blocks until its reply has
/// come (a command with a value, or any command in the pymycobot dialect, which answers
/// `01`/`00` to the others) or the deadline has passed, polling the port and the clock: it
/// never waits longer than [`reply_timeout_us`](Self::reply_timeout_us), twice that for a
/// refusal (it then asks get error information, 0x07, for the reason). In the seed dialect a
/// command without a value gets no answer, and the call returns once its frame is written.
///
/// Replies are found with a [`FrameDecoder`] reading LEN as counted (both dialects answer so):
/// bytes outside frames are skipped, a frame with another CMD is ignored, a frame cut short
/// is dropped once the line has been quiet for [`REPLY_FRAME_GAP_US`], and what was received
/// before a request is dropped when it is written (a late reply to an earlier call cannot be
/// taken for this one's). That is right for a host link, which carries nothing but the
/// robot's replies; it is not a station on the shared bus between the Basic and the Atom
/// (servo packets, own echo, when it may transmit), which is the firmware's
/// [`Listener`](protocol_core::listener::Listener) and forwarder's job.
#[derive(Debug)]
pub struct MyCobot<P, C> {
    port: P,
    clock: C,
    dialect: Dialect,
    decoder: FrameDecoder,
    reply_timeout_us: u64,
}

impl<P: BytePort, C: Clock> MyCobot<P, C> {
    /// A robot on `port`, timed by `clock`, spoken to in `dialect` (the Basic's setting:
    /// `docs/protocol.md` section 21; pymycobot's unless changed).
    ///
    /// ```
    /// use mycobot_api::MyCobot;
    /// use protocol_core::dialect::Dialect;
    /// use protocol_core::NullPort;
    ///
    /// let start = std::time::Instant::now();
    /// let clock = move || start.elapsed().as_micros() as u64;
    /// let mut arm = MyCobot::new(NullPort, clock, Dialect::Pymycobot);
    /// arm.set_reply_timeout_us(20_000);
    /// // Nothing is attached: no reply within 20 ms.
    /// assert_eq!(arm.get_angles(), Err(mycobot_api::Error::Timeout { cmd: 0x20 }));
    /// ```
    pub fn new(port: P, clock: C, dialect: Dialect) -> Self {
        Self {
            port,
            clock,
            dialect,
            decoder: FrameDecoder::new(),
            reply_timeout_us: DEFAULT_REPLY_TIMEOUT_US,
        }
    }

    /// The dialect the calls speak.
    pub fn dialect(&self) -> Dialect {
        self.dialect
    }

    /// Speaks `dialect` from the next call on. This changes how this side talks, not the
    /// Basic's setting.
    pub fn set_dialect(&mut self, dialect: Dialect) {
        self.dialect = dialect;
    }

    /// How long a call waits for its reply, in microseconds.
    pub fn reply_timeout_us(&self) -> u64 {
        self.reply_timeout_us
    }

    /// Sets how long a call waits for its reply, in microseconds
    /// ([`DEFAULT_REPLY_TIMEOUT_US`] at first).
    pub fn set_reply_timeout_us(&mut self, timeout_us: u64) {
        self.reply_timeout_us = timeout_us;
    }

    /// The port.
    pub fn port(&self) -> &P {
        &self.port
    }

    /// The port, to change its settings (writing to it between calls is harmless: what it
    /// receives before a call is dropped).
    pub fn port_mut(&mut self) -> &mut P {
        &mut self.port
    }

    /// Gives the port and the clock back.
    pub fn into_parts(self) -> (P, C) {
        (self.port, self.clock)
    }

    /// The clock, to advance it (a program in a super-loop that hands the time in).
    pub fn clock_mut(&mut self) -> &mut C {
        &mut self.clock
    }

    /// Sends any request and returns its reply as the pymycobot dialect types it, or `None`
    /// for a command without a value in the seed dialect (nothing comes back). In the seed
    /// dialect, the joint limits (0x4A, 0x4B) and the digital input (0x62), which come back
    /// as the value alone, are given the joint or pin they were asked for.
    ///
    /// The typed calls of this crate are built on it; use it for a command they do not cover.
    /// A `00` to a command expecting anything but one byte is a refusal ([`Error::Refused`]).
    /// It is [`start`](Self::start) and [`poll`](Self::poll) until the call ends.
    pub fn request(&mut self, request: &Request) -> Result<Option<Reply>, Error> {
        let mut call = self.start(request)?;
        loop {
            if let Some(outcome) = self.poll(&mut call) {
                return outcome;
            }
        }
    }

    /// Writes `request` and returns at once, for a program that must not block (a loop that
    /// also reads buttons or draws a screen): [`poll`](Self::poll) the [`Call`] until it
    /// ends. One call at a time: starting another drops what the first would have received.
    ///
    /// ```
    /// use mycobot_api::MyCobot;
    /// use protocol_core::NullPort;
    /// use protocol_core::command::Request;
    /// use protocol_core::dialect::Dialect;
    ///
    /// let mut now = 0;
    /// let mut arm = MyCobot::new(NullPort, move || { now += 1_000; now }, Dialect::Pymycobot);
    /// let mut call = arm.start(&Request::GetAngles)?;
    /// let outcome = loop {
    ///     // ... read the buttons, draw the screen ...
    ///     if let Some(outcome) = arm.poll(&mut call) {
    ///         break outcome;
    ///     }
    /// };
    /// assert_eq!(outcome, Err(mycobot_api::Error::Timeout { cmd: 0x20 }));
    /// # Ok::<(), mycobot_api::Error>(())
    /// ```
    pub fn start(&mut self, request: &Request) -> Result<Call, Error> {
        let cmd = request.cmd();
        let frame = self
            .dialect
            .encode(request)
            .ok_or(Error::NotInDialect { cmd })?;
        let answer = match self.dialect {
            Dialect::Pymycobot => Answer::AsIs,
            Dialect::Seed => self.dialect.translate(&frame).answer,
        };
        let kind = request.reply_kind();
        let wire_kind = match (answer, kind) {
            (Answer::ValueOnly, ReplyKind::JointLimit) => ReplyKind::Int16,
            (Answer::ValueOnly, ReplyKind::PinLevel) => ReplyKind::Byte,
            _ => kind,
        };
        self.drain();
        self.port.write(&frame.to_bytes());
        let now = self.clock.now_us();
        Ok(Call {
            request: request.clone(),
            wire_kind,
            stage: if answer == Answer::Silent {
                Stage::Written
            } else {
                Stage::Reply
            },
            wire_cmd: frame.cmd(),
            deadline_us: now.saturating_add(self.reply_timeout_us),
            last_byte_us: now,
        })
    }

    /// Reads what has arrived for `call`: `None` while its reply may still come, then its
    /// outcome, as [`request`](Self::request) returns it (once; polling an ended call again
    /// gives [`Error::Timeout`]). Never blocks: it reads only the bytes already received.
    pub fn poll(&mut self, call: &mut Call) -> Option<Result<Option<Reply>, Error>> {
        let cmd = call.request.cmd();
        let now = self.clock.now_us();
        match call.stage {
            Stage::Written => {
                call.stage = Stage::Ended;
                Some(Ok(None))
            }
            Stage::Ended => Some(Err(Error::Timeout { cmd })),
            Stage::Reply => {
                let Some(reply) = self.receive(call, now) else {
                    return (now >= call.deadline_us).then(|| {
                        call.stage = Stage::Ended;
                        Err(Error::Timeout { cmd })
                    });
                };
                if reply.data() == [0] && !matches!(call.wire_kind, ReplyKind::Byte) {
                    // Refused: ask for the reason, with a deadline of its own.
                    return match self.dialect.encode(&Request::GetErrorInfo) {
                        Some(frame) => {
                            self.drain();
                            self.port.write(&frame.to_bytes());
                            let now = self.clock.now_us();
                            call.stage = Stage::Reason;
                            call.wire_cmd = frame.cmd();
                            call.deadline_us = now.saturating_add(self.reply_timeout_us);
                            call.last_byte_us = now;
                            None
                        }
                        None => {
                            call.stage = Stage::Ended;
                            Some(Err(Error::Refused { cmd, code: None }))
                        }
                    };
                }
                call.stage = Stage::Ended;
                Some(typed(call, &reply).map(Some))
            }
            Stage::Reason => {
                let code = match self.receive(call, now) {
                    Some(reply) => match reply.data() {
                        [code] => ErrorCode::from_code(*code).filter(|c| *c != ErrorCode::None),
                        _ => None,
                    },
                    None if now >= call.deadline_us => None,
                    None => return None,
                };
                call.stage = Stage::Ended;
                Some(Err(Error::Refused { cmd, code }))
            }
        }
    }

    /// Drops whatever was received before a request: a late reply to an earlier one, noise.
    /// Bounded by the reply timeout, for a port that never stops receiving.
    fn drain(&mut self) {
        self.decoder = FrameDecoder::new();
        let deadline = self.clock.now_us().saturating_add(self.reply_timeout_us);
        while self.port.read_byte().is_some() && self.clock.now_us() < deadline {}
    }

    /// The first frame with the call's CMD among the bytes received by now (at most
    /// [`POLL_READ_BUDGET`] of them); other frames and bytes are skipped.
    fn receive(&mut self, call: &mut Call, now: u64) -> Option<Frame> {
        for _ in 0..POLL_READ_BUDGET {
            let mut found = match self.port.read_byte() {
                Some(byte) => {
                    call.last_byte_us = now;
                    self.decoder.push(byte)
                }
                None if self.decoder.has_partial()
                    && now.saturating_sub(call.last_byte_us) >= REPLY_FRAME_GAP_US =>
                {
                    self.decoder.on_quiet_line()
                }
                None => return None,
            };
            while let Some(frame) = found {
                if frame.cmd() == call.wire_cmd {
                    return Some(frame);
                }
                found = self.decoder.next_frame();
            }
        }
        None
    }
}

/// Most bytes one [`MyCobot::poll`] reads, so a port that never stops receiving cannot hold it.
pub const POLL_READ_BUDGET: usize = 256;

/// A request written by [`MyCobot::start`], waiting for its reply.
#[derive(Debug)]
pub struct Call {
    request: Request,
    /// How the reply's data reads on the wire (the seed dialect's value alone).
    wire_kind: ReplyKind,
    stage: Stage,
    /// The CMD of the frame awaited (the request's, or get error information's).
    wire_cmd: u8,
    deadline_us: u64,
    /// When the last byte came (or the frame was written), for a frame cut short.
    last_byte_us: u64,
}

impl Call {
    /// The request this call sent.
    pub fn request(&self) -> &Request {
        &self.request
    }
}

/// Where a [`Call`] is.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
enum Stage {
    /// Written, no answer comes (a seed command without a value).
    Written,
    /// Waiting for the reply.
    Reply,
    /// Refused; waiting for get error information's answer.
    Reason,
    /// The outcome was given.
    Ended,
}

/// The reply typed as `call`'s request expects it, with the joint or pin a seed value-only
/// answer leaves out.
fn typed(call: &Call, reply: &Frame) -> Result<Reply, Error> {
    let cmd = call.request.cmd();
    let parsed = Reply::parse(call.wire_kind, reply).map_err(|_| Error::BadReply { cmd })?;
    Ok(match (&call.request, parsed) {
        (Request::GetJointMin { joint } | Request::GetJointMax { joint }, Reply::Int16(limit)) => {
            Reply::JointLimit {
                joint: *joint,
                limit: Decideg(limit),
            }
        }
        (Request::GetDigitalInput { pin }, Reply::Byte(level)) => Reply::PinLevel {
            pin: pin.gpio(),
            high: match level {
                0 => false,
                1 => true,
                _ => return Err(Error::BadReply { cmd }),
            },
        },
        (_, parsed) => parsed,
    })
}
