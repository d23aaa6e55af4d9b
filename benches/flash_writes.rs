//! What the boards' flash costs the arm's clients: two clients poll `get_angles` as fast as
//! their answers come (the Basic's USB and a network client) while a third writes collision
//! thresholds (each a new value, so each is stored) and backs up every servo's parameters,
//! over and over, under virtual time. The flash stands each board still for the datasheet's
//! typical or worst times (`src/sim/flash_timing.rs`); the figures say how many answers were
//! late beyond the Basic's 400 ms, or never came, and the slowest.
//!
//! `cargo bench --bench flash_writes [SECONDS]` (virtual seconds per case, default 10). Figures,
//! not pass/fail; the target is printed beside them: no answer late or lost.
#![allow(clippy::unwrap_used, clippy::expect_used, clippy::indexing_slicing)] // a harness

use open_mycobot::sim::{FlashTiming, HostLink, RobotConfig, VirtualRobot};
use protocol_core::FrameDecoder;
use protocol_core::command::{CollisionThreshold, JointId, Request, ServoSelect};
use protocol_core::timing::HOST_REPLY_DEADLINE_US;

/// The Basic's deadline for the Atom's answer, in us.
const LATE_US: u64 = 400_000;

/// One client: what it asks in turn, and how its answers came.
struct Client {
    link: HostLink,
    requests: Vec<Request>,
    next: usize,
    decoder: FrameDecoder,
    /// When the request waiting for its answer was sent, in us.
    sent_us: Option<u64>,
    answered: u32,
    late: u32,
    lost: u32,
    worst_us: u64,
}

impl Client {
    fn new(link: HostLink, requests: Vec<Request>) -> Self {
        Self {
            link,
            requests,
            next: 0,
            decoder: FrameDecoder::new(),
            sent_us: None,
            answered: 0,
            late: 0,
            lost: 0,
            worst_us: 0,
        }
    }

    /// Sends the next request if none is waiting; takes what came back.
    fn serve(&mut self, robot: &mut VirtualRobot) {
        let now = robot.now_us();
        let mut bytes = Vec::new();
        robot.link_read(self.link, &mut bytes);
        for byte in bytes {
            if let (Some(_frame), Some(sent)) = (self.decoder.push(byte), self.sent_us) {
                let took = now - sent;
                self.answered += 1;
                self.worst_us = self.worst_us.max(took);
                if took > LATE_US {
                    self.late += 1;
                }
                self.sent_us = None;
            }
        }
        if let Some(sent) = self.sent_us
            && now - sent > HOST_REPLY_DEADLINE_US
        {
            self.lost += 1;
            self.sent_us = None;
        }
        if self.sent_us.is_none() {
            let request = &self.requests[self.next % self.requests.len()];
            self.next += 1;
            robot.link_write(self.link, &request.to_frame().to_bytes());
            self.sent_us = Some(now);
        }
    }
}

fn run(timing: FlashTiming, seconds: u64) {
    let mut robot = VirtualRobot::new(RobotConfig {
        flash_timing: timing,
        ..RobotConfig::default()
    });
    robot.run_for(1_500_000);
    let poller = |link| Client::new(link, vec![Request::GetAngles]);
    let writes = (0..20u8)
        .map(|i| {
            if i % 4 == 3 {
                Request::BackupServoParams {
                    servo: ServoSelect::All,
                }
            } else {
                Request::SetCollisionThreshold {
                    joint: JointId::new(1 + i % 6).unwrap(),
                    threshold: CollisionThreshold::new(60 + 9 * i).unwrap(),
                }
            }
        })
        .collect();
    let usb = poller(HostLink::Basic);
    let net = poller(robot.connect().unwrap());
    let writer = Client::new(robot.connect().unwrap(), writes);
    let mut clients = [usb, net, writer];
    let end = robot.now_us() + seconds * 1_000_000;
    while robot.now_us() < end {
        for client in &mut clients {
            client.serve(&mut robot);
        }
        robot.run_for(100);
    }
    println!("flash timing {timing:?}, {seconds} s:");
    for (name, c) in [
        "get_angles (USB)",
        "get_angles (TCP)",
        "thresholds + backups",
    ]
    .iter()
    .zip(&clients)
    {
        println!(
            "  {name:22} {:6} answered, {:3} late > 400 ms, {:3} lost (> 0.5 s), slowest {:6.1} ms   (target: 0 late, 0 lost)",
            c.answered,
            c.late,
            c.lost,
            c.worst_us as f64 / 1_000.0
        );
    }
}

fn main() {
    let seconds = std::env::args()
        .skip(1)
        .find_map(|a| a.parse().ok())
        .unwrap_or(10);
    for timing in [
        FlashTiming::Instant,
        FlashTiming::Typical,
        FlashTiming::Worst,
    ] {
        run(timing, seconds);
    }
}
