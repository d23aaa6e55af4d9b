//! Circular arcs (0x8B, 0x8C, MyCobotBasic's `moveCCoords`): the flange, measured at the
//! simulated shafts, goes along the circle through the three poses; arcs that cannot be
//! followed are refused before anything moves.
#![allow(clippy::unwrap_used, clippy::expect_used, clippy::indexing_slicing)] // a test harness: a panic is a failed check

mod sim_support;

use open_mycobot::sim::measure::{self, Circle};
use open_mycobot::sim::{AskError, VirtualRobot};
use protocol_core::command::{MoveMode, Pose, Reply, ReplyError, Request};
use protocol_core::units::{Centideg, DeciMm};
use sim_support::*;

/// A pose from millimetres and degrees.
fn pose(p: [f64; 6]) -> Pose {
    let mm = |v: f64| DeciMm((v * 10.0).round() as i16);
    let deg = |v: f64| Centideg((v * 100.0).round() as i16);
    Pose {
        x: mm(p[0]),
        y: mm(p[1]),
        z: mm(p[2]),
        rx: deg(p[3]),
        ry: deg(p[4]),
        rz: deg(p[5]),
    }
}

fn mm(p: &Pose) -> [f64; 3] {
    [p.x.0, p.y.0, p.z.0].map(|v| f64::from(v) / 10.0)
}

fn coords(robot: &mut VirtualRobot) -> Pose {
    match ask(robot, Request::GetCoords) {
        Reply::Coords(p) => p,
        other => panic!("get_coords answered {other:?}"),
    }
}

fn flange_mm(robot: &VirtualRobot) -> [f64; 3] {
    measure::flange(&robot.shaft_angles_deg()).position_mm
}

/// Where the flange goes, sampled every millisecond until the arm stops.
fn trace_until_still(robot: &mut VirtualRobot) -> Vec<[f64; 3]> {
    let mut trace = vec![flange_mm(robot)];
    robot.run_for(30_000);
    while robot.atom().is_moving() {
        robot.run_for(1_000);
        trace.push(flange_mm(robot));
        assert!(trace.len() < 30_000, "still moving after 30 s");
    }
    trace
}

fn error_code(robot: &mut VirtualRobot) -> Reply {
    ask(robot, Request::GetErrorInfo)
}

/// The arm at joint angles where a 40 mm circle fits around the flange in every direction.
fn posed() -> (VirtualRobot, Pose) {
    let mut robot = arm();
    ack(
        &mut robot,
        Request::SendAngles {
            angles: degrees([10.0, -30.0, -50.0, -10.0, 10.0, 20.0]),
            speed: speed(100),
        },
    );
    wait_until_stopped(&mut robot);
    robot.run_for(300_000);
    let here = coords(&mut robot);
    (robot, here)
}

fn shifted(p: &Pose, dx: f64, dy: f64, dz: f64) -> Pose {
    let add = |v: DeciMm, d: f64| DeciMm(v.0 + (d * 10.0).round() as i16);
    Pose {
        x: add(p.x, dx),
        y: add(p.y, dy),
        z: add(p.z, dz),
        ..*p
    }
}

#[test]
fn an_arc_from_here_follows_the_circle_through_its_poses() {
    let (mut robot, here) = posed();
    let via = shifted(&here, -40.0, 40.0, 10.0);
    let end = shifted(&here, 0.0, 80.0, 0.0);
    let circle = Circle::through(&flange_mm(&robot), &mm(&via), &mm(&end)).expect("a circle");
    ack(&mut robot, Request::SetSpeed { speed: speed(50) });
    ack(
        &mut robot,
        Request::MoveCCoordsFromHere { middle: via, end },
    );
    let trace = trace_until_still(&mut robot);
    let off = trace
        .iter()
        .map(|p| circle.distance_mm(p))
        .fold(0.0, f64::max);
    let nearest_via = trace
        .iter()
        .map(|p| measure::distance_mm(p, &mm(&via)))
        .fold(f64::MAX, f64::min);
    let last = trace.last().expect("a trace");
    assert!(off < 0.3, "{off:.3} mm off the circle");
    assert!(
        nearest_via < 0.3,
        "passes {nearest_via:.3} mm from the via pose"
    );
    assert!(
        measure::distance_mm(last, &mm(&end)) < 0.2,
        "ends at {last:?}"
    );
    assert_eq!(error_code(&mut robot), Reply::Byte(0));
}

#[test]
fn an_arc_with_a_begin_goes_there_first_then_along_the_circle() {
    let (mut robot, here) = posed();
    let begin = shifted(&here, -20.0, -20.0, 0.0);
    let middle = shifted(&here, -40.0, 20.0, 20.0);
    let end = shifted(&here, -10.0, 50.0, 0.0);
    ack(&mut robot, Request::MoveCCoords { begin, middle, end });
    let trace = trace_until_still(&mut robot);
    let at_begin = trace
        .iter()
        .position(|p| measure::distance_mm(p, &mm(&begin)) < 0.3)
        .expect("reaches the begin pose");
    let circle = Circle::through(&mm(&begin), &mm(&middle), &mm(&end)).expect("a circle");
    let (to_begin, arc) = trace.split_at(at_begin);
    let start = to_begin.first().copied().unwrap_or_default();
    let line_off = to_begin
        .iter()
        .map(|p| measure::distance_to_segment_mm(p, &start, &mm(&begin)))
        .fold(0.0, f64::max);
    assert!(
        line_off < 0.3,
        "{line_off:.3} mm off the line to the begin pose"
    );
    let off = arc
        .iter()
        .map(|p| circle.distance_mm(p))
        .fold(0.0, f64::max);
    assert!(off < 0.4, "{off:.3} mm off the circle");
    assert!(
        arc.iter()
            .any(|p| measure::distance_mm(p, &mm(&middle)) < 0.3),
        "misses the middle pose"
    );
    let last = trace.last().expect("a trace");
    assert!(
        measure::distance_mm(last, &mm(&end)) < 0.2,
        "ends at {last:?}"
    );
}

#[test]
fn arcs_that_cannot_be_followed_are_refused_before_anything_moves() {
    let (mut robot, here) = posed();
    let refused = |robot: &mut VirtualRobot, request: Request, code: u8| {
        ack(robot, Request::ClearErrorInfo);
        let before = robot.measured_angles();
        assert_eq!(
            robot.ask(&request),
            Err(AskError::BadReply(ReplyError::BadValue(0))),
            "{request:?}"
        );
        assert_eq!(error_code(robot), Reply::Byte(code), "{request:?}");
        robot.run_for(300_000);
        assert_eq!(robot.measured_angles(), before, "moved after {request:?}");
        assert!(!robot.atom().is_moving());
    };
    // Three points on one line, and the via pose on the start: no circle (33).
    refused(
        &mut robot,
        Request::MoveCCoordsFromHere {
            middle: shifted(&here, 10.0, 10.0, 0.0),
            end: shifted(&here, 20.0, 20.0, 0.0),
        },
        33,
    );
    refused(
        &mut robot,
        Request::MoveCCoordsFromHere {
            middle: here,
            end: shifted(&here, 20.0, 20.0, 0.0),
        },
        33,
    );
    // An end out of reach (32).
    refused(
        &mut robot,
        Request::MoveCCoordsFromHere {
            middle: shifted(&here, 10.0, 10.0, 5.0),
            end: shifted(&here, 400.0, 0.0, 0.0),
        },
        32,
    );
    // Three reachable poses whose circle goes the long way round, out of reach (34).
    let down = |x, y, z| pose([x, y, z, 180.0, 0.0, 0.0]);
    let start = down(148.0, 15.0, 160.0);
    ack(
        &mut robot,
        Request::SendCoords {
            pose: start,
            speed: speed(100),
            mode: Some(MoveMode::Joint),
        },
    );
    wait_until_stopped(&mut robot);
    robot.run_for(300_000);
    refused(
        &mut robot,
        Request::MoveCCoords {
            begin: start,
            middle: down(130.0, 146.0, 154.0),
            end: down(123.0, -59.0, 195.0),
        },
        34,
    );
}
