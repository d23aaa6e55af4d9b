//! What every end-to-end test of the virtual robot needs: a booted arm and a host that talks to
//! it the way pymycobot does (one request, one reply, checked).
#![allow(dead_code)]

use open_mycobot::sim::{HostLink, RobotConfig, VirtualRobot};
use protocol_core::command::{Direction, JointId, Reply, Request, ServoId};
use protocol_core::units::{Centideg, SpeedPercent, Steps};
use protocol_core::{Frame, FrameDecoder};

/// pymycobot sleeps this long after opening the port before its first request, in us.
pub const CLIENT_OPEN_DELAY_US: u64 = 1_500_000;
/// How long a test waits for a motion to finish, in us.
pub const MOTION_TIMEOUT_US: u64 = 15_000_000;
/// One encoder step is 0.088 degrees: angles read back within this many centidegrees.
pub const ANGLE_TOLERANCE: i16 = 10;

/// A robot built from `config`, switched on and left alone for as long as pymycobot waits
/// after opening the port.
pub fn booted(config: RobotConfig) -> VirtualRobot {
    let mut robot = VirtualRobot::new(config);
    robot.run_for(CLIENT_OPEN_DELAY_US);
    robot
}

/// The real arm, booted.
pub fn arm() -> VirtualRobot {
    booted(RobotConfig::default())
}

/// Angles in degrees to the wire unit.
pub fn degrees(d: [f64; 6]) -> [Centideg; 6] {
    d.map(|a| Centideg((a * 100.0).round() as i16))
}

/// A speed in percent.
pub fn speed(percent: u8) -> SpeedPercent {
    SpeedPercent::new(percent).expect("speed 1..=100")
}

/// A servo id 1..=7.
pub fn servo(id: u8) -> ServoId {
    ServoId::new(id).expect("servo 1..=7")
}

/// Asks `request` on the Basic's USB port; panics with the request if no usable reply came.
pub fn ask(robot: &mut VirtualRobot, request: Request) -> Reply {
    ask_on(robot, HostLink::Basic, request)
}

/// Asks `request` on `link`; panics with the request if no usable reply came.
pub fn ask_on(robot: &mut VirtualRobot, link: HostLink, request: Request) -> Reply {
    match robot.ask_on(link, &request) {
        Ok(reply) => reply,
        Err(e) => panic!("{request:?} at t = {} us: {e:?}", robot.now_us()),
    }
}

/// Asks `request` and checks it is acknowledged.
pub fn ack(robot: &mut VirtualRobot, request: Request) {
    let reply = ask(robot, request.clone());
    assert_eq!(reply, Reply::Ack, "reply to {request:?}");
}

/// Starts joint 1 jogging in the positive direction at `percent` (0x30) and checks it is taken.
pub fn jog_joint_1(robot: &mut VirtualRobot, percent: u8) {
    let joint = JointId::new(1).expect("joint 1");
    let direction = Direction::Positive;
    ack(
        robot,
        Request::JogAngle {
            joint,
            direction,
            speed: speed(percent),
        },
    );
}

/// The arm's reported joint angles (0x20).
pub fn get_angles(robot: &mut VirtualRobot) -> [Centideg; 6] {
    match ask(robot, Request::GetAngles) {
        Reply::Angles(a) => a,
        other => panic!("get_angles answered {other:?}"),
    }
}

/// Asks is_moving (0x2B) every 50 ms until the arm says it stopped; panics after the timeout.
pub fn wait_until_stopped(robot: &mut VirtualRobot) {
    let deadline = robot.now_us() + MOTION_TIMEOUT_US;
    loop {
        robot.run_for(50_000);
        if ask(robot, Request::IsMoving) == Reply::Byte(0) {
            return;
        }
        assert!(robot.now_us() < deadline, "still moving after the timeout");
    }
}

/// Watches the arm itself (no request) until it stands still, then 0.2 s more; panics after the
/// timeout.
pub fn wait_still(robot: &mut VirtualRobot) {
    robot.run_for(50_000);
    let still = robot.run_until_true(MOTION_TIMEOUT_US, |r| !r.atom().is_moving());
    assert!(still, "still moving");
    robot.run_for(200_000);
}

/// Waits for a gripper command just sent to take effect and the gripper to stop.
pub fn settle_gripper(robot: &mut VirtualRobot) {
    robot.run_for(50_000);
    let stopped = robot.run_until_true(MOTION_TIMEOUT_US, |r| {
        r.servo(7).is_some_and(|s| !s.is_moving())
    });
    assert!(stopped, "the gripper never stopped");
    robot.run_for(100_000);
}

/// Asserts that `actual` is within [`ANGLE_TOLERANCE`] of `expected`, joint by joint.
pub fn assert_angles_near(actual: [Centideg; 6], expected: [Centideg; 6], what: &str) {
    for (j, (a, e)) in actual.iter().zip(expected).enumerate() {
        assert!(
            (a.0 - e.0).abs() <= ANGLE_TOLERANCE,
            "{what}: joint {} is at {} cdeg, expected {} (all: {actual:?})",
            j + 1,
            a.0,
            e.0
        );
    }
}

/// Runs `quiet_us` more and asserts that no further byte came back on `link` (exactly one
/// reply per request, no echo, no late duplicate).
pub fn assert_silent_for(robot: &mut VirtualRobot, link: HostLink, quiet_us: u64) {
    robot.run_for(quiet_us);
    let mut extra = Vec::new();
    robot.link_read(link, &mut extra);
    assert!(
        extra.is_empty(),
        "unexpected bytes to the host: {extra:02x?}"
    );
}

/// Sends `request` and collects every frame that comes back within `window_us`.
pub fn frames_within(robot: &mut VirtualRobot, request: &Frame, window_us: u64) -> Vec<Frame> {
    robot.host_write(&request.to_bytes());
    robot.run_for(window_us);
    let mut bytes = Vec::new();
    robot.host_read(&mut bytes);
    let mut frames = Vec::new();
    FrameDecoder::new().feed(&bytes, |f| frames.push(f));
    frames
}

/// Encoder steps of a servo's present position as the wire unit.
pub fn steps(position: u16) -> Steps {
    Steps(position as i16)
}
