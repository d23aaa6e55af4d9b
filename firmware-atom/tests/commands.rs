//! The Atom answering host commands like a user's script would drive it, against simulated
//! servos on a simulated wire.
#![allow(clippy::unwrap_used, clippy::expect_used, clippy::indexing_slicing)]

mod support;

use protocol_core::Frame;
use protocol_core::servo::reg;
use sim_hw::Faults;
use sim_hw::servo::{AMBIENT_C, OVERHEAT_C};
use support::rig::{Rig, be};

const GET_ANGLES: u8 = 0x20;
const SEND_ANGLES: u8 = 0x22;

fn angles(rig: &mut Rig) -> Vec<i16> {
    rig.ask_i16(GET_ANGLES, &[])
}

fn close(a: &[i16], b: &[i16], tol: i16) -> bool {
    a.len() == b.len() && a.iter().zip(b).all(|(x, y)| (x - y).abs() <= tol)
}

#[test]
fn starts_at_zero_and_powered() {
    let mut rig = Rig::new();
    assert_eq!(angles(&mut rig), [0; 6]);
    assert_eq!(rig.ask(0x12, &[]), [1]);
    assert_eq!(rig.ask(0x07, &[]), [0]);
}

#[test]
fn send_angles_moves_all_joints_to_arrive_together() {
    let mut rig = Rig::new();
    let target = [3000i16, -2000, 1500, 0, 4500, -9000];
    let mut data = be(&target);
    data.push(80);
    assert_eq!(rig.ask(SEND_ANGLES, &data), [1]);
    rig.run_ms(50);
    assert_eq!(rig.ask(0x2B, &[]), [1], "is moving");
    // Joints 1 (30 deg) and 6 (90 deg) started together: halfway through, both have covered
    // about the same share of their travel.
    rig.run_ms(400);
    let mid = angles(&mut rig);
    let share1 = f64::from(mid[0]) / 3000.0;
    let share6 = f64::from(mid[5]) / -9000.0;
    assert!((share1 - share6).abs() < 0.1, "{mid:?}");
    rig.run_ms(3000);
    let end = angles(&mut rig);
    assert!(close(&end, &target, 10), "{end:?}");
    assert_eq!(rig.ask(0x2B, &[]), [0], "not moving after arrival");
    let mut pos = be(&target);
    pos.push(0);
    assert_eq!(rig.ask(0x2A, &pos), [1], "in position");
}

#[test]
fn out_of_limit_angle_is_refused_and_changes_nothing() {
    let mut rig = Rig::new();
    let goals_before = rig.bus.goals[1].len();
    let mut data = be(&[0, 15_000, 0, 0, 0, 0]); // J2 limit is 140 deg
    data.push(50);
    assert_eq!(rig.ask(SEND_ANGLES, &data), [0]);
    assert_eq!(rig.ask(0x07, &[]), [2], "error code names joint 2");
    rig.run_ms(100);
    assert_eq!(rig.bus.goals[1].len(), goals_before);
    assert_eq!(angles(&mut rig), [0; 6]);
    assert_eq!(rig.ask(0x08, &[]), [1]);
    assert_eq!(rig.ask(0x07, &[]), [0]);
}

#[test]
fn lowered_joint_limit_is_enforced() {
    let mut rig = Rig::new();
    // Joint 1 max = 10.0 deg (wire: deg x 10).
    let mut data = vec![1];
    data.extend(be(&[100]));
    assert_eq!(rig.ask(0x4D, &data), [1]);
    assert_eq!(rig.ask(0x4B, &[1]), [1, 0, 100]);
    let mut send = vec![1];
    send.extend(be(&[2000]));
    send.push(50);
    assert_eq!(rig.ask(0x21, &send), [0]);
    assert_eq!(rig.ask(0x07, &[]), [1]);
}

#[test]
fn power_off_refuses_motion_and_power_on_restores_it() {
    let mut rig = Rig::new();
    assert_eq!(rig.ask(0x11, &[]), [1]);
    assert_eq!(rig.ask(0x12, &[]), [0]);
    rig.run_ms(20);
    assert!(!rig.bus.servo(1).torque_enabled());
    let mut send = vec![1];
    send.extend(be(&[2000]));
    send.push(50);
    assert_eq!(rig.ask(0x21, &send), [0]);
    assert_eq!(rig.ask(0x10, &[]), [1]);
    rig.run_ms(20);
    assert!(rig.bus.servo(1).torque_enabled());
    assert_eq!(rig.ask(0x21, &send), [1]);
    rig.run_ms(2000);
    assert!(close(&angles(&mut rig)[..1], &[2000], 10));
}

#[test]
fn stop_holds_where_the_arm_is() {
    let mut rig = Rig::new();
    let mut data = be(&[9000, 0, 0, 0, 0, 0]);
    data.push(30);
    rig.ask(SEND_ANGLES, &data);
    rig.run_ms(500);
    assert_eq!(rig.ask(0x29, &[]), [1]);
    rig.run_ms(300);
    let a = angles(&mut rig)[0];
    rig.run_ms(1000);
    assert_eq!(angles(&mut rig)[0], a, "stays put after stop");
    assert!(a > 0 && a < 9000);
}

#[test]
fn pause_and_resume_finish_the_move() {
    let mut rig = Rig::new();
    let mut data = be(&[6000, 0, 0, 0, 0, 0]);
    data.push(30);
    rig.ask(SEND_ANGLES, &data);
    rig.run_ms(300);
    assert_eq!(rig.ask(0x26, &[]), [1]);
    assert_eq!(rig.ask(0x27, &[]), [1], "is paused");
    rig.run_ms(1500);
    let held = angles(&mut rig)[0];
    assert!(held < 6000);
    assert_eq!(rig.ask(0x28, &[]), [1]);
    rig.run_ms(4000);
    assert!(close(&angles(&mut rig)[..1], &[6000], 10));
}

#[test]
fn queue_mode_runs_moves_in_order() {
    let mut rig = Rig::new();
    assert_eq!(rig.ask(0x16, &[0]), [1]);
    assert_eq!(rig.ask(0x17, &[]), [0]);
    let mut first = vec![1];
    first.extend(be(&[3000]));
    first.push(100);
    let mut second = vec![1];
    second.extend(be(&[-3000]));
    second.push(100);
    rig.ask(0x21, &first);
    rig.ask(0x21, &second);
    let mut max_seen = 0;
    for _ in 0..40 {
        rig.run_ms(100);
        max_seen = max_seen.max(angles(&mut rig)[0]);
    }
    assert!(max_seen > 2900, "first move ran: {max_seen}");
    assert!(close(&angles(&mut rig)[..1], &[-3000], 10));
}

#[test]
fn jog_runs_until_stopped() {
    let mut rig = Rig::new();
    assert_eq!(rig.ask(0x30, &[1, 1, 50]), [1]);
    rig.run_ms(500);
    let a = angles(&mut rig)[0];
    assert!(a > 500, "{a}");
    assert_eq!(rig.ask(0x34, &[]), [1], "jog stop (LEN 2)");
    rig.run_ms(500);
    let b = angles(&mut rig)[0];
    rig.run_ms(500);
    assert_eq!(angles(&mut rig)[0], b);
}

#[test]
fn jog_stops_by_itself_when_the_host_goes_silent() {
    let mut rig = Rig::new();
    assert_eq!(rig.ask(0x30, &[1, 0, 5]), [1]);
    rig.run_ms(3000);
    let a = rig.atom.present_angles()[0].0;
    rig.run_ms(2000);
    assert_eq!(rig.atom.present_angles()[0].0, a, "stopped by the watchdog");
    assert!(a > -16_800, "stopped before the limit: {a}");
}

#[test]
fn increment_jog_moves_relative() {
    let mut rig = Rig::new();
    let mut data = vec![3];
    data.extend(be(&[1000]));
    data.push(100);
    assert_eq!(rig.ask(0x33, &data), [1]);
    rig.run_ms(1500);
    assert_eq!(rig.ask(0x33, &data), [1]);
    rig.run_ms(1500);
    assert!(close(&angles(&mut rig)[2..3], &[2000], 10));
}

#[test]
fn encoders_round_trip() {
    let mut rig = Rig::new();
    let mut data = vec![2];
    data.extend(be(&[2548]));
    data.push(100);
    assert_eq!(rig.ask(0x3A, &data), [1]);
    rig.run_ms(1500);
    assert_eq!(rig.ask_i16(0x3B, &[2]), [2548]);
    let enc = rig.ask_i16(0x3D, &[]);
    assert_eq!(enc[1], 2548);
    // An encoder past the joint limit is refused.
    let mut bad = vec![2];
    bad.extend(be(&[4000]));
    bad.push(100);
    assert_eq!(rig.ask(0x3A, &bad), [0]);
}

#[test]
fn coords_at_zero_pose_and_joint_move_to_coords() {
    let mut rig = Rig::new();
    let c = rig.ask_i16(0x23, &[]);
    assert!(close(&c, &[456, -634, 4127, -9000, 0, -9000], 2), "{c:?}");
    // A reachable pose: the pose at some joint angles.
    let q = [1000i16, -2000, -3000, 2000, 1000, 500];
    let pose = rig.ask_i16(0x23, &be(&q));
    let mut data = be(&pose);
    data.push(50);
    data.push(0);
    assert_eq!(rig.ask(0x25, &data), [1]);
    rig.run_ms(4000);
    let now = rig.ask_i16(0x23, &[]);
    assert!(close(&now[..3], &pose[..3], 20), "{now:?} vs {pose:?}");
}

#[test]
fn unreachable_coords_are_refused_with_error_32() {
    let mut rig = Rig::new();
    let mut data = be(&[3000, 3000, 3000, 0, 0, 0]);
    data.push(50);
    assert_eq!(rig.ask(0x25, &data), [0]);
    assert_eq!(rig.ask(0x07, &[]), [32]);
    assert_eq!(angles(&mut rig), [0; 6]);
}

#[test]
fn gripper_value_and_state() {
    let mut rig = Rig::new();
    assert_eq!(rig.ask(0x67, &[60, 100]), [1]);
    rig.run_ms(1500);
    let v = rig.ask(0x65, &[])[0];
    assert!((59..=61).contains(&v), "{v}");
    assert_eq!(rig.ask(0x66, &[1, 100]), [1], "close");
    rig.run_ms(1500);
    assert_eq!(rig.ask(0x65, &[]), [0]);
    assert_eq!(rig.ask(0x69, &[]), [0], "not moving");
}

#[test]
fn servo_data_read_and_eeprom_write() {
    let mut rig = Rig::new();
    // Read present temperature (addr 63) of servo 3.
    assert_eq!(rig.ask(0x53, &[3, 63]), [AMBIENT_C]);
    // Two-byte read of the present position.
    assert_eq!(rig.ask(0x53, &[3, 56, 1]), [0x08, 0x00]);
    // EEPROM write (P coefficient, addr 21): unlocked, written, locked again.
    assert_eq!(rig.ask(0x52, &[3, 21, 40]), [1]);
    rig.run_ms(10);
    assert_eq!(rig.bus.servo(3).reg(21), 40);
    assert_eq!(rig.bus.servo(3).reg(55), 1, "EEPROM locked again");
    // The id and baud rate are refused (the servo would leave the arm's bus).
    assert_eq!(rig.ask(0x52, &[3, 5, 9]), [0]);
    rig.run_ms(10);
    assert_eq!(rig.bus.servo(3).reg(5), 3);
    // A raw write to the goal register goes through the limits.
    let mut goal = vec![1, 42];
    goal.extend(be(&[4095]));
    goal.push(1);
    let _ = rig.ask(0x52, &goal);
    rig.run_ms(10);
    assert!(rig.bus.goals[0].iter().all(|&g| g < 4000));
}

#[test]
fn missing_servo_is_reported_and_no_motion_starts_without_it() {
    let mut rig = Rig::new();
    rig.bus.servo(4).set_faults(Faults::NO_ANSWER);
    rig.run_ms(50);
    assert_eq!(rig.ask(0x50, &[4]), [4, 0]);
    assert_eq!(rig.ask(0x50, &[3]), [3, 1]);
    assert_eq!(rig.ask(0x51, &[]), [0]);
    let errors = rig.ask(0x15, &[]);
    assert_eq!(errors, [0, 0, 0, 16, 0, 0, 0]);
    assert_eq!(
        rig.ask(0xE4, &[]),
        [0, 0, 0, 0xFF, 0, 0],
        "status of a silent servo"
    );
    // Reading the missing servo answers (after bounded retries) instead of hanging.
    assert_eq!(rig.ask(0x53, &[4, 63]), [0xFF]);
    // Nobody knows where joint 4 is: a move is refused, 0x07 names the joint (20 + 4).
    let mut data = be(&[1000, 0, 0, 0, 0, 0]);
    data.push(100);
    assert_eq!(rig.ask(SEND_ANGLES, &data), [0]);
    assert_eq!(rig.ask(0x07, &[]), [24]);
    rig.run_ms(500);
    assert!(close(&angles(&mut rig)[..1], &[0], 10), "nothing moved");
}

#[test]
fn servo_fault_is_reported() {
    let mut rig = Rig::new();
    rig.bus.servo(5).set_faults(Faults::OVERHEAT);
    rig.run_ms(20);
    let status = rig.ask(0xE4, &[]);
    assert_eq!(status, [0, 0, 0, 0, 4, 0]);
    assert_eq!(rig.ask(0x15, &[])[4], 36);
    let mut temps = [AMBIENT_C; 6];
    temps[4] = OVERHEAT_C;
    assert_eq!(rig.ask(0xE5, &[]), temps);
    assert_eq!(rig.ask(0xE3, &[]), [120; 6]);
}

#[test]
fn a_servo_with_corrupt_answers_is_reported_as_such() {
    let mut rig = Rig::new();
    rig.bus.servo(6).set_faults(Faults::BAD_CHECKSUM);
    rig.run_ms(50);
    assert_eq!(rig.ask(0x15, &[]), [0, 0, 0, 0, 0, 17, 0]);
    assert_eq!(angles(&mut rig), [0; 6], "the host is still served");
}

#[test]
fn corrupt_answers_are_retried() {
    let mut rig = Rig::new();
    rig.bus.servo(2).corrupt_next_answers(1);
    assert_eq!(rig.ask(0x53, &[2, 63]), [AMBIENT_C]);
}

#[test]
fn pins_leds_and_button() {
    let mut rig = Rig::new();
    assert_eq!(rig.ask(0x60, &[22, 1]), [1]);
    assert_eq!(rig.ask(0x61, &[22, 1]), [1]);
    assert_eq!(rig.ask(0x62, &[22]), [22, 1]);
    assert_eq!(rig.ask(0x61, &[39, 1]), [0], "39 is input only");
    assert_eq!(rig.ask(0x64, &[23, 0x03, 0xE8, 128]), [1]);
    assert_eq!(rig.io.pwm[2], Some((1000, 128)));
    assert_eq!(rig.ask(0x6A, &[255, 0, 10]), [1]);
    assert_eq!(rig.io.rgb, (255, 0, 10));
    rig.io.button = true;
    assert_eq!(rig.ask(0x62, &[39]), [39, 0], "button pressed reads low");
}

#[test]
fn leds_that_take_no_colour_make_set_color_answer_an_error() {
    let mut rig = Rig::new();
    assert_eq!(rig.ask(0x6A, &[1, 2, 3]), [1]);
    // The board's LED update failed (its RMT data did not leave by the deadline).
    rig.io.leds_fail = true;
    assert_eq!(
        rig.ask(0x6A, &[255, 0, 10]),
        [0],
        "refused, not a silent ok"
    );
    assert_eq!(rig.io.rgb, (1, 2, 3));
    // The Atom goes on: the next commands are answered, the next colour is shown.
    assert_eq!(rig.ask(0x62, &[22]), [22, 0]);
    rig.io.leds_fail = false;
    assert_eq!(rig.ask(0x6A, &[255, 0, 10]), [1]);
    assert_eq!(rig.io.rgb, (255, 0, 10));
}

#[test]
fn every_command_gets_one_reply_with_its_cmd_even_when_invalid() {
    let mut rig = Rig::new();
    for (cmd, data) in [
        (0x21u8, vec![9, 0, 0, 50]), // joint 9
        (0x22, vec![0; 3]),          // wrong length
        (0x77, vec![]),              // unknown
        (0x30, vec![1, 1, 0]),       // speed 0
        (0x02, vec![]),
        (0x14, vec![]),
    ] {
        let seen = rig.bus.replies.len();
        let reply = rig.request(&Frame::new(cmd, &data).unwrap()).unwrap();
        assert_eq!(reply.cmd(), cmd);
        assert!(!reply.data().is_empty(), "never the data-less status frame");
        rig.run_ms(20);
        assert_eq!(
            rig.bus.replies.len(),
            seen + 1,
            "exactly one reply to {cmd:#04x}"
        );
    }
}

#[test]
fn works_on_a_bus_without_echo() {
    let mut rig = Rig::with(
        firmware_atom::AtomConfig {
            powered_at_boot: true,
            ..Default::default()
        },
        false,
    );
    assert_eq!(rig.ask(0x53, &[1, 63]), [AMBIENT_C]);
    let mut data = be(&[1000, 0, 0, 0, 0, 0]);
    data.push(100);
    assert_eq!(rig.ask(SEND_ANGLES, &data), [1]);
    rig.run_ms(1500);
    assert!(close(&angles(&mut rig)[..1], &[1000], 10));
}

#[test]
fn usb_link_gets_the_same_commands() {
    let mut rig = Rig::new();
    rig.usb.send_frame(&Frame::new(GET_ANGLES, &[]).unwrap());
    rig.usb.send_frame(&Frame::new(0x12, &[]).unwrap());
    rig.run_ms(5);
    assert_eq!(rig.usb.replies.len(), 2);
    assert_eq!(rig.usb.replies[0].cmd(), GET_ANGLES);
    assert_eq!(rig.usb.replies[1].data(), [1]);
    // get servo data over USB: the reply comes back on USB after the servo read.
    rig.usb.send_frame(&Frame::new(0x53, &[1, 63]).unwrap());
    rig.run_ms(10);
    assert_eq!(rig.usb.replies[2].data(), [AMBIENT_C]);
}

#[test]
fn state_refresh_runs_at_100_hz_or_faster() {
    let mut rig = Rig::new();
    let before = rig.atom.refresh_rounds();
    rig.run_ms(100);
    let rounds = rig.atom.refresh_rounds() - before;
    assert!(rounds >= 10, "{rounds} rounds in 100 ms");
}

#[test]
fn own_reply_heard_late_is_not_taken_for_a_request() {
    // A bus without echo, where the reply comes back later than the echo window (a slow
    // transceiver): angles-to-coords replies have the layout of a valid request.
    let mut rig = Rig::with(
        firmware_atom::AtomConfig {
            powered_at_boot: true,
            ..Default::default()
        },
        false,
    );
    let request = Frame::new(0x23, &be(&[0, 0, 0, 0, 0, 0])).unwrap();
    let reply = rig.request(&request).unwrap();
    rig.run_us(50);
    let replies = rig.bus.replies.len();
    rig.bus.send_raw(&reply.to_bytes());
    rig.run_ms(5);
    assert_eq!(rig.bus.replies.len(), replies, "no reply to our own reply");
}

#[test]
fn lost_goal_and_torque_writes_are_repaired_from_the_read_back() {
    let mut rig = Rig::new();
    // Servo 3 misses the SYNC WRITE of the move (a collision on the wire).
    rig.bus.servo(3).lose_next_writes(1);
    let mut data = be(&[1000, 1000, 1000, 0, 0, 0]);
    data.push(100);
    assert_eq!(rig.ask(SEND_ANGLES, &data), [1]);
    rig.run_ms(1500);
    assert!(close(&angles(&mut rig)[..3], &[1000, 1000, 1000], 10));
    // Servo 2 misses the torque-off of release all servos.
    rig.bus.servo(2).lose_next_writes(1);
    assert_eq!(rig.ask(0x13, &[]), [1]);
    rig.run_ms(30);
    assert!(!rig.bus.servo(2).torque_enabled(), "torque-off re-sent");
    assert_eq!(rig.ask(0x10, &[]), [1]);
    rig.run_ms(30);
    assert!(rig.bus.servo(2).torque_enabled());
}

#[test]
fn power_on_before_the_first_state_read_does_not_move_the_arm() {
    // The real arm: unpowered at boot, joints somewhere away from zero; the Basic sends power
    // on at once.
    let mut bus = support::ArmBus::new(true);
    bus.servo(2).move_by_hand(2500);
    let mut rig = Rig {
        atom: firmware_atom::Atom::new(firmware_atom::AtomConfig::default()),
        bus,
        usb: support::FakeUsb::default(),
        io: firmware_atom::RecordingIo::default(),
    };
    assert_eq!(rig.ask(0x10, &[]), [1]);
    rig.run_ms(100);
    let enc = rig.ask_i16(0x3D, &[]);
    assert!(
        (enc[1] - 2500).abs() <= 2,
        "joint 2 stayed where it was: {enc:?}"
    );
    assert!(rig.bus.goals[1].iter().all(|&g| (g - 2500).abs() <= 2));
}

#[test]
fn every_atom_command_answers_in_the_layout_its_client_expects() {
    use protocol_core::command::*;
    use protocol_core::units::{Centideg, DeciMm, Decideg, SpeedPercent, Steps};
    let j = |n| JointId::new(n).unwrap();
    let s = |n| ServoId::new(n).unwrap();
    let sp = SpeedPercent::new(50).unwrap();
    let pin = |g| AtomPin::new(g).unwrap();
    let zero = [Centideg(0); 6];
    let pose = Pose {
        x: DeciMm(1500),
        y: DeciMm(-634),
        z: DeciMm(2500),
        rx: Centideg(-9000),
        ry: Centideg(0),
        rz: Centideg(-9000),
    };
    let gs = GripperSpeed::new(50).unwrap();
    let requests = vec![
        Request::GetModifyVersion,
        Request::GetSystemVersion,
        Request::ClearQueue,
        Request::CheckAsyncOrSync,
        Request::GetErrorInfo,
        Request::ClearErrorInfo,
        Request::IsPowerOn,
        Request::PowerOn,
        Request::IsControllerConnected,
        Request::ReadNextError,
        Request::SetFreshMode { fresh: true },
        Request::GetFreshMode,
        Request::SetFreeMode { on: false },
        Request::IsFreeMode,
        Request::SetVisionMode { on: false },
        Request::GetRebootCount,
        Request::GetAngles,
        Request::SendAngle {
            joint: j(1),
            angle: Centideg(500),
            speed: sp,
        },
        Request::SendAngles {
            angles: zero,
            speed: sp,
        },
        Request::GetCoords,
        Request::AnglesToCoords { angles: zero },
        Request::Pause,
        Request::IsPaused,
        Request::Resume,
        Request::Stop,
        Request::IsInPosition {
            target: PositionTarget::Angles(zero),
        },
        Request::IsMoving,
        Request::SolveIk {
            target: pose,
            current: zero,
        },
        Request::GetAnglesCoords,
        Request::GetPlannedAngles,
        Request::GetPlannedCoords,
        Request::JogAngle {
            joint: j(2),
            direction: Direction::Positive,
            speed: sp,
        },
        Request::JogStop,
        Request::JogIncrementAngle {
            joint: j(2),
            increment: Centideg(100),
            speed: sp,
        },
        Request::SetEncoder {
            servo: s(1),
            encoder: Steps(2100),
            speed: Some(sp),
        },
        Request::GetEncoder { servo: s(1) },
        Request::SetEncoders {
            encoders: [Steps(2048); 6],
            speed: sp,
        },
        Request::GetEncoders,
        Request::SetEncodersDrag {
            encoders: [Steps(2048); 6],
            speeds_steps_per_s: [500; 6],
        },
        Request::GetSpeed,
        Request::SetSpeed { speed: sp },
        Request::GetJointMin { joint: j(3) },
        Request::GetJointMax { joint: j(3) },
        Request::SetJointMin {
            joint: j(3),
            limit: Decideg(-1500),
        },
        Request::SetJointMax {
            joint: j(3),
            limit: Decideg(1500),
        },
        Request::IsServoEnabled { servo: s(2) },
        Request::AreAllServosEnabled,
        Request::SetServoData {
            servo: s(2),
            address: 21,
            value: ServoValue::Byte(10),
        },
        Request::GetServoData {
            servo: s(2),
            address: 21,
            width: None,
        },
        Request::GetServoData {
            servo: s(2),
            address: 56,
            width: Some(DataWidth::Word),
        },
        Request::JointBrake { servo: s(2) },
        Request::ReleaseServo {
            servo: s(2),
            undamped: None,
        },
        Request::FocusServo {
            servo: ServoSelect::One(s(2)),
        },
        Request::GetServoSpeeds,
        Request::GetServoCurrents,
        Request::GetServoVoltages,
        Request::GetServoStatus,
        Request::GetServoTemps,
        Request::BackupServoParams {
            servo: ServoSelect::All,
        },
        Request::RestoreServoParams {
            servo: ServoSelect::All,
        },
        Request::SetPinMode {
            pin: pin(19),
            mode: PinMode::Output,
        },
        Request::SetDigitalOutput {
            pin: pin(19),
            high: true,
        },
        Request::GetDigitalInput { pin: pin(19) },
        Request::SetPwmOutput {
            pin: pin(33),
            frequency_hz: 500,
            duty: 100,
        },
        Request::GetGripperValue { gripper: None },
        Request::SetGripperStateNoSpeed {
            state: GripperState::Open,
        },
        Request::SetGripperState {
            state: GripperState::Close,
            speed: gs,
            model: GripperModel::Default,
        },
        Request::SetGripperValue {
            value: GripperValue::new(40).unwrap(),
            speed: gs,
            model: GripperModel::Default,
        },
        Request::IsGripperMoving,
        Request::SetColor {
            rgb: Rgb { r: 1, g: 2, b: 3 },
        },
        Request::SetHtsGripperTorque { torque: 300 },
        Request::GetHtsGripperTorque,
        Request::GetGripperProtectCurrent,
        Request::SetGripperProtectCurrent { current: 100 },
        Request::SetToolReference { pose },
        Request::GetToolReference,
        Request::SetWorldReference { pose },
        Request::GetWorldReference,
        Request::SetReferenceFrame {
            frame: ReferenceFrame::Base,
        },
        Request::GetReferenceFrame,
        Request::SetMovementType {
            mode: MoveMode::Joint,
        },
        Request::GetMovementType,
        Request::SetEndType {
            end: EndType::Flange,
        },
        Request::GetEndType,
        Request::SendCoords {
            pose,
            speed: sp,
            mode: Some(MoveMode::Joint),
        },
        Request::SendCoord {
            target: AxisValue::new(Axis::Z, 2400),
            speed: sp,
        },
        Request::JogIncrementCoord {
            increment: AxisValue::new(Axis::X, 50),
            speed: sp,
        },
        Request::JogCoord {
            axis: Axis::Y,
            direction: Direction::Negative,
            speed: sp,
        },
        Request::JogRpy {
            axis: RpyAxis::Yaw,
            direction: Direction::Positive,
            speed: sp,
        },
        Request::SetServoCalibration { servo: s(7) },
        Request::SetGripperCalibration,
        Request::ReleaseAllServos { undamped: None },
        Request::PowerOff,
    ];
    let mut rig = Rig::new();
    for request in requests {
        let reply = rig
            .request(&request.to_frame())
            .unwrap_or_else(|| panic!("no reply to {request:?}"));
        assert_eq!(reply.cmd(), request.cmd(), "{request:?}");
        let parsed = Reply::parse(request.reply_kind(), &reply);
        assert!(parsed.is_ok(), "{request:?} -> {reply:?}: {parsed:?}");
        rig.run_ms(30);
    }
}

#[test]
fn a_move_to_exactly_the_limit_is_accepted() {
    let mut rig = Rig::new();
    // 140 deg is not a whole encoder step; the nearest step inside the limit is used.
    let mut data = vec![2];
    data.extend(be(&[14_000]));
    data.push(100);
    assert_eq!(rig.ask(0x21, &data), [1]);
    rig.run_ms(3000);
    let a = angles(&mut rig)[1];
    assert!((13_990..=14_000).contains(&a), "{a}");
}

#[test]
fn the_basics_liveness_probe_does_not_keep_a_jog_alive() {
    let mut rig = Rig::new();
    assert_eq!(rig.ask(0x30, &[1, 1, 10]), [1]);
    for _ in 0..6 {
        rig.run_ms(1000);
        assert_eq!(rig.ask(0x12, &[]), [1], "the Basic's probe");
    }
    let a = angles(&mut rig)[0];
    rig.run_ms(1000);
    assert_eq!(angles(&mut rig)[0], a, "stopped despite the probes");
}

#[test]
fn is_in_position_waits_for_the_arm_to_come_to_rest() {
    let mut rig = Rig::new();
    let target = [2000i16, 0, 0, 0, 0, 0];
    let mut data = be(&target);
    data.push(20);
    rig.ask(SEND_ANGLES, &data);
    let mut query = be(&target);
    query.push(0);
    // Poll like sync_send_angles; the first 1 must come with the arm at the target.
    for _ in 0..100 {
        if rig.ask(0x2A, &query) == [1] {
            assert!(
                close(&angles(&mut rig), &target, 9),
                "{:?}",
                angles(&mut rig)
            );
            return;
        }
        rig.run_ms(50);
    }
    panic!("never in position");
}

#[test]
fn power_on_while_powered_does_not_cut_a_move_short() {
    // The Basic sends power on (0x10) at its boot, which may come after a client's first move.
    let mut rig = Rig::new();
    let target = [9000i16, 0, 0, 0, 0, 0];
    let mut data = be(&target);
    data.push(100);
    assert_eq!(rig.ask(SEND_ANGLES, &data), [1]);
    rig.run_ms(200);
    assert_eq!(rig.ask(0x10, &[]), [1]);
    rig.run_ms(3000);
    let end = angles(&mut rig);
    assert!(close(&end, &target, 10), "{end:?}");
}

#[test]
fn an_atom_restarted_mid_move_lets_the_move_finish_and_keeps_the_arm_powered() {
    let mut rig = Rig::new();
    let target = [6000i16, -3000, 0, 0, 0, 0];
    let mut data = be(&target);
    data.push(50);
    assert_eq!(rig.ask(SEND_ANGLES, &data), [1]);
    rig.run_ms(300);
    // The Atom reboots (the real arm's configuration: unpowered at boot until told).
    rig.atom = firmware_atom::Atom::new(firmware_atom::AtomConfig::default());
    rig.run_ms(4000);
    for id in 1..=6 {
        assert!(rig.bus.servo(id).torque_enabled(), "servo {id} went limp");
    }
    let end = angles(&mut rig);
    assert!(close(&end, &target, 10), "{end:?}");
    assert_eq!(
        rig.ask(0x12, &[]),
        [1],
        "the restarted Atom knows the arm is powered"
    );
    // The Basic's power on after the restart changes nothing.
    assert_eq!(rig.ask(0x10, &[]), [1]);
    rig.run_ms(200);
    assert!(close(&angles(&mut rig), &target, 10));
}

#[test]
fn backup_and_restore_bring_back_a_servos_parameters_after_a_restart() {
    let mut rig = Rig::new();
    assert_eq!(rig.ask(0xEB, &[2]), [0], "no backup yet: restore refused");
    assert_eq!(rig.ask(0xEA, &[254]), [1], "backup of every joint");
    // The backups reach the flash once the arm has been quiet for 20 ms.
    rig.run_ms(50);
    // Someone changes joint 2's P gain and dead zone...
    assert_eq!(rig.ask(0x52, &[2, 21, 40]), [1]);
    assert_eq!(rig.ask(0x52, &[2, 26, 9]), [1]);
    rig.run_ms(20);
    assert_eq!(rig.bus.servo(2).reg(21), 40);
    // ...the Atom restarts (its flash keeps the backups)...
    rig.atom = firmware_atom::Atom::new(firmware_atom::AtomConfig {
        powered_at_boot: true,
        ..firmware_atom::AtomConfig::default()
    });
    rig.run_ms(50);
    // ...and the restore puts them back.
    assert_eq!(rig.ask(0xEB, &[2]), [1]);
    rig.run_ms(20);
    assert_eq!(rig.bus.servo(2).reg(21), 10, "the factory P gain again");
    assert_eq!(rig.bus.servo(2).reg(26), 1, "the dead zone again");
    assert_eq!(
        rig.bus.servo(2).reg(reg::EEPROM_LOCK),
        1,
        "EEPROM locked again"
    );
    assert!(
        rig.bus.servo(2).torque_enabled(),
        "same zero: still holding"
    );
}

#[test]
fn a_restore_that_moves_a_zero_releases_the_servo_instead_of_letting_it_jump() {
    let mut rig = Rig::new();
    let mut data = be(&[0, 0, 3000, 0, 0, 0]);
    data.push(100);
    assert_eq!(rig.ask(SEND_ANGLES, &data), [1]);
    rig.run_ms(2000);
    assert_eq!(rig.ask(0xEA, &[3]), [1]);
    // Calibrating at 30 degrees moves joint 3's zero there (and nothing moves).
    let before = rig.bus.servo(3).physical_steps();
    assert_eq!(rig.ask(0x54, &[3]), [1]);
    rig.run_ms(300);
    assert!(
        (rig.bus.servo(3).physical_steps() - before).abs() < 1.0,
        "calibration moved the joint"
    );
    let shifted = rig.bus.servo(3).reg_u16(reg::HOMING_OFFSET);
    assert_ne!(shifted, 0);
    let shaft = rig.bus.servo(3).physical_steps();
    assert_eq!(rig.ask(0xEB, &[3]), [1]);
    rig.run_ms(300);
    assert_eq!(
        rig.bus.servo(3).reg_u16(reg::HOMING_OFFSET),
        0,
        "the old zero is back"
    );
    assert!(!rig.bus.servo(3).torque_enabled(), "released, not jumping");
    assert!(
        (rig.bus.servo(3).physical_steps() - shaft).abs() < 1.0,
        "the shaft stayed put"
    );
    let angle = angles(&mut rig)[2];
    assert!(
        (angle - 3000).abs() <= 10,
        "reads 30 degrees again: {angle}"
    );
}

#[test]
fn settings_reach_the_flash_with_a_silent_servo_and_an_arm_off_its_goals() {
    let mut rig = Rig::new();
    rig.bus.servo(4).set_faults(Faults::NO_ANSWER);
    // Switched off and turned by hand: no joint is on the goal it last held.
    assert_eq!(rig.ask(0x11, &[]), [1]);
    rig.bus.servo(2).move_by_hand(2400);
    rig.run_ms(50);
    assert_eq!(rig.ask(0x75, &[3, 180]), [1]);
    // Quiet for more than 20 ms: the threshold is written, and survives a restart.
    rig.run_ms(100);
    rig.atom = firmware_atom::Atom::new(firmware_atom::AtomConfig::default());
    rig.run_ms(50);
    assert_eq!(rig.ask(0x76, &[]), [100, 100, 180, 100, 100, 100]);
}
