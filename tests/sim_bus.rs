//! The shared bus misbehaves: boards that do or do not hear their own echo, noise on the wire,
//! transmissions that collide. Every request still gets exactly one correct reply.

mod sim_support;

use open_mycobot::sim::{BusByte, HostLink, RobotConfig, VirtualRobot};
use protocol_core::command::{Reply, Request};
use protocol_core::timing::HOST_REPLY_DEADLINE_US;
use protocol_core::{Frame, FrameDecoder};
use sim_support::*;

/// A small deterministic generator, so a failure can be replayed.
struct Lcg(u64);

impl Lcg {
    fn next(&mut self, below: u64) -> u64 {
        self.0 = self
            .0
            .wrapping_mul(6_364_136_223_846_793_005)
            .wrapping_add(1_442_695_040_888_963_407);
        (self.0 >> 33) % below
    }
}

fn user_session(robot: &mut VirtualRobot) {
    assert_eq!(ask(robot, Request::IsPowerOn), Reply::Byte(1));
    let target = degrees([12.0, -24.0, 36.0, -48.0, 60.0, -72.0]);
    ack(
        robot,
        Request::SendAngles {
            angles: target,
            speed: speed(100),
        },
    );
    wait_until_stopped(robot);
    assert_angles_near(robot.measured_angles(), target, "shafts");
    assert_angles_near(get_angles(robot), target, "get_angles");
    assert_silent_for(robot, HostLink::Basic, 100_000);
}

#[test]
fn works_whether_or_not_the_boards_hear_their_own_echo() {
    for (atom_hears_echo, basic_hears_echo) in
        [(true, true), (false, false), (true, false), (false, true)]
    {
        let mut robot = booted(RobotConfig {
            atom_hears_echo,
            basic_hears_echo,
            ..RobotConfig::default()
        });
        user_session(&mut robot);
        assert_eq!(
            robot.bus().collisions(),
            0,
            "echo atom {atom_hears_echo} basic {basic_hears_echo}: stations talked over each other"
        );
    }
}

/// Sends `request`, throws `noise` onto the bus `delay_us` later, and returns every frame the
/// host got within pymycobot's reply deadline.
fn exchange_with_noise(
    robot: &mut VirtualRobot,
    request: &Frame,
    delay_us: u64,
    noise: &[u8],
) -> Vec<Frame> {
    robot.host_write(&request.to_bytes());
    robot.run_for(delay_us);
    robot.inject_bus_noise(noise);
    robot.run_for(HOST_REPLY_DEADLINE_US - delay_us);
    let mut bytes = Vec::new();
    robot.host_read(&mut bytes);
    let mut frames = Vec::new();
    FrameDecoder::new().feed(&bytes, |f| frames.push(f));
    frames
}

#[test]
fn bus_noise_loses_nothing() {
    let mut robot = arm();
    let mut rng = Lcg(0x5eed);
    let requests = [
        Request::GetAngles,
        Request::IsPowerOn,
        Request::GetEncoders,
        Request::GetServoTemps,
        Request::SendAngles {
            angles: degrees([10.0, 10.0, 10.0, 10.0, 10.0, 10.0]),
            speed: speed(100),
        },
        Request::SendAngles {
            angles: degrees([-10.0, -10.0, -10.0, -10.0, -10.0, -10.0]),
            speed: speed(100),
        },
    ];
    for round in 0..36 {
        let request = &requests[round % requests.len()];
        let frame = request.to_frame();
        // Noise lands anywhere from while the request is still on the USB line to well after
        // the reply.
        let delay_us = rng.next(3_000);
        let noise: Vec<u8> = (0..1 + rng.next(24)).map(|_| rng.next(256) as u8).collect();
        let frames = exchange_with_noise(&mut robot, &frame, delay_us, &noise);
        assert_eq!(
            frames.len(),
            1,
            "round {round}: {request:?} with {noise:02x?} after {delay_us} us got {frames:?}"
        );
        assert_eq!(frames[0].cmd(), frame.cmd(), "round {round}");
        assert!(
            Reply::parse(request.reply_kind(), &frames[0]).is_ok(),
            "round {round}: {:?}",
            frames[0]
        );
    }
    assert!(robot.bus().collisions() > 0, "the noise did hit traffic");
    // The last move was to -10 degrees everywhere, and the arm got there.
    wait_until_stopped(&mut robot);
    assert_angles_near(
        robot.measured_angles(),
        degrees([-10.0; 6]),
        "after the noisy session",
    );
}

#[test]
fn a_request_that_collides_on_the_bus_is_still_answered() {
    let mut robot = arm();
    let basic = robot.basic_station().expect("basic");
    for request in [Request::GetAngles, Request::IsPowerOn, Request::GetEncoders] {
        let frame = request.to_frame();
        robot.bus_mut().set_tracing(true);
        robot.host_write(&frame.to_bytes());
        // Wait for the Basic to be two bytes into forwarding, then talk over it.
        let mut trace = Vec::new();
        let deadline = robot.now_us() + HOST_REPLY_DEADLINE_US;
        while trace.iter().filter(|b: &&BusByte| b.from == basic).count() < 2 {
            assert!(
                robot.now_us() < deadline,
                "the Basic never forwarded {request:?}"
            );
            robot.run_for(5);
            trace.extend(robot.bus_mut().take_trace());
        }
        let collisions_before = robot.bus().collisions();
        robot.inject_bus_noise(&[0x00, 0xFE, 0x55]);
        let reply = {
            let mut decoder = FrameDecoder::new();
            let mut found = None;
            let deadline = robot.now_us() + HOST_REPLY_DEADLINE_US;
            while found.is_none() && robot.now_us() < deadline {
                robot.run_for(100);
                let mut bytes = Vec::new();
                robot.host_read(&mut bytes);
                decoder.feed(&bytes, |f| {
                    found.get_or_insert(f);
                });
            }
            found
        };
        robot.bus_mut().set_tracing(false);
        assert!(robot.bus().collisions() > collisions_before, "noise missed");
        let reply = reply.unwrap_or_else(|| panic!("{request:?} lost after a collision"));
        assert_eq!(reply.cmd(), frame.cmd());
        assert!(Reply::parse(request.reply_kind(), &reply).is_ok());
        assert_silent_for(&mut robot, HostLink::Basic, 200_000);
    }
}
