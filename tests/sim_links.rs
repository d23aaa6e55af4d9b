//! The host talks to the arm in the other ways users have: straight into the Atom's own USB
//! port (with or without a Basic), and to the Basic's own pins.
#![allow(clippy::unwrap_used, clippy::expect_used, clippy::indexing_slicing)] // a test harness: a panic is a failed check

mod sim_support;

use open_mycobot::sim::{HostLink, RobotConfig};
use protocol_core::command::{BasicInputPin, BasicOutputPin, Reply, Request};
use sim_support::*;

#[test]
fn without_a_basic_the_atom_usb_port_drives_the_arm() {
    let mut robot = booted(RobotConfig {
        with_basic: false,
        ..RobotConfig::default()
    });
    assert_eq!(
        ask_on(&mut robot, HostLink::AtomUsb, Request::IsPowerOn),
        Reply::Byte(1)
    );
    let target = degrees([-15.0, 25.0, -35.0, 45.0, -55.0, 65.0]);
    assert_eq!(
        ask_on(
            &mut robot,
            HostLink::AtomUsb,
            Request::SendAngles {
                angles: target,
                speed: speed(100),
            }
        ),
        Reply::Ack
    );
    assert!(robot.run_until_true(MOTION_TIMEOUT_US, |r| {
        r.measured_angles()
            .iter()
            .zip(target)
            .all(|(a, t)| (a.0 - t.0).abs() <= ANGLE_TOLERANCE)
    }));
    robot.run_for(200_000);
    let Reply::Angles(reported) = ask_on(&mut robot, HostLink::AtomUsb, Request::GetAngles) else {
        panic!("no angles");
    };
    assert_angles_near(reported, target, "get_angles over the Atom's USB");
    // Nothing talks to a Basic that is not there.
    assert!(robot.ask(&Request::IsPowerOn).is_err());
}

#[test]
fn both_usb_ports_work_side_by_side() {
    let mut robot = arm();
    for _ in 0..3 {
        assert_eq!(ask(&mut robot, Request::IsPowerOn), Reply::Byte(1));
        assert_eq!(
            ask_on(&mut robot, HostLink::AtomUsb, Request::IsPowerOn),
            Reply::Byte(1)
        );
    }
    assert_silent_for(&mut robot, HostLink::Basic, 200_000);
    assert_silent_for(&mut robot, HostLink::AtomUsb, 0);
}

#[test]
fn the_basic_answers_its_own_pins() {
    let mut robot = arm();
    let pump = BasicOutputPin::new(5).expect("pin 5");
    let reply = ask(
        &mut robot,
        Request::SetBasicOutput {
            pin: pump,
            high: true,
        },
    );
    assert!(matches!(reply, Reply::Ack | Reply::Raw(_)), "{reply:?}");
    assert_eq!(robot.basic_io_mut().expect("basic").outputs, [false, true]);
    robot.basic_io_mut().expect("basic").inputs = [false, true];
    let pin = BasicInputPin::new(36).expect("pin 36");
    assert_eq!(
        ask(&mut robot, Request::GetBasicInput { pin }),
        Reply::PinLevel {
            pin: 36,
            high: true
        }
    );
    assert!(matches!(
        ask(&mut robot, Request::GetBasicVersion),
        Reply::Byte(v) if v > 0
    ));
}

#[test]
fn half_a_frame_and_garbage_from_the_host_do_not_block_the_next_request() {
    let mut robot = arm();
    let full = Request::GetAngles.to_frame().to_bytes();
    // A client killed mid-write, then line noise, then a fresh client.
    robot.host_write(&full[..3]);
    robot.run_for(20_000);
    robot.host_write(&[0x00, 0xFA, 0x13, 0xFE]);
    robot.run_for(20_000);
    let reply = ask(&mut robot, Request::IsPowerOn);
    assert_eq!(reply, Reply::Byte(1));
    assert_silent_for(&mut robot, HostLink::Basic, 100_000);
}

#[test]
fn transparent_mode_lets_the_host_talk_to_a_servo() {
    use protocol_core::command::TransponderMode;
    use protocol_core::servo::{Instruction, PacketDecoder, reg};
    let mut robot = arm();
    ack(
        &mut robot,
        Request::SetTransponderMode {
            mode: TransponderMode::Transparent,
        },
    );
    let read_id = Instruction::Read {
        addr: reg::ID,
        count: 1,
    }
    .to_packet(3)
    .expect("packet");
    let mut answers = Vec::new();
    // The Atom keeps using the bus: a request may collide, so try a few times like a tool would.
    for _ in 0..5 {
        robot.host_write(&read_id.to_bytes());
        robot.run_for(20_000);
        let mut bytes = Vec::new();
        robot.host_read(&mut bytes);
        PacketDecoder::new().feed(&bytes, |p| {
            if p.id() == 3 && p.params() == [3] {
                answers.push(p);
            }
        });
        if !answers.is_empty() {
            break;
        }
    }
    assert!(
        !answers.is_empty(),
        "servo 3 never answered through the Basic"
    );
    robot.host_write(
        &Request::SetTransponderMode {
            mode: TransponderMode::Framed,
        }
        .to_frame()
        .to_bytes(),
    );
    robot.run_for(50_000);
    let mut drain = Vec::new();
    robot.host_read(&mut drain);
    assert_eq!(ask(&mut robot, Request::IsPowerOn), Reply::Byte(1));
}
