//! Straight-line moves (send_coords mode 1) stay straight when they wait in the queue (fresh
//! mode 0): a user drawing a square with queued mode-1 moves saw the later sides bow out like
//! joint moves.
#![allow(clippy::unwrap_used, clippy::expect_used, clippy::indexing_slicing)] // a test harness: a panic is a failed check

mod sim_support;

use open_mycobot::sim::VirtualRobot;
use protocol_core::command::{MoveMode, Pose, Reply, Request};
use protocol_core::units::{Centideg, DeciMm};
use sim_support::*;

/// Tool pointing down, at (x, y, 181.3) mm.
fn pose(x_mm: i16, y_mm: i16) -> Pose {
    Pose {
        x: DeciMm(x_mm * 10),
        y: DeciMm(y_mm * 10),
        z: DeciMm(1813),
        rx: Centideg(18_000),
        ry: Centideg(0),
        rz: Centideg(-9_000),
    }
}

fn get_coords(robot: &mut VirtualRobot) -> Pose {
    match ask(robot, Request::GetCoords) {
        Reply::Coords(p) => p,
        other => panic!("get_coords answered {other:?}"),
    }
}

fn line_to(robot: &mut VirtualRobot, target: Pose) {
    ack(
        robot,
        Request::SendCoords {
            pose: target,
            speed: speed(40),
            mode: Some(MoveMode::Linear),
        },
    );
}

/// A robot at (226.2, -63.4) ... pointing down, moved by a straight line to (230, -63.4).
fn at_first_corner() -> VirtualRobot {
    let mut robot = arm();
    ack(
        &mut robot,
        Request::SendAngles {
            angles: degrees([0.0, -30.0, -60.0, 0.0, 0.0, 0.0]),
            speed: speed(100),
        },
    );
    wait_until_stopped(&mut robot);
    line_to(&mut robot, pose(230, -63));
    wait_until_stopped(&mut robot);
    robot
}

/// Largest distance (tenth-mm) of the reported x from `x` while the arm moves (a side at
/// constant x), sampled every 20 ms until it stops.
fn worst_x_drift(robot: &mut VirtualRobot, x: DeciMm) -> i16 {
    let mut worst = 0;
    for _ in 0..400 {
        robot.run_for(20_000);
        worst = worst.max((get_coords(robot).x.0 - x.0).abs());
        if ask(robot, Request::IsMoving) == Reply::Byte(0) {
            return worst;
        }
    }
    panic!("still moving after 8 s");
}

#[test]
fn queued_straight_lines_stay_straight() {
    let mut robot = at_first_corner();
    ack(&mut robot, Request::SetFreshMode { fresh: false });
    line_to(&mut robot, pose(230, -13));
    line_to(&mut robot, pose(230, -63));
    let drift = worst_x_drift(&mut robot, DeciMm(2300));
    assert!(
        drift <= 5,
        "x strayed {drift} tenth-mm off the queued lines"
    );
}

#[test]
fn a_paused_queue_of_lines_resumes_and_finishes() {
    let mut robot = arm();
    ack(
        &mut robot,
        Request::SendAngles {
            angles: degrees([0.0, -30.0, -60.0, 0.0, 0.0, 0.0]),
            speed: speed(100),
        },
    );
    wait_until_stopped(&mut robot);
    ack(&mut robot, Request::SetFreshMode { fresh: false });
    line_to(&mut robot, pose(230, -63));
    line_to(&mut robot, pose(230, -13));
    line_to(&mut robot, pose(200, -13));
    robot.run_for(800_000);
    ack(&mut robot, Request::Pause);
    robot.run_for(500_000);
    ack(&mut robot, Request::Resume);
    wait_until_stopped(&mut robot);
    let end = get_coords(&mut robot);
    assert!(
        (end.x.0 - 2000).abs() <= 5 && (end.y.0 + 130).abs() <= 5,
        "the queue ended at {end:?}"
    );
}
