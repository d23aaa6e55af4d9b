//! Coordinate commands end to end: linear moves, single-axis moves, Cartesian jogs, frames.
#![allow(clippy::unwrap_used, clippy::expect_used, clippy::indexing_slicing)]

mod support;

use support::rig::{Rig, be};

fn coords(rig: &mut Rig) -> Vec<i16> {
    rig.ask_i16(0x23, &[])
}

/// A pose comfortably inside the workspace: the pose at some joint angles.
fn reachable_pose(rig: &mut Rig) -> Vec<i16> {
    rig.ask_i16(0x23, &be(&[0, -3000, -6000, 0, 0, 0]))
}

fn move_to_angles(rig: &mut Rig, q: [i16; 6]) {
    let mut data = be(&q);
    data.push(100);
    assert_eq!(rig.ask(0x22, &data), [1]);
    rig.run_ms(4000);
}

#[test]
fn linear_move_reaches_the_pose() {
    let mut rig = Rig::new();
    move_to_angles(&mut rig, [0, -3000, -6000, 0, 0, 0]);
    let start = coords(&mut rig);
    let mut target = start.clone();
    target[0] -= 300; // 30 mm along -x
    let mut data = be(&target);
    data.push(50);
    data.push(1);
    assert_eq!(rig.ask(0x25, &data), [1]);
    rig.run_ms(3000);
    let now = coords(&mut rig);
    for i in 0..3 {
        assert!((now[i] - target[i]).abs() <= 20, "{now:?} vs {target:?}");
    }
    assert_eq!(rig.ask(0x2B, &[]), [0]);
}

#[test]
fn send_coord_changes_one_axis() {
    let mut rig = Rig::new();
    move_to_angles(&mut rig, [0, -3000, -6000, 0, 0, 0]);
    let start = coords(&mut rig);
    let mut data = vec![3];
    data.extend(be(&[start[2] - 200]));
    data.push(50);
    assert_eq!(rig.ask(0x24, &data), [1]);
    rig.run_ms(3000);
    let now = coords(&mut rig);
    assert!((now[2] - (start[2] - 200)).abs() <= 20, "{now:?}");
    assert!(
        (now[0] - start[0]).abs() <= 20 && (now[1] - start[1]).abs() <= 20,
        "{now:?}"
    );
}

#[test]
fn coordinate_jog_moves_along_the_axis_and_stops() {
    let mut rig = Rig::new();
    let pose = reachable_pose(&mut rig);
    move_to_angles(&mut rig, [0, -3000, -6000, 0, 0, 0]);
    let start = coords(&mut rig);
    assert!((start[2] - pose[2]).abs() <= 20);
    assert_eq!(rig.ask(0x32, &[3, 0, 30]), [1], "jog z down");
    rig.run_ms(500);
    assert_eq!(rig.ask(0x34, &[]), [1]);
    rig.run_ms(500);
    let now = coords(&mut rig);
    assert!(now[2] < start[2] - 50, "moved down: {start:?} -> {now:?}");
    assert!(
        (now[0] - start[0]).abs() <= 30,
        "x held: {start:?} -> {now:?}"
    );
}

#[test]
fn increment_coord_jog() {
    let mut rig = Rig::new();
    move_to_angles(&mut rig, [0, -3000, -6000, 0, 0, 0]);
    let start = coords(&mut rig);
    let mut data = vec![2];
    data.extend(be(&[150]));
    data.push(50);
    assert_eq!(rig.ask(0x34, &data), [1]);
    rig.run_ms(3000);
    let now = coords(&mut rig);
    assert!(
        (now[1] - (start[1] + 150)).abs() <= 20,
        "{start:?} -> {now:?}"
    );
}

#[test]
fn tool_frame_shifts_reported_coords() {
    let mut rig = Rig::new();
    let flange = coords(&mut rig);
    // A tool 100 mm along the flange z axis.
    assert_eq!(rig.ask(0x81, &be(&[0, 0, 1000, 0, 0, 0])), [1]);
    assert_eq!(rig.ask_i16(0x82, &[]), [0, 0, 1000, 0, 0, 0]);
    assert_eq!(rig.ask(0x89, &[1]), [1]);
    assert_eq!(rig.ask(0x8A, &[]), [1]);
    let tool = coords(&mut rig);
    // At the zero pose the flange z axis points along base +x.
    assert!(
        (tool[0] - (flange[0] + 1000)).abs() <= 2,
        "{flange:?} -> {tool:?}"
    );
    assert_eq!(rig.ask(0x89, &[0]), [1]);
    assert_eq!(coords(&mut rig), flange);
}

#[test]
fn solve_ik_round_trips_forward_kinematics() {
    let mut rig = Rig::new();
    let q = [1500i16, -2500, -4000, 1000, 2000, 3000];
    let pose = rig.ask_i16(0x23, &be(&q));
    let mut data = be(&pose);
    data.extend(be(&q));
    let solved = rig.ask_i16(0x8D, &data);
    for (a, b) in solved.iter().zip(&q) {
        assert!((a - b).abs() <= 20, "{solved:?} vs {q:?}");
    }
}

#[test]
fn free_mode_button_releases_the_joints_while_held() {
    let mut rig = Rig::new();
    assert_eq!(rig.ask(0x1A, &[1]), [1]);
    assert_eq!(rig.ask(0x1B, &[]), [1]);
    rig.io.button = true;
    rig.run_ms(20);
    assert!(!rig.bus.servo(2).torque_enabled());
    rig.io.button = false;
    rig.run_ms(20);
    assert!(rig.bus.servo(2).torque_enabled());
}

#[test]
fn free_mode_holds_the_pose_the_hand_left() {
    let mut rig = Rig::new();
    assert_eq!(rig.ask(0x1A, &[1]), [1]);
    rig.io.button = true;
    rig.run_ms(20);
    // The user swings joint 1 to about 30 degrees while the button is held.
    rig.bus.servo(1).move_by_hand(2048 + 341);
    rig.run_ms(50);
    rig.io.button = false;
    rig.run_ms(500);
    assert!(rig.bus.servo(1).torque_enabled());
    let posed = rig.ask_i16(0x20, &[])[0];
    assert!((posed - 3000).abs() <= 10, "{posed}");
    rig.run_ms(1000);
    assert_eq!(rig.ask_i16(0x20, &[])[0], posed, "holds the pose");
}

#[test]
fn a_slow_coordinate_jog_is_moving_until_stopped_and_the_watchdog_ends_it() {
    let mut rig = Rig::new();
    move_to_angles(&mut rig, [0, -3000, -6000, 0, 0, 0]);
    assert_eq!(rig.ask(0x32, &[1, 1, 1]), [1], "jog x at 1 %");
    for _ in 0..5 {
        rig.run_ms(200);
        assert_eq!(rig.ask(0x2B, &[]), [1], "still jogging");
    }
    // The host goes silent: the watchdog stops the jog.
    rig.run_ms(3000);
    let a = rig.atom.present_angles();
    rig.run_ms(1000);
    assert_eq!(rig.atom.present_angles(), a, "stopped");
    assert_eq!(rig.ask(0x2B, &[]), [0]);
}
