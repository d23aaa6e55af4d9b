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

use open_mycobot::sim::{BusyClient, FlashTiming, HostLink, RobotConfig, VirtualRobot};
use protocol_core::command::{CollisionThreshold, JointId, Request, ServoSelect};

/// What the writing client writes, over and over.
#[derive(Clone, Copy, Debug)]
enum Writes {
    /// Collision thresholds (each a new value) and a backup of every servo: the Atom's flash.
    AtomSettings,
    /// The Wi-Fi server port, two values in turn: the Basic's flash.
    WifiPort,
}

impl Writes {
    fn requests(self) -> Vec<Request> {
        match self {
            Self::AtomSettings => (0..20u8)
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
                .collect(),
            Self::WifiPort => [9_001, 9_002]
                .map(|port| Request::SetServerPort { port })
                .to_vec(),
        }
    }
}

fn run(timing: FlashTiming, writes: Writes, seconds: u64) {
    let mut robot = VirtualRobot::new(RobotConfig {
        flash_timing: timing,
        ..RobotConfig::default()
    });
    robot.run_for(1_500_000);
    let poller = |link| BusyClient::new(link, vec![Request::GetAngles]);
    let usb = poller(HostLink::Basic);
    let net = poller(robot.connect().unwrap());
    let writer = BusyClient::new(robot.connect().unwrap(), writes.requests());
    let mut clients = [usb, net, writer];
    let end = robot.now_us() + seconds * 1_000_000;
    while robot.now_us() < end {
        for client in &mut clients {
            client.serve(&mut robot);
        }
        robot.run_for(100);
    }
    println!("flash timing {timing:?}, writes {writes:?}, {seconds} s:");
    for (name, c) in ["get_angles (USB)", "get_angles (TCP)", "writes"]
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
    for writes in [Writes::AtomSettings, Writes::WifiPort] {
        for timing in [
            FlashTiming::Instant,
            FlashTiming::Typical,
            FlashTiming::Worst,
        ] {
            run(timing, writes, seconds);
        }
    }
}
