//! The transponder forwarding host requests to the Atom and replies back, on a simulated wire.
#![allow(clippy::unwrap_used, clippy::indexing_slicing)]

mod common;

use common::{BUS_BYTE_NS, Rig, frame, pymycobot_reads};
use firmware_basic::forwarder::HOLD_BYTE;
use firmware_basic::host_link::STREAM_FILLER;
use firmware_basic::{AtomLink, BasicConfig, BasicError, EchoMode};
use protocol_core::Frame;
use protocol_core::timing::BUS_QUIET_BEFORE_SEND_US;

const GET_ANGLES: u8 = 0x20;
const IS_POWERED_ON: u8 = 0x12;
const SEND_ANGLES: u8 = 0x22;

fn angles_reply() -> Vec<u8> {
    frame(
        GET_ANGLES,
        &[0, 100, 0xFF, 0x9C, 0, 0, 0, 0, 0x12, 0x34, 0xFE, 0xFA],
    )
}

/// A servo status packet (present position of servo 3), as the Atom's polling puts on the wire.
const SERVO_PACKET: [u8; 8] = [0xFF, 0xFF, 0x03, 0x04, 0x00, 0x00, 0x08, 0xF0];

#[test]
fn get_angles_goes_to_the_atom_once_and_its_reply_to_the_host_once() {
    for echo in [true, false] {
        let mut rig = Rig::quiet(echo);
        rig.run_us(100);
        rig.host.send(&frame(GET_ANGLES, &[]));
        rig.run_us(10_000);
        assert_eq!(rig.atom_got.len(), 1, "echo {echo}");
        assert_eq!(rig.atom_got[0].1, Frame::new(GET_ANGLES, &[]).unwrap());
        assert_eq!(rig.host.received(), angles_reply(), "echo {echo}");
        assert_eq!(rig.basic.status().atom, AtomLink::Answering);
        assert_eq!(rig.basic.status().echo_heard, Some(echo));
    }
}

#[test]
fn works_with_the_echo_mode_fixed_by_config() {
    for (echo, mode) in [(true, EchoMode::Present), (false, EchoMode::Absent)] {
        let config = BasicConfig {
            echo: mode,
            power_on_at_boot: false,
            probe_interval_us: 0,
            ..BasicConfig::default()
        };
        let mut rig = Rig::new(config, echo);
        for _ in 0..3 {
            rig.host.send(&frame(GET_ANGLES, &[]));
            rig.run_us(5_000);
        }
        assert_eq!(rig.atom_got.len(), 3, "{mode:?}");
        assert_eq!(rig.host_frames().len(), 3, "{mode:?}");
        assert_eq!(rig.basic.status().collisions, 0);
    }
}

#[test]
fn a_request_arriving_in_pieces_is_forwarded_whole() {
    let mut rig = Rig::quiet(true);
    let request = frame(
        SEND_ANGLES,
        &[0, 0, 0xFE, 0xFE, 0, 0, 0, 0, 0xFA, 0, 0, 0, 50],
    );
    for chunk in request.chunks(4) {
        rig.host.send(chunk);
        // A USB-serial adapter delivers in bursts; 1 ms apart is within a frame's gap.
        rig.run_us(1_000);
    }
    rig.run_us(5_000);
    assert_eq!(rig.atom_got.len(), 1);
    assert_eq!(rig.atom_got[0].1.to_bytes().as_slice(), request.as_slice());
    assert_eq!(rig.host.received(), frame(SEND_ANGLES, &[1]));
}

#[test]
fn a_truncated_request_is_dropped_and_does_not_swallow_the_next() {
    let mut rig = Rig::quiet(true);
    // The first 6 bytes of a send_angles, then the sender resets.
    rig.host.send(&[0xFE, 0xFE, 0x0F, SEND_ANGLES, 0x01, 0x02]);
    rig.run_us(3_000);
    rig.host.send(&frame(GET_ANGLES, &[]));
    rig.run_us(5_000);
    let got: Vec<u8> = rig.atom_got.iter().map(|(_, f)| f.cmd()).collect();
    assert_eq!(got, [GET_ANGLES]);
    assert_eq!(rig.host.received(), angles_reply());
}

#[test]
fn servo_packets_garbage_and_other_frames_never_reach_the_host() {
    let mut rig = Rig::quiet(true);
    rig.atom = Box::new(|f: &Frame| {
        // Servo traffic, a frame for another command, noise, then the reply and a duplicate.
        let mut bytes = SERVO_PACKET.to_vec();
        bytes.extend(frame(0x2B, &[0]));
        bytes.extend([0xFE, 0x00, 0xFA, 0xFE, 0xFE]);
        bytes.extend(frame(f.cmd(), &[1]));
        bytes.extend(SERVO_PACKET);
        bytes.extend(frame(f.cmd(), &[1]));
        Some(bytes)
    });
    rig.wire().inject(50_000, &SERVO_PACKET);
    rig.run_us(100);
    rig.host.send(&frame(IS_POWERED_ON, &[]));
    rig.run_us(10_000);
    assert_eq!(rig.host.received(), frame(IS_POWERED_ON, &[1]));
}

#[test]
fn a_silent_atom_times_out_and_the_next_request_still_goes() {
    let mut rig = Rig::quiet(true);
    rig.atom = Box::new(|_| None);
    rig.host.send(&frame(GET_ANGLES, &[]));
    rig.host.send(&frame(IS_POWERED_ON, &[]));
    rig.run_us(100_000);
    assert_eq!(rig.atom_got.len(), 1, "the second waits for the first");
    rig.run_us(BasicConfig::default().reply_timeout_us);
    assert_eq!(rig.atom_got.len(), 2);
    let status = rig.basic.status();
    assert_eq!(status.atom, AtomLink::Silent);
    assert_eq!(
        status.last_error,
        Some(BasicError::ReplyTimeout { cmd: GET_ANGLES })
    );
    assert!(rig.host.received().is_empty());
    // The Atom comes back: the next request is answered.
    rig.atom = common::ack_everything();
    rig.run_us(BasicConfig::default().reply_timeout_us);
    rig.host.send(&frame(GET_ANGLES, &[]));
    rig.run_us(5_000);
    assert_eq!(rig.host.received(), angles_reply());
    assert_eq!(rig.basic.status().atom, AtomLink::Answering);
}

#[test]
fn own_commands_are_answered_at_once_while_the_atom_is_silent() {
    let mut rig = Rig::quiet(true);
    rig.atom = Box::new(|_| None);
    rig.io.tof_mm = Some(250);
    rig.host.send(&frame(GET_ANGLES, &[]));
    rig.run_us(1_000);
    rig.host.send(&frame(0xC0, &[]));
    assert!(rig.run_until_host_has(7, 2_000));
    assert_eq!(rig.host.received(), frame(0xC0, &[0, 250]));
    assert_eq!(rig.atom_got.len(), 1, "0xC0 never reaches the bus");
}

#[test]
fn a_late_reply_after_the_timeout_is_dropped() {
    let mut rig = Rig::quiet(true);
    rig.atom_delay_ns = (BasicConfig::default().reply_timeout_us + 10_000) * 1_000;
    rig.host.send(&frame(GET_ANGLES, &[]));
    rig.run_us(BasicConfig::default().reply_timeout_us + 50_000);
    assert!(rig.host.received().is_empty());
    assert_eq!(rig.basic.status().timeouts, 1);
}

#[test]
fn pipelined_requests_are_forwarded_one_at_a_time_and_answered_in_order() {
    let mut rig = Rig::quiet(false);
    let cmds = [0x20u8, 0x12, 0x2B, 0x23, 0x14];
    for cmd in cmds {
        rig.host.send(&frame(cmd, &[]));
    }
    rig.run_us(20_000);
    let sent: Vec<u8> = rig.atom_got.iter().map(|(_, f)| f.cmd()).collect();
    assert_eq!(sent, cmds);
    let answered: Vec<u8> = rig.host_frames().iter().map(Frame::cmd).collect();
    assert_eq!(answered, cmds);
    // Each request went out only after the previous reply arrived.
    let wire = rig.wire();
    assert!(wire.basic_sent.windows(2).all(|w| w[0].0 < w[1].0));
}

#[test]
fn a_flood_to_a_dead_atom_neither_wedges_nor_replays_stale_commands() {
    let mut rig = Rig::quiet(true);
    rig.atom = Box::new(|_| None);
    for _ in 0..40 {
        rig.host.send(&frame(
            SEND_ANGLES,
            &[0, 0, 0, 0, 0, 0, 0, 0, 0, 0, 0, 0, 50],
        ));
    }
    rig.step_ns = 5_000;
    // 40 requests of 18 bytes take 63 ms to arrive at 115200.
    rig.run_us(100_000);
    assert_eq!(
        rig.basic.status().last_error,
        Some(BasicError::QueueFull { cmd: SEND_ANGLES }),
        "more than the queue holds"
    );
    rig.run_us(1_000_000);
    // Each forwarded request waits out its reply timeout; the rest expire unsent once the
    // client has given up on them (0.5 s) instead of moving the arm seconds later.
    let timeout_us = BasicConfig::default().reply_timeout_us;
    assert_eq!(rig.atom_got.len() as u64, 500_000 / timeout_us + 1);
    // The Atom is back: the next command is answered at once.
    rig.atom = common::ack_everything();
    rig.step_ns = 1_000;
    rig.host.send(&frame(IS_POWERED_ON, &[]));
    rig.run_us(5_000);
    assert_eq!(rig.host.received(), frame(IS_POWERED_ON, &[1]));
}

#[test]
fn a_collision_is_detected_and_the_request_sent_again() {
    let mut rig = Rig::quiet(true);
    let request = frame(GET_ANGLES, &[]);
    rig.host.send(&request);
    // The host frame's last byte ends at 5 byte times of 115200; the Basic starts sending
    // right after. Another station talks over its second byte.
    let host_end_ns = 5 * common::HOST_BYTE_NS;
    rig.wire()
        .inject(host_end_ns + BUS_BYTE_NS + 3_000, &[0x55, 0x55]);
    rig.run_us(10_000);
    assert!(rig.basic.status().collisions >= 1);
    assert_eq!(rig.atom_got.len(), 1, "one intact copy");
    assert_eq!(rig.host.received(), angles_reply());
}

#[test]
fn on_a_line_that_does_not_echo_bytes_heard_while_sending_never_repeat_a_request() {
    // Without an echo the Basic cannot tell another station talking over its frame from an
    // answer (early, or late to an earlier request) to a frame that arrived whole: it does not
    // send it again. Here it was a collision: the request is lost, and the client resends.
    let mut rig = Rig::quiet(false);
    rig.host.send(&frame(GET_ANGLES, &[]));
    let host_end_ns = 5 * common::HOST_BYTE_NS;
    rig.wire()
        .inject(host_end_ns + BUS_BYTE_NS + 3_000, &[0x55, 0x55]);
    rig.run_us(BasicConfig::default().reply_timeout_us + 10_000);
    let sent_frames = rig
        .wire()
        .basic_sent
        .iter()
        .filter(|(_, b)| *b == 0xFA)
        .count();
    assert_eq!(sent_frames, 1, "sent once");
    assert!(rig.host.received().is_empty());
    assert_eq!(rig.basic.status().timeouts, 1);
    rig.host.send(&frame(GET_ANGLES, &[]));
    rig.run_us(5_000);
    assert_eq!(rig.host.received(), angles_reply());
}

#[test]
fn the_basic_waits_for_a_quiet_wire_before_sending() {
    let mut rig = Rig::quiet(true);
    // The Atom is busy with a long servo exchange when the host request arrives.
    let busy_from = 4 * common::HOST_BYTE_NS;
    let burst: Vec<u8> = SERVO_PACKET.iter().cycle().take(200).copied().collect();
    rig.wire().inject(busy_from, &burst);
    let busy_until = busy_from + 200 * BUS_BYTE_NS;
    rig.host.send(&frame(GET_ANGLES, &[]));
    rig.run_us(10_000);
    let first_sent = rig.wire().basic_sent[0].0;
    assert!(first_sent >= busy_until + 60_000, "sent at {first_sent} ns");
    assert_eq!(rig.basic.status().collisions, 0);
    assert_eq!(rig.host.received(), angles_reply());
}

/// An Atom that boots powered off: 0x12 answers `00` until a 0x10.
fn atom_off_until_powered_on() -> common::Responder {
    let mut powered = false;
    Box::new(move |f: &Frame| {
        powered |= f.cmd() == 0x10;
        let data = match f.cmd() {
            IS_POWERED_ON => u8::from(powered),
            _ => 1,
        };
        Some(frame(f.cmd(), &[data]))
    })
}

#[test]
fn boot_powers_the_atom_on_without_telling_the_host() {
    let mut rig = Rig::new(BasicConfig::default(), true);
    rig.atom = atom_off_until_powered_on();
    rig.step_ns = 20_000;
    rig.run_us(900_000);
    assert!(rig.atom_got.is_empty(), "the Atom is still booting");
    rig.run_us(200_000);
    let got: Vec<u8> = rig.atom_got.iter().map(|(_, f)| f.cmd()).collect();
    assert_eq!(got, [IS_POWERED_ON, 0x10], "asked first, then powered on");
    let status = rig.basic.status();
    assert_eq!(status.atom, AtomLink::Answering);
    assert_eq!(status.atom_powered, Some(true));
    assert!(rig.host.received().is_empty());
}

#[test]
fn an_atom_already_on_at_boot_is_only_asked() {
    // 0x10 makes the Atom hold the arm where it is: sent to an Atom that is on, it would cut
    // short a move the host started before the Basic's boot power-on.
    let mut rig = Rig::new(BasicConfig::default(), true);
    rig.step_ns = 20_000;
    rig.run_us(1_100_000);
    let got: Vec<u8> = rig.atom_got.iter().map(|(_, f)| f.cmd()).collect();
    assert_eq!(got, [IS_POWERED_ON]);
    assert_eq!(rig.basic.status().atom_powered, Some(true));
    assert!(rig.host.received().is_empty());
}

#[test]
fn a_host_request_after_the_atom_said_off_makes_the_basic_ask_again() {
    let mut rig = Rig::new(BasicConfig::default(), true);
    let said_off = std::rc::Rc::new(std::cell::Cell::new(false));
    let flag = said_off.clone();
    let mut atom = atom_off_until_powered_on();
    rig.atom = Box::new(move |f: &Frame| {
        flag.set(flag.get() || f.cmd() == IS_POWERED_ON);
        atom(f)
    });
    rig.atom_delay_ns = 2_000_000;
    rig.step_ns = 1_000;
    rig.run_us(1_000_000);
    while !said_off.get() {
        rig.step();
    }
    // The host's request arrives while the Basic waits for the Atom's "off": it reaches the
    // Atom after that answer.
    rig.host.send(&frame(GET_ANGLES, &[]));
    rig.run_us(20_000);
    let got: Vec<u8> = rig.atom_got.iter().map(|(_, f)| f.cmd()).collect();
    assert_eq!(got, [IS_POWERED_ON, GET_ANGLES, IS_POWERED_ON, 0x10]);
    assert_eq!(rig.host.received(), frame(GET_ANGLES, &[1]));
}

#[test]
fn a_host_power_on_at_boot_is_not_repeated_by_the_basic() {
    let mut rig = Rig::new(BasicConfig::default(), true);
    rig.atom = atom_off_until_powered_on();
    rig.step_ns = 20_000;
    rig.host.send(&frame(0x10, &[]));
    rig.run_us(2_500_000);
    let got: Vec<u8> = rig.atom_got.iter().map(|(_, f)| f.cmd()).collect();
    assert_eq!(got.iter().filter(|&&c| c == 0x10).count(), 1, "{got:02x?}");
}

#[test]
fn a_silent_atom_at_boot_is_shown_and_powered_on_once_it_answers() {
    let mut rig = Rig::new(BasicConfig::default(), false);
    rig.step_ns = 20_000;
    rig.atom = Box::new(|_| None);
    rig.run_us(1_500_000);
    assert_eq!(rig.basic.status().atom, AtomLink::Silent);
    rig.atom = common::ack_everything();
    rig.run_us(1_000_000);
    let status = rig.basic.status();
    assert_eq!(status.atom, AtomLink::Answering);
    assert_eq!(status.atom_powered, Some(true));
    assert!(rig.host.received().is_empty());
    // Powered on: from now on it is only probed, with 0x12.
    let before = rig.atom_got.len();
    rig.run_us(2_100_000);
    let probes: Vec<u8> = rig.atom_got[before..]
        .iter()
        .map(|(_, f)| f.cmd())
        .collect();
    assert_eq!(probes, [IS_POWERED_ON, IS_POWERED_ON]);
    assert!(rig.host.received().is_empty());
}

#[test]
fn a_host_request_with_the_probes_command_gets_exactly_its_own_reply() {
    let mut rig = Rig::new(BasicConfig::default(), true);
    rig.step_ns = 20_000;
    rig.run_us(1_100_000);
    rig.step_ns = 1_000;
    rig.host.send(&frame(IS_POWERED_ON, &[]));
    rig.run_us(10_000);
    assert_eq!(rig.host.received(), frame(IS_POWERED_ON, &[1]));
}

#[test]
fn a_host_power_off_cancels_the_boot_power_on() {
    let mut rig = Rig::new(BasicConfig::default(), true);
    rig.step_ns = 20_000;
    rig.host.send(&frame(0x11, &[]));
    rig.run_us(500_000);
    assert_eq!(rig.host.received(), frame(0x11, &[1]));
    assert_eq!(rig.basic.status().atom_powered, Some(false));
    rig.run_us(2_000_000);
    let got: Vec<u8> = rig.atom_got.iter().map(|(_, f)| f.cmd()).collect();
    assert!(!got.contains(&0x10), "{got:02x?}");
}

#[test]
fn button_a_powers_the_atom_on_again() {
    let mut rig = Rig::quiet(true);
    rig.run_us(1_000);
    rig.io.buttons.a = true;
    rig.run_us(5_000);
    rig.io.buttons.a = false;
    rig.run_us(5_000);
    let got: Vec<u8> = rig.atom_got.iter().map(|(_, f)| f.cmd()).collect();
    assert_eq!(got, [0x10]);
    assert!(rig.host.received().is_empty());
}

/// Commands the Atom received, in order.
fn cmds_got(rig: &Rig) -> Vec<u8> {
    rig.atom_got.iter().map(|(_, f)| f.cmd()).collect()
}

#[test]
fn a_button_read_pressed_from_boot_powers_nothing_until_released_and_pressed() {
    // An emulator reads every input as 0: button A looks held from boot. The Atom does not
    // answer (as when it is slow), and the Basic probes it.
    let config = BasicConfig {
        power_on_at_boot: false,
        ..BasicConfig::default()
    };
    let mut rig = Rig::new(config, true);
    rig.atom = Box::new(|_| None);
    rig.step_ns = 20_000;
    rig.io.buttons.a = true;
    rig.run_us(3_000_000);
    assert!(!cmds_got(&rig).contains(&0x10), "{:02x?}", cmds_got(&rig));
    // Released, then pressed and held: one power on.
    rig.io.buttons.a = false;
    rig.run_us(100_000);
    rig.io.buttons.a = true;
    rig.run_us(3_000_000);
    let power_ons = cmds_got(&rig).iter().filter(|&&c| c == 0x10).count();
    assert_eq!(power_ons, 1, "{:02x?}", cmds_got(&rig));
    // Each press is one more.
    rig.io.buttons.a = false;
    rig.run_us(100_000);
    rig.io.buttons.a = true;
    rig.run_us(100_000);
    let power_ons = cmds_got(&rig).iter().filter(|&&c| c == 0x10).count();
    assert_eq!(power_ons, 2, "{:02x?}", cmds_got(&rig));
    assert!(rig.host.received().is_empty());
}

#[test]
fn an_unanswered_boot_power_on_is_asked_about_again_not_resent_blindly() {
    // The Atom says it is off, then stops answering.
    let mut rig = Rig::new(BasicConfig::default(), true);
    let mut asked = false;
    rig.atom = Box::new(move |f: &Frame| {
        if f.cmd() != IS_POWERED_ON || asked {
            return None;
        }
        asked = true;
        Some(frame(IS_POWERED_ON, &[0]))
    });
    rig.step_ns = 20_000;
    rig.run_us(4_000_000);
    let got = cmds_got(&rig);
    assert_eq!(got.first(), Some(&IS_POWERED_ON), "{got:02x?}");
    assert_eq!(got.iter().filter(|&&c| c == 0x10).count(), 1, "{got:02x?}");
}

#[test]
fn an_atom_answering_right_after_the_request_is_not_mistaken_for_a_broken_echo() {
    for echo in [true, false] {
        let mut rig = Rig::quiet(echo);
        rig.atom_delay_ns = 0;
        for _ in 0..3 {
            rig.host.send(&frame(GET_ANGLES, &[]));
            rig.run_us(5_000);
        }
        assert_eq!(rig.atom_got.len(), 3, "echo {echo}: each request sent once");
        assert_eq!(rig.host_frames().len(), 3, "echo {echo}");
        assert_eq!(rig.basic.status().collisions, 0, "echo {echo}");
    }
}

/// An Atom whose first reply to each request has byte `garbled` changed (as by noise).
fn garbling_atom(garbled: usize) -> common::Responder {
    let mut n = 0;
    Box::new(move |f: &Frame| {
        n += 1;
        let mut reply = frame(f.cmd(), &[1]);
        if n % 2 == 1 {
            reply[garbled] ^= 0x5A;
        }
        Some(reply)
    })
}

#[test]
fn a_garbled_reply_is_lost_and_the_request_never_sent_again() {
    // The second header byte, LEN, CMD or the footer hit: the start of a reply was heard but
    // no valid frame with our CMD came. The request reached the Atom; sending it again would
    // make it reach the Atom twice. The client resends if it wants.
    for garbled in [1, 2, 3, 5] {
        for echo in [true, false] {
            let mut rig = Rig::quiet(echo);
            rig.atom = garbling_atom(garbled);
            rig.host.send(&frame(IS_POWERED_ON, &[]));
            rig.run_us(BasicConfig::default().reply_timeout_us + 10_000);
            let context = format!("byte {garbled}, echo {echo}");
            assert_eq!(rig.atom_got.len(), 1, "{context}");
            // With only the footer hit, the reply's start was passed on as it arrived
            // (cut-through), and the rest of its place filled: no frame for any client.
            let passed_on = if garbled == 5 {
                vec![0xFE, 0xFE, 0x03, IS_POWERED_ON, 0x01, STREAM_FILLER]
            } else {
                Vec::new()
            };
            assert_eq!(rig.host.received(), passed_on, "{context}");
            assert!(rig.host_frames().is_empty(), "{context}");
            assert!(
                pymycobot_reads(&rig.host.received()).is_empty(),
                "{context}"
            );
            // The client's resend is answered.
            rig.host.send(&frame(IS_POWERED_ON, &[]));
            rig.run_us(5_000);
            assert_eq!(rig.atom_got.len(), 2, "{context}");
            let answer = frame(IS_POWERED_ON, &[1]);
            assert!(rig.host.received().ends_with(&answer), "{context}");
            let frames = rig.host_frames();
            assert_eq!(frames.len(), 1, "{context}: {frames:?}");
            assert_eq!(pymycobot_reads(&rig.host.received()), [answer], "{context}");
        }
    }
}

#[test]
fn the_basics_own_question_is_asked_again_at_once_when_its_answer_comes_garbled() {
    let mut rig = Rig::new(BasicConfig::default(), true);
    rig.atom = garbling_atom(2);
    rig.step_ns = 5_000;
    rig.run_us(1_010_000);
    assert_eq!(cmds_got(&rig), [IS_POWERED_ON, IS_POWERED_ON]);
    assert_eq!(rig.basic.status().atom_powered, Some(true));
}

#[test]
fn an_incremental_jog_is_never_sent_twice() {
    let mut rig = Rig::quiet(true);
    rig.atom = garbling_atom(2);
    // Jog joint 1 by +10 degrees at speed 50.
    rig.host.send(&frame(0x33, &[1, 0x03, 0xE8, 50]));
    rig.run_us(BasicConfig::default().reply_timeout_us + 10_000);
    assert_eq!(rig.atom_got.len(), 1);
    assert!(rig.host.received().is_empty());
}

#[test]
fn a_valid_reply_right_after_a_garbled_one_is_taken_without_asking_again() {
    let mut rig = Rig::quiet(true);
    rig.atom = Box::new(|f: &Frame| {
        let mut bytes = frame(f.cmd(), &[1]);
        bytes[2] ^= 0x5A;
        bytes.extend(frame(f.cmd(), &[1]));
        Some(bytes)
    });
    rig.host.send(&frame(IS_POWERED_ON, &[]));
    rig.run_us(5_000);
    assert_eq!(rig.atom_got.len(), 1);
    assert_eq!(rig.host.received(), frame(IS_POWERED_ON, &[1]));
}

#[test]
fn fifty_pipelined_requests_get_fifty_replies() {
    let mut rig = Rig::quiet(true);
    rig.atom_delay_ns = 100_000;
    let mut burst = Vec::new();
    for _ in 0..50 {
        burst.extend(frame(GET_ANGLES, &[]));
    }
    rig.step_ns = 2_000;
    rig.host.send(&burst);
    // The replies (17 bytes each) need 74 ms of host link; the requests arrive in 22 ms.
    rig.run_us(150_000);
    assert_eq!(rig.host_frames().len(), 50);
    assert_eq!(rig.atom_got.len(), 50);
    assert_eq!(rig.basic.status().last_error, None);
}

#[test]
fn the_basic_never_starts_late_in_the_atoms_gap() {
    use firmware_basic::forwarder::{ATOM_START_SEEN_US, LATEST_START_IN_GAP_US};
    // Whenever the host request completes, relative to the end of the Atom's last servo
    // packet, the Basic starts either early in the gap (the Atom hears it before its gap of
    // 100 us is over) or once the gap is visibly over - never in between, where both
    // stations would start before hearing each other.
    for phase_us in (0..200).step_by(7) {
        let mut rig = Rig::quiet(true);
        let host_end_ns = 5 * common::HOST_BYTE_NS;
        let packet_end_ns = host_end_ns - phase_us * 1_000;
        rig.wire().inject(
            packet_end_ns - SERVO_PACKET.len() as u64 * BUS_BYTE_NS,
            &SERVO_PACKET,
        );
        rig.host.send(&frame(GET_ANGLES, &[]));
        rig.run_us(3_000);
        let quiet_us = (rig.wire().basic_sent[0].0 - packet_end_ns) / 1_000;
        assert!(
            (60..LATEST_START_IN_GAP_US).contains(&quiet_us) || quiet_us >= ATOM_START_SEEN_US,
            "request ready {phase_us} us into the gap: sent after {quiet_us} us of quiet"
        );
        assert_eq!(rig.host.received(), angles_reply());
    }
}

#[test]
fn a_request_in_the_atoms_gap_is_answered_while_it_polls_servos() {
    use protocol_core::timing::ATOM_TRANSACTION_GAP_US;
    // The Basic starts early in the Atom's gap; the Atom hears its first byte before the gap
    // is over and holds its next servo transaction (firmware-atom's bus schedule), so nothing
    // collides, with or without the echo: the request reaches the Atom once and its reply the
    // host. The polling is under way when the request arrives (its first READ starts before
    // the request's last byte reaches the Basic, 424 us in), at 40 phases across its 430 us
    // period.
    for echo in [true, false] {
        for phase in 0..40 {
            let mut rig = Rig::quiet(echo);
            rig.step_ns = 10_000;
            rig.atom_delay_ns = 150_000;
            rig.run_us(1_000);
            let now = rig.now_ns;
            let from = now + (phase * 10_997) % 420_000;
            rig.wire().poll_servos(from, now + 4_000_000);
            rig.host.send(&frame(GET_ANGLES, &[]));
            rig.run_us(3_000);
            let case = format!("echo {echo}, servo polling from +{} ns", from - now);
            assert_eq!(rig.host.received(), angles_reply(), "{case}");
            assert_eq!(rig.atom_got.len(), 1, "{case}");
            assert_eq!(rig.wire().collisions(), 0, "{case}");
            assert_eq!(rig.basic.status().collisions, 0, "{case}");
            // The Atom kept its gap after the Basic's bytes, and kept polling.
            let wire = rig.wire();
            assert!(wire.servo_reads.len() > 4, "{case}");
            for &read in &wire.servo_reads {
                assert!(
                    wire.basic_sent.iter().all(|&(start, _)| {
                        start >= read
                            || start + BUS_BYTE_NS + ATOM_TRANSACTION_GAP_US * 1_000 <= read
                    }),
                    "{case}: READ at {read} ns within the Atom's gap after the Basic's bytes"
                );
            }
        }
    }
}

/// When the Atom's reply to the last request ended on the bus, ns.
fn atom_reply_end_ns(rig: &Rig) -> u64 {
    let (start, bytes) = rig.atom_sent.last().unwrap();
    start + bytes.len() as u64 * BUS_BYTE_NS
}

#[test]
fn a_reply_reaches_a_serial_client_before_it_has_ended_on_the_bus_and_without_a_gap() {
    for echo in [true, false] {
        let mut rig = Rig::quiet(echo);
        rig.host.send(&frame(GET_ANGLES, &[]));
        rig.run_us(5_000);
        let reply = angles_reply();
        assert_eq!(rig.host.received(), reply, "echo {echo}");
        let starts: Vec<u64> = rig.host.from_basic.iter().map(|&(t, _)| t).collect();
        let (bus_start, _) = rig.atom_sent[0];
        // Its CMD (the fourth byte) is in at the start plus 4 byte times, and the poll after.
        assert!(
            starts[0] <= bus_start + 4 * BUS_BYTE_NS + rig.step_ns,
            "echo {echo}: USB from {} ns, the reply on the bus from {bus_start} ns",
            starts[0]
        );
        assert!(starts[0] < atom_reply_end_ns(&rig));
        assert!(
            starts
                .windows(2)
                .all(|w| w[1] - w[0] == common::HOST_BYTE_NS),
            "echo {echo}: back to back on the wire: {starts:?}"
        );
    }
}

#[test]
fn without_cut_through_a_reply_goes_once_it_has_ended_on_the_bus() {
    let mut rig = Rig::new(
        BasicConfig {
            power_on_at_boot: false,
            probe_interval_us: 0,
            cut_through: false,
            ..BasicConfig::default()
        },
        true,
    );
    rig.host.send(&frame(GET_ANGLES, &[]));
    rig.run_us(5_000);
    assert_eq!(rig.host.received(), angles_reply());
    assert!(rig.host.from_basic[0].0 >= atom_reply_end_ns(&rig));
}

#[test]
fn a_network_client_and_a_seed_client_get_each_reply_whole() {
    let mut rig = Rig::quiet(true);
    let net = rig.connect().unwrap();
    rig.client(net).send(&frame(GET_ANGLES, &[]));
    rig.run_us(5_000);
    let client = rig.client(net);
    assert_eq!(client.received(), angles_reply());
    let first = client.from_basic[0].0;
    assert!(
        client.from_basic.iter().all(|&(t, _)| t == first),
        "in one write: pymycobot's socket client takes one recv for the whole reply"
    );
    assert!(first >= atom_reply_end_ns(&rig));
    // The seed dialect: its clients read frames of their own; replies go whole.
    rig.host.send(&frame(0xC5, &[2]));
    rig.run_us(2_000);
    rig.host.from_basic.clear();
    rig.host.send(&frame(GET_ANGLES, &[]));
    rig.run_us(5_000);
    assert_eq!(rig.host.received(), angles_reply());
    assert!(rig.host.from_basic[0].0 >= atom_reply_end_ns(&rig));
}

#[test]
fn a_reply_cut_by_noise_leaves_no_frame_and_the_atoms_resend_gets_through() {
    let reply = angles_reply();
    // Noise hits the reply from its byte `hit` to its footer: the Basic had begun to pass it on
    // (its CMD was in), and the frame does not end in FA. The Atom's echo shows it the
    // collision and it sends the reply again (firmware-atom's schedule; here another station
    // sends the same bytes once the wire has been quiet).
    for hit in [5usize, 11, 16] {
        for cut_through in [true, false] {
            let mut rig = Rig::new(
                BasicConfig {
                    power_on_at_boot: false,
                    probe_interval_us: 0,
                    cut_through,
                    ..BasicConfig::default()
                },
                true,
            );
            rig.host.send(&frame(GET_ANGLES, &[]));
            // The scripted Atom keeps clear of traffic it knows is coming: the noise is
            // scheduled once its reply is on the wire.
            while rig.atom_sent.is_empty() {
                rig.step();
            }
            let reply_start_ns = rig.atom_sent[0].0;
            let noise = vec![0x00; reply.len() - hit];
            rig.wire()
                .inject(reply_start_ns + hit as u64 * BUS_BYTE_NS, &noise);
            let resend_ns = reply_start_ns + (reply.len() as u64 + 10) * BUS_BYTE_NS;
            rig.wire().inject(resend_ns, &reply);
            rig.run_us(10_000);
            let context = format!("hit at {hit}, cut-through {cut_through}");
            let received = rig.host.received();
            assert_eq!(rig.host_frames().len(), 1, "{context}: {received:02x?}");
            assert_eq!(
                pymycobot_reads(&received),
                std::slice::from_ref(&reply),
                "{context}"
            );
            assert!(received.ends_with(&reply), "{context}");
            if cut_through {
                // The garbled reply's start, then filler up to its length: no frame.
                assert_eq!(
                    received.len(),
                    2 * reply.len(),
                    "{context}: {received:02x?}"
                );
                assert_eq!(received[..hit], reply[..hit], "{context}");
            } else {
                assert_eq!(received, reply, "{context}");
            }
            assert_eq!(rig.atom_got.len(), 1, "{context}: the request went once");
        }
    }
}

/// A rig whose scripted Atom polls a servo from 1 ms on, with the bus hold on or off.
fn polling_rig(bus_hold: bool) -> Rig {
    let mut rig = Rig::new(
        BasicConfig {
            power_on_at_boot: false,
            probe_interval_us: 0,
            bus_hold,
            ..BasicConfig::default()
        },
        true,
    );
    rig.step_ns = 2_000;
    rig.run_us(1_000);
    let now = rig.now_ns;
    rig.wire().poll_servos(now, now + 1_000_000_000);
    rig
}

/// How long after it was in (its last byte from the host) the request went onto the bus, us,
/// when the host starts sending it `phase_ns` after the Atom started polling.
fn request_wait_us(bus_hold: bool, phase_ns: u64) -> u64 {
    let mut rig = polling_rig(bus_hold);
    rig.run_us(phase_ns / 1_000);
    let in_ns = rig.host.send(&frame(GET_ANGLES, &[]));
    rig.run_us(3_000);
    assert_eq!(
        rig.host.received(),
        angles_reply(),
        "hold {bus_hold}, phase {phase_ns}"
    );
    assert_eq!(rig.atom_got.len(), 1);
    assert_eq!(rig.wire().collisions(), 0);
    let sent = rig.wire().basic_sent.clone();
    let frame_start = sent
        .windows(2)
        .find(|w| w[0].1 == 0xFE && w[1].1 == 0xFE)
        .map(|w| w[0].0)
        .unwrap();
    let held = sent
        .iter()
        .filter(|&&(t, b)| t < frame_start && b == HOLD_BYTE)
        .count();
    assert!(bus_hold || held == 0);
    (frame_start - in_ns) / 1_000
}

#[test]
fn while_the_atom_polls_a_request_goes_soon_after_it_is_in_if_the_bus_was_held_for_it() {
    let phases: Vec<u64> = (0..40).map(|k| k * 10_997).collect();
    let held: Vec<u64> = phases.iter().map(|&p| request_wait_us(true, p)).collect();
    let not_held: Vec<u64> = phases.iter().map(|&p| request_wait_us(false, p)).collect();
    for ((phase, h), n) in phases.iter().zip(&held).zip(&not_held) {
        // After its last hold byte the request waits for the quiet every start needs.
        assert!(
            *h <= n + BUS_QUIET_BEFORE_SEND_US,
            "phase {phase} ns: {h} us held, {n} us not"
        );
    }
    let mean = |w: &[u64]| w.iter().sum::<u64>() / w.len() as u64;
    assert!(
        mean(&held) * 3 < mean(&not_held),
        "held {held:?}, not held {not_held:?}"
    );
}

#[test]
fn a_client_whose_frames_never_end_cannot_starve_the_servo_refresh() {
    // Plausible headers back to back, each with a footer that is not FA: every one looks like a
    // request coming until its last byte.
    let junk: Vec<u8> = [0xFE, 0xFE, 0x03, GET_ANGLES, 0x01, 0x00].repeat(200);
    let reads = |bus_hold: bool| {
        let mut rig = polling_rig(bus_hold);
        let from = rig.wire().servo_reads.len();
        rig.host.send(&junk);
        rig.run_us(100_000);
        assert!(rig.atom_got.is_empty());
        assert!(rig.host.received().is_empty());
        rig.wire().servo_reads.len() - from
    };
    let (held, free) = (reads(true), reads(false));
    // At least one servo transaction after each hold: here about one per junk header.
    assert!(
        held * 2 >= free,
        "{held} servo reads with the hold, {free} without"
    );
    assert!(held >= 100_000 / 1_300, "{held}");
}
