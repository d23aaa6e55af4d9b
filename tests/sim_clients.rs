//! Several clients on the arm at once: the Basic's USB serial and network clients (TCP, like
//! its Wi-Fi server), one of them sending garbage. Each gets exactly its own answers, read from
//! the real Atom and servos: every client asks the encoder of its own joint, and the joints
//! stand at different angles, so a reply given to the wrong client shows as a wrong value.
#![allow(clippy::unwrap_used, clippy::expect_used, clippy::indexing_slicing)] // a test harness: a panic is a failed check

mod sim_support;

use open_mycobot::sim::{HostLink, VirtualRobot};
use protocol_core::command::{Reply, Request};
use protocol_core::{Frame, FrameDecoder};
use sim_support::*;

/// Rounds in which every client asks once, all at the same time.
const ROUNDS: usize = 300;

/// The arm posed so that joints 1..4 read different encoders.
fn posed_arm() -> VirtualRobot {
    let mut robot = arm();
    ack(
        &mut robot,
        Request::SendAngles {
            angles: degrees([20.0, -40.0, 60.0, -80.0, 0.0, 0.0]),
            speed: speed(100),
        },
    );
    wait_until_stopped(&mut robot);
    robot
}

/// Collects what comes back on each of `links` until every one has a frame (or pymycobot's
/// deadline passed).
fn replies(robot: &mut VirtualRobot, links: &[HostLink]) -> Vec<Vec<Frame>> {
    let deadline = robot.now_us() + 500_000;
    let mut got: Vec<Vec<Frame>> = vec![Vec::new(); links.len()];
    let mut decoders: Vec<FrameDecoder> = links.iter().map(|_| FrameDecoder::new()).collect();
    while robot.now_us() < deadline && got.iter().any(Vec::is_empty) {
        robot.run_for(100);
        for ((link, decoder), frames) in links.iter().zip(&mut decoders).zip(&mut got) {
            let mut bytes = Vec::new();
            robot.link_read(*link, &mut bytes);
            decoder.feed(&bytes, |f| frames.push(f));
        }
    }
    got
}

/// What get_encoder answers.
fn expected_kind() -> protocol_core::command::ReplyKind {
    Request::GetEncoder { servo: servo(1) }.reply_kind()
}

#[test]
fn four_clients_one_sending_garbage_each_read_their_own_joint() {
    let mut robot = posed_arm();
    let expected: Vec<Reply> = (1..=4)
        .map(|joint| {
            ask(
                &mut robot,
                Request::GetEncoder {
                    servo: servo(joint),
                },
            )
        })
        .collect();
    assert!(
        expected.windows(2).all(|w| w[0] != w[1]),
        "the joints read alike: {expected:?}"
    );
    let mut links = vec![HostLink::Basic];
    links.extend((0..3).map(|_| robot.connect().expect("a free link")));
    let garbage_sender = links[3];
    for round in 0..ROUNDS {
        // The last network client sends noise and half a frame before its request.
        robot.link_write(
            garbage_sender,
            &[0x13, 0x00, 0xF0, 0xFE, 0xFE, 0x30, round as u8],
        );
        for (joint, link) in (1..=4).zip(&links) {
            let request = Request::GetEncoder {
                servo: servo(joint),
            }
            .to_frame();
            robot.link_write(*link, &request.to_bytes());
        }
        // The garbage sender's half frame holds its own request until its link's quiet gap
        // (20 ms) has passed: late, but its own.
        let got = replies(&mut robot, &links);
        for (i, frames) in got.iter().enumerate() {
            let parsed: Vec<_> = frames
                .iter()
                .map(|f| Reply::parse(expected_kind(), f))
                .collect();
            assert_eq!(
                parsed,
                [Ok(expected[i].clone())],
                "round {round}, client {i} ({:?})",
                links[i]
            );
        }
        assert_silent_for(&mut robot, HostLink::Basic, 0);
    }
}

#[test]
fn a_network_client_drives_the_arm_while_the_usb_client_watches() {
    let mut robot = arm();
    let net = robot.connect().expect("a free link");
    let target = degrees([-30.0, 20.0, 10.0, 0.0, 0.0, 45.0]);
    assert_eq!(
        robot.ask_on(
            net,
            &Request::SendAngles {
                angles: target,
                speed: speed(100)
            }
        ),
        Ok(Reply::Ack)
    );
    wait_until_stopped(&mut robot);
    assert_angles_near(
        get_angles(&mut robot),
        target,
        "the USB client sees the move",
    );
    robot.disconnect(net);
    assert!(!robot.link_connected(net));
    assert_eq!(
        robot.ask_on(net, &Request::IsPowerOn),
        Err(open_mycobot::sim::AskError::NoReply)
    );
    assert_eq!(ask(&mut robot, Request::IsPowerOn), Reply::Byte(1));
}
