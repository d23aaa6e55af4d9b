//! A pose read from the arm can always be sent back: pymycobot refuses coordinates outside
//! x, y in +-281.45 mm and z in -70..412.67 mm before they reach the arm, so the arm must not
//! report a pose that only rounding pushed past those bounds (the zero pose is at z = 412.67).
#![allow(clippy::unwrap_used, clippy::expect_used, clippy::indexing_slicing)] // a test harness: a panic is a failed check

mod sim_support;

use open_mycobot::sim::VirtualRobot;
use protocol_core::command::{MoveMode, Pose, Reply, Request};
use protocol_core::units::Centideg;
use sim_support::*;

/// pymycobot 4.0.7's coordinate bounds for MyCobot280 (x, y, z in tenths of a millimetre).
fn pymycobot_accepts(p: &Pose) -> bool {
    let within = |v: i16, min: f64, max: f64| (min..=max).contains(&(f64::from(v) / 10.0));
    within(p.x.0, -281.45, 281.45) && within(p.y.0, -281.45, 281.45) && within(p.z.0, -70.0, 412.67)
}

fn coords(robot: &mut VirtualRobot, request: Request) -> Pose {
    match ask(robot, request) {
        Reply::Coords(p) => p,
        Reply::AnglesAndCoords { coords, .. } => coords,
        other => panic!("answered {other:?}"),
    }
}

#[test]
fn the_zero_pose_reads_back_as_a_pose_the_client_can_send() {
    let mut robot = arm();
    let read = coords(&mut robot, Request::GetCoords);
    assert!(pymycobot_accepts(&read), "get_coords at zero: {read:?}");
    assert!(
        (i32::from(read.z.0) - 4127).abs() <= 1,
        "still the zero pose: {read:?}"
    );
    let both = coords(&mut robot, Request::GetAnglesCoords);
    assert_eq!(both, read);
    let fk = coords(
        &mut robot,
        Request::AnglesToCoords {
            angles: [Centideg(0); 6],
        },
    );
    assert_eq!(fk, read);

    // Sending it back leaves the arm where it is.
    ack(
        &mut robot,
        Request::SendCoords {
            pose: read,
            speed: speed(50),
            mode: Some(MoveMode::Joint),
        },
    );
    wait_until_stopped(&mut robot);
    assert_angles_near(robot.measured_angles(), [Centideg(0); 6], "still at zero");
}
