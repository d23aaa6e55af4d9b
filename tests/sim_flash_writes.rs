//! Flash writes cost no byte: with the flash at its datasheet's worst times (a sector erase
//! stands a board still for 400 ms), two clients polling `get_angles` flat out while a third
//! writes collision thresholds, backs up every servo and restores one, over and over, get
//! every answer within
//! the Basic's 400 ms; a streamed move is the same as with a flash that takes no time; and what
//! was written is in flash once the clients rest (docs/protocol.md, "Settings in flash").
#![allow(clippy::unwrap_used, clippy::expect_used, clippy::indexing_slicing)] // tests

mod sim_support;

use open_mycobot::sim::{BusyClient, FlashTiming, HostLink, RobotConfig, VirtualRobot};
use protocol_core::command::{CollisionThreshold, JointId, Reply, Request, ServoId, ServoSelect};
use protocol_core::units::Centideg;
use sim_support::{ask, booted, speed};

/// The writer's requests: thresholds, each a new value for its joint (none so low that the
/// streamed move would feel a collision), a backup of every servo and a restore of one.
fn writes() -> Vec<Request> {
    (0..20u8)
        .map(|i| {
            if i % 5 == 3 {
                Request::BackupServoParams {
                    servo: ServoSelect::All,
                }
            } else if i % 5 == 4 {
                Request::RestoreServoParams {
                    servo: ServoSelect::One(ServoId::new(1 + i % 6).unwrap()),
                }
            } else {
                Request::SetCollisionThreshold {
                    joint: JointId::new(1 + i % 6).unwrap(),
                    threshold: CollisionThreshold::new(120 + 6 * i).unwrap(),
                }
            }
        })
        .collect()
}

/// Runs the pollers and the writer for `seconds` of virtual time, and a 50 Hz stream of
/// `send_angles` on the Basic's USB if `stream`; returns the clients and the arm's measured
/// angles every 20 ms.
fn flood(
    robot: &mut VirtualRobot,
    seconds: u64,
    stream: bool,
) -> (Vec<BusyClient>, Vec<[Centideg; 6]>) {
    let poll = vec![Request::GetAngles];
    let mut clients = vec![
        BusyClient::new(robot.connect().unwrap(), poll.clone()),
        BusyClient::new(robot.connect().unwrap(), poll.clone()),
        BusyClient::new(robot.connect().unwrap(), writes()),
    ];
    if !stream {
        clients.push(BusyClient::new(HostLink::Basic, poll));
    }
    let start = robot.now_us();
    let mut path = Vec::new();
    let mut next_sample = start;
    while robot.now_us() < start + seconds * 1_000_000 {
        for client in &mut clients {
            client.serve(robot);
        }
        if robot.now_us() >= next_sample {
            path.push(robot.measured_angles());
            if stream {
                let t = (next_sample - start) as f64 / 1e6;
                let a = (3000.0 * (t * 1.5).sin()) as i16;
                let request = Request::SendAngles {
                    angles: [a, -a / 2, a / 3, 0, a / 4, 0].map(Centideg),
                    speed: speed(100),
                };
                robot.host_write(&request.to_frame().to_bytes());
                let mut replies = Vec::new();
                robot.host_read(&mut replies);
            }
            next_sample += 20_000;
        }
        robot.run_for(100);
    }
    (clients, path)
}

fn robot(timing: FlashTiming) -> VirtualRobot {
    booted(RobotConfig {
        flash_timing: timing,
        ..RobotConfig::default()
    })
}

#[test]
fn polls_and_writes_together_are_all_answered_in_time_and_the_writes_reach_the_flash() {
    let mut robot = robot(FlashTiming::Worst);
    let (clients, _) = flood(&mut robot, 3, false);
    for (i, client) in clients.iter().enumerate() {
        assert!(
            client.answered > 100,
            "client {i}: {} answers",
            client.answered
        );
        assert_eq!((client.late, client.lost), (0, 0), "client {i}: late, lost");
    }
    // The clients rest; the Atom writes what waited, then restarts from its flash.
    robot.run_for(2_000_000);
    robot.link_read(HostLink::Basic, &mut Vec::new());
    robot.reset_atom();
    robot.run_for(200_000);
    let written = clients[2].sent;
    let mut expected = [0u8; 6];
    for request in writes().iter().cycle().take(written) {
        if let Request::SetCollisionThreshold { joint, threshold } = request {
            expected[usize::from(joint.get() - 1)] = threshold.get();
        }
    }
    assert_eq!(
        ask(&mut robot, Request::GetCollisionThresholds),
        Reply::Bytes6(expected),
        "the last thresholds survive the restart"
    );
}

#[test]
fn a_streamed_move_is_the_same_whatever_the_flash_costs() {
    let (_, instant) = flood(&mut robot(FlashTiming::Instant), 2, true);
    let (clients, worst) = flood(&mut robot(FlashTiming::Worst), 2, true);
    assert!(clients.iter().all(|c| c.late + c.lost == 0));
    assert!(
        instant.iter().any(|a| a[0].0.abs() > 1000),
        "the arm moved: {:?}",
        &instant[instant.len() - 3..]
    );
    assert_eq!(instant, worst);
}
