//! Drag teaching as an owner does it: release the arm, start recording, move it by hand, end,
//! read the points back one by one, and replay them.
#![allow(clippy::unwrap_used, clippy::expect_used, clippy::indexing_slicing)] // a test harness: a panic is a failed check

mod sim_support;

use firmware_atom::drag::{CAPACITY, SAMPLE_PERIOD_US};
use open_mycobot::sim::VirtualRobot;
use protocol_core::command::{DragPoint, Reply, Request};
use protocol_core::units::Steps;
use sim_support::*;

fn count(robot: &mut VirtualRobot, request: Request) -> i16 {
    match ask(robot, request.clone()) {
        Reply::Int16(n) => n,
        other => panic!("{request:?} answered {other:?}"),
    }
}

fn read_points(robot: &mut VirtualRobot, n: i16) -> Vec<DragPoint> {
    let points = (0..n)
        .map(|i| match ask(robot, Request::DragGetRecordData) {
            Reply::DragPoint(Some(p)) => p,
            other => panic!("point {i} of {n}: {other:?}"),
        })
        .collect();
    assert_eq!(
        ask(robot, Request::DragGetRecordData),
        Reply::DragPoint(None),
        "after the last point"
    );
    points
}

fn position(robot: &VirtualRobot, id: u8) -> i32 {
    i32::from(robot.servo(id).expect("servo").present_position())
}

#[test]
fn a_hand_move_is_recorded_read_back_in_order_and_replayed() {
    let mut robot = arm();
    ack(&mut robot, Request::ReleaseAllServos { undamped: None });
    robot.run_for(100_000);
    assert_eq!(count(&mut robot, Request::DragClearRecordData), 0);
    assert_eq!(count(&mut robot, Request::DragStartRecord), 0);
    // The hand swings joint 1 by 45 deg and joint 2 by -30 deg in 2 s, then lets go.
    let start = std::array::from_fn::<i32, 6, _>(|j| position(&robot, j as u8 + 1));
    assert!(robot.turn_by_hand(1, 2048 + 512, 2_000_000));
    assert!(robot.turn_by_hand(2, 2048 - 341, 2_000_000));
    robot.run_for(2_500_000);
    let n = count(&mut robot, Request::DragEndRecord);
    // 20 points a second for the 2.5 s (and the few ms the requests took).
    let expected = (2_500_000 / SAMPLE_PERIOD_US) as i16;
    assert!((expected..=expected + 2).contains(&n), "{n} points");
    robot.run_for(500_000);
    assert_eq!(count(&mut robot, Request::DragGetRecordLen), n, "ended");

    let points = read_points(&mut robot, n);
    let first = points.first().expect("points");
    let last = points.last().expect("points");
    assert_eq!(
        first.encoders.map(|s| i32::from(s.0)),
        start,
        "starts where the arm was"
    );
    assert_eq!(last.encoders[0], Steps(2048 + 512));
    assert_eq!(last.encoders[1], Steps(2048 - 341));
    assert!(last.encoders[2..].iter().all(|&e| e == Steps(2048)));
    for pair in points.windows(2) {
        assert!(
            pair[1].encoders[0] >= pair[0].encoders[0],
            "joint 1 in order"
        );
        assert!(
            pair[1].encoders[1] <= pair[0].encoders[1],
            "joint 2 in order"
        );
    }
    // The hand's speed peaks half way at pi/2 x 256 steps/s for joint 1, 268 for joint 2.
    let peak = |j: usize| points.iter().map(|p| p.speeds_steps_per_s[j]).max();
    assert!(
        peak(0).is_some_and(|v| (380..=420).contains(&v)),
        "{:?}",
        peak(0)
    );
    assert!(
        peak(1).is_some_and(|v| (250..=290).contains(&v)),
        "{:?}",
        peak(1)
    );
    assert_eq!(last.speeds_steps_per_s, [0; 6], "at rest at the end");

    // Replay: back to the start, then the points as a 20 Hz stream of set encoders.
    ack(&mut robot, Request::PowerOn);
    ack(
        &mut robot,
        Request::SetEncoders {
            encoders: first.encoders,
            speed: speed(100),
        },
    );
    wait_until_stopped(&mut robot);
    assert!((position(&robot, 1) - start[0]).abs() <= 2);
    let mut halfway = None;
    for (i, p) in points.iter().enumerate() {
        let sent = robot.now_us();
        ack(
            &mut robot,
            Request::SetEncoders {
                encoders: p.encoders,
                speed: speed(100),
            },
        );
        if i == points.len() / 2 {
            halfway = Some(position(&robot, 1));
        }
        robot.run_until(sent + SAMPLE_PERIOD_US);
    }
    wait_until_stopped(&mut robot);
    let halfway = halfway.expect("half way");
    assert!(
        (2048 + 150..2048 + 362).contains(&halfway),
        "joint 1 half way through the replay: {halfway}"
    );
    assert!((position(&robot, 1) - (2048 + 512)).abs() <= 2);
    assert!((position(&robot, 2) - (2048 - 341)).abs() <= 2);

    assert_eq!(count(&mut robot, Request::DragClearRecordData), 0);
    assert_eq!(count(&mut robot, Request::DragGetRecordLen), 0);
    assert_eq!(
        ask(&mut robot, Request::DragGetRecordData),
        Reply::DragPoint(None)
    );
}

#[test]
fn a_full_recording_stops_by_itself_and_says_so() {
    let mut robot = arm();
    ack(&mut robot, Request::ReleaseAllServos { undamped: None });
    assert_eq!(count(&mut robot, Request::DragStartRecord), 0);
    let full_after_us = CAPACITY as u64 * SAMPLE_PERIOD_US;
    robot.run_for(full_after_us + 1_000_000);
    assert!(!robot.atom().drag_record().1, "stopped");
    let full = CAPACITY as i16;
    assert_eq!(count(&mut robot, Request::DragGetRecordLen), full);
    // A new start records nothing until the points are cleared.
    assert_eq!(count(&mut robot, Request::DragStartRecord), full);
    robot.run_for(200_000);
    assert_eq!(count(&mut robot, Request::DragEndRecord), full);
    assert_eq!(count(&mut robot, Request::DragClearRecordData), 0);
    assert_eq!(count(&mut robot, Request::DragStartRecord), 0);
    robot.run_for(SAMPLE_PERIOD_US * 3);
    assert!(count(&mut robot, Request::DragEndRecord) >= 3);
}
