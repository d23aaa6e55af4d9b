//! A client that keeps the arm busy: it sends its requests in turn, each as soon as the last
//! one was answered (or given up on), and counts how its answers came. What the flash and load
//! tests and benchmarks drive the robot with (`tests/sim_flash_writes.rs`,
//! `benches/flash_writes.rs`).

use protocol_core::FrameDecoder;
use protocol_core::command::Request;
use protocol_core::timing::HOST_REPLY_DEADLINE_US;

use super::{HostLink, VirtualRobot};

/// The Basic's deadline for the Atom's answer, in us: an answer later than this is late.
pub const LATE_US: u64 = 400_000;

/// A client sending `requests` in turn on one link. See the [module doc](self).
pub struct BusyClient {
    link: HostLink,
    requests: Vec<Request>,
    decoder: FrameDecoder,
    /// When the request waiting for its answer was sent, in us.
    sent_us: Option<u64>,
    /// Requests sent so far.
    pub sent: usize,
    /// Answers received.
    pub answered: u32,
    /// Answers that came later than [`LATE_US`].
    pub late: u32,
    /// Requests given up on: no answer within pymycobot's [`HOST_REPLY_DEADLINE_US`].
    pub lost: u32,
    /// The slowest answer, in us.
    pub worst_us: u64,
}

impl BusyClient {
    /// A client on `link` that will send `requests` in turn, over and over.
    pub fn new(link: HostLink, requests: Vec<Request>) -> Self {
        Self {
            link,
            requests,
            decoder: FrameDecoder::new(),
            sent_us: None,
            sent: 0,
            answered: 0,
            late: 0,
            lost: 0,
            worst_us: 0,
        }
    }

    /// Takes what came back, and sends the next request if none is waiting.
    pub fn serve(&mut self, robot: &mut VirtualRobot) {
        let now = robot.now_us();
        let mut bytes = Vec::new();
        robot.link_read(self.link, &mut bytes);
        for byte in bytes {
            if let (Some(_frame), Some(sent)) = (self.decoder.push(byte), self.sent_us) {
                let took = now.saturating_sub(sent);
                self.answered += 1;
                self.worst_us = self.worst_us.max(took);
                self.late += u32::from(took > LATE_US);
                self.sent_us = None;
            }
        }
        if let Some(sent) = self.sent_us
            && now.saturating_sub(sent) > HOST_REPLY_DEADLINE_US
        {
            self.lost += 1;
            self.sent_us = None;
        }
        if self.sent_us.is_none()
            && let Some(request) = self.requests.get(self.sent % self.requests.len().max(1))
        {
            robot.link_write(self.link, &request.to_frame().to_bytes());
            self.sent += 1;
            self.sent_us = Some(now);
        }
    }
}
