//! The frames of the MyCobotBasic Arduino library (the seed manual's layouts: big-endian values,
//! x, y, z x 10, angles x 100, no speed byte on the arcs), written here byte by byte and sent to
//! the Atom's own port, and what they do to the arm.
#![allow(clippy::unwrap_used, clippy::expect_used, clippy::indexing_slicing)] // a test harness: a panic is a failed check

mod sim_support;

use open_mycobot::sim::measure;
use open_mycobot::sim::{HostLink, VirtualRobot};
use protocol_core::command::{Reply, Request};
use protocol_core::servo::reg;
use protocol_core::timing::HOST_REPLY_DEADLINE_US;
use protocol_core::{Frame, FrameDecoder};
use sim_support::*;

const LINK: HostLink = HostLink::AtomUsb;

/// A MyCobotBasic frame: `FE FE LEN CMD DATA FA`, LEN = data + 2.
fn basic_frame(cmd: u8, data: &[u8]) -> Vec<u8> {
    let mut bytes = vec![0xFE, 0xFE, data.len() as u8 + 2, cmd];
    bytes.extend_from_slice(data);
    bytes.push(0xFA);
    bytes
}

/// A coordinate list as MyCobotBasic writes it: x, y, z x 10 and rx, ry, rz x 100, each
/// high byte first.
fn coords_bytes(c: [f64; 6]) -> Vec<u8> {
    c.iter()
        .enumerate()
        .flat_map(|(i, v)| {
            let scale = if i < 3 { 10.0 } else { 100.0 };
            ((v * scale) as i16).to_be_bytes()
        })
        .collect()
}

/// Sends `bytes` on the Atom's port and returns the reply frame.
fn send(robot: &mut VirtualRobot, bytes: &[u8]) -> Frame {
    robot.link_write(LINK, bytes);
    robot
        .await_frame(LINK, HOST_REPLY_DEADLINE_US)
        .unwrap_or_else(|| panic!("no reply to {bytes:02x?}"))
}

/// MyCobotBasic's getCoords (0x23): the pose in mm and degrees.
fn get_coords(robot: &mut VirtualRobot) -> [f64; 6] {
    let reply = send(robot, &basic_frame(0x23, &[]));
    let v: Vec<f64> = reply
        .data()
        .chunks(2)
        .map(|c| f64::from(i16::from_be_bytes([c[0], c[1]])))
        .collect();
    std::array::from_fn(|i| v[i] / if i < 3 { 10.0 } else { 100.0 })
}

fn flange_mm(robot: &VirtualRobot) -> [f64; 3] {
    measure::flange(&robot.shaft_angles_deg()).position_mm
}

/// The arm, its joints at some angles away from singularities (writeAngles, 0x22).
fn posed() -> VirtualRobot {
    let mut robot = arm();
    let mut data: Vec<u8> = [10.0, -30.0, -50.0, -10.0, 10.0, 20.0]
        .iter()
        .flat_map(|d: &f64| ((d * 100.0) as i16).to_be_bytes())
        .collect();
    data.push(100);
    assert_eq!(send(&mut robot, &basic_frame(0x22, &data)).data(), [1]);
    wait_still(&mut robot);
    robot
}

#[test]
fn write_coord_with_axis_0_moves_x_as_the_seed_manual_numbers_it() {
    let mut robot = posed();
    let start = get_coords(&mut robot);
    // writeCoord(Axis::X, x - 30, 30): axis byte 0.
    let value = ((start[0] - 30.0) * 10.0) as i16;
    let [hi, lo] = value.to_be_bytes();
    let reply = send(&mut robot, &basic_frame(0x24, &[0, hi, lo, 30]));
    assert_eq!(reply.cmd(), 0x24);
    assert_eq!(reply.data(), [1], "accepted");
    wait_still(&mut robot);
    let now = get_coords(&mut robot);
    assert!(
        (now[0] - (start[0] - 30.0)).abs() <= 0.5,
        "{start:?} -> {now:?}"
    );
    assert!((now[1] - start[1]).abs() <= 0.5 && (now[2] - start[2]).abs() <= 0.5);
}

#[test]
fn set_pid_writes_every_joint_and_get_pid_reads_it_back() {
    let mut robot = arm();
    // setPid: P, I, D of joints 1..3, then of joints 4..6.
    let pids = [20, 0, 3, 30, 2, 10];
    assert_eq!(send(&mut robot, &basic_frame(0x2C, &pids)).data(), [1]);
    robot.run_for(100_000);
    for id in 1..=6u8 {
        let servo = robot.servo(id).expect("servo");
        let want = if id <= 3 { [20, 3, 0] } else { [30, 10, 2] };
        let got = [
            servo.reg(reg::P_COEFFICIENT),
            servo.reg(reg::D_COEFFICIENT),
            servo.reg(reg::I_COEFFICIENT),
        ];
        assert_eq!(got, want, "servo {id}: P, D, I registers");
        assert_eq!(servo.reg(reg::EEPROM_LOCK), 1, "servo {id} locked again");
    }
    // getPid: FE FE 02 2D FA -> FE FE 08 2D p i d p i d FA.
    let reply = send(&mut robot, &basic_frame(0x2D, &[]));
    assert_eq!(reply.cmd(), 0x2D);
    assert_eq!(reply.data(), pids);
    // The gripper keeps its own gains.
    assert_eq!(robot.servo(7).expect("gripper").reg(reg::P_COEFFICIENT), 10);
}

#[test]
fn get_pid_answers_the_factory_gains_and_255_for_a_missing_servo() {
    let mut robot = arm();
    let reply = send(&mut robot, &basic_frame(0x2D, &[]));
    // Joint 1 (10, 0, 1 as P, D, I) and joint 4 (32, 32, 0), in P, I, D order.
    assert_eq!(reply.data(), [10, 1, 0, 32, 0, 32]);
    // The same through the Basic, whose bus the reply shares with the servo reads.
    assert_eq!(
        ask(&mut robot, Request::GetPid),
        Reply::Bytes6([10, 1, 0, 32, 0, 32])
    );
    robot
        .servo_mut(4)
        .expect("servo 4")
        .set_faults(open_mycobot::sim::Faults::NO_ANSWER);
    let reply = send(&mut robot, &basic_frame(0x2D, &[]));
    assert_eq!(reply.data(), [10, 1, 0, 255, 255, 255]);
}

#[test]
fn move_c_coords_with_three_and_with_two_poses() {
    let mut robot = posed();
    let c = get_coords(&mut robot);
    let offset = |dx: f64, dy: f64, dz: f64| [c[0] + dx, c[1] + dy, c[2] + dz, c[3], c[4], c[5]];
    // moveCCoords(begin, middle, end): 0x8B, LEN 38, no speed.
    let (begin, middle, end) = (
        offset(-20.0, -20.0, 0.0),
        offset(-40.0, 20.0, 20.0),
        offset(-10.0, 50.0, 0.0),
    );
    let mut data = coords_bytes(begin);
    data.extend(coords_bytes(middle));
    data.extend(coords_bytes(end));
    let frame = basic_frame(0x8B, &data);
    assert_eq!(frame[2], 38, "MOVEC_COORDS_DEFAULT_LEN");
    assert_eq!(send(&mut robot, &frame).data(), [1]);
    let mut passed_middle = f64::MAX;
    let mut passed_begin = f64::MAX;
    let close = |p: &[f64; 3], q: &[f64; 6]| measure::distance_mm(p, &[q[0], q[1], q[2]]);
    robot.run_for(30_000);
    while robot.atom().is_moving() {
        robot.run_for(1_000);
        let p = flange_mm(&robot);
        passed_begin = passed_begin.min(close(&p, &begin));
        passed_middle = passed_middle.min(close(&p, &middle));
    }
    robot.run_for(200_000);
    assert!(
        passed_begin < 0.3,
        "{passed_begin:.3} mm from the begin pose"
    );
    assert!(
        passed_middle < 0.3,
        "{passed_middle:.3} mm from the middle pose"
    );
    assert!(close(&flange_mm(&robot), &end) < 0.3);

    // moveCCoords(middle, end): 0x8C, LEN 26, from where the arm is, back towards the start.
    let (middle, end) = (offset(-25.0, 25.0, 10.0), offset(0.0, 0.0, 0.0));
    let mut data = coords_bytes(middle);
    data.extend(coords_bytes(end));
    let frame = basic_frame(0x8C, &data);
    assert_eq!(frame[2], 26, "MOVEC_COORDS_LEN");
    assert_eq!(send(&mut robot, &frame).data(), [1]);
    wait_still(&mut robot);
    assert!(close(&flange_mm(&robot), &end) < 0.3);
    let back = get_coords(&mut robot);
    assert!(
        (back[0] - c[0]).abs() <= 0.3 && (back[1] - c[1]).abs() <= 0.3,
        "{back:?} vs {c:?}"
    );
}

#[test]
fn replies_are_single_frames_with_the_request_code() {
    let mut robot = arm();
    for (cmd, data) in [(0x2D, vec![]), (0x2C, vec![10, 0, 1, 32, 0, 32])] {
        robot.link_write(LINK, &basic_frame(cmd, &data));
        robot.run_for(100_000);
        let mut bytes = Vec::new();
        robot.link_read(LINK, &mut bytes);
        let mut frames = Vec::new();
        FrameDecoder::new().feed(&bytes, |f| frames.push(f));
        assert_eq!(frames.len(), 1, "{cmd:#04x}: {bytes:02x?}");
        assert_eq!(frames[0].cmd(), cmd);
    }
}
