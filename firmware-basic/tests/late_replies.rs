//! A slow Atom (under emulation, every Atom): replies that come after the Basic gave up on
//! their request. Each client request reaches the Atom once, and a late reply never reaches
//! a client that did not ask it (protocol.md section 13).
#![allow(clippy::unwrap_used, clippy::indexing_slicing)]

mod common;

use common::{Rig, frame};
use firmware_basic::BasicConfig;
use protocol_core::Frame;

const GET_ANGLES: u8 = 0x20;
const IS_POWERED_ON: u8 = 0x12;
const POWER_ON: u8 = 0x10;

/// How many times the Atom received a frame with command `cmd`.
fn times_got(rig: &Rig, cmd: u8) -> usize {
    rig.atom_got.iter().filter(|(_, f)| f.cmd() == cmd).count()
}

/// An Atom that answers every request with its number: the first gets `[1]`, the next `[2]`.
fn numbering_atom() -> common::Responder {
    let mut n = 0_u8;
    Box::new(move |f: &Frame| {
        n += 1;
        Some(frame(f.cmd(), &[n]))
    })
}

#[test]
fn a_late_answer_to_the_basics_own_question_does_not_make_it_repeat_the_hosts_request() {
    // The emulator's fault: the Atom answers in 100 ms, after the boot question's 50 ms
    // deadline; its late answer arrives while the host's request waits for its reply.
    for echo in [true, false] {
        let mut rig = Rig::new(BasicConfig::default(), echo);
        rig.atom_delay_ns = 100_000_000;
        rig.step_ns = 5_000;
        let probe_timeout_us = BasicConfig::default().probe_timeout_us;
        rig.run_us(1_000_000 + probe_timeout_us + 10_000);
        assert_eq!(
            times_got(&rig, IS_POWERED_ON),
            1,
            "echo {echo}: asked at boot"
        );
        rig.host.send(&frame(GET_ANGLES, &[]));
        rig.run_us(600_000);
        assert_eq!(
            times_got(&rig, GET_ANGLES),
            1,
            "echo {echo}: forwarded once"
        );
        let replies = rig.host_frames();
        assert_eq!(replies.len(), 1, "echo {echo}: {replies:?}");
        assert_eq!(replies[0].cmd(), GET_ANGLES, "echo {echo}");
        let status = rig.basic.status();
        assert_eq!(status.late_replies, 1, "echo {echo}");
        // The late answer still told the Basic the Atom is on: no power on.
        assert_eq!(status.atom_powered, Some(true), "echo {echo}");
        assert_eq!(times_got(&rig, POWER_ON), 0, "echo {echo}");
    }
}

#[test]
fn a_late_reply_is_not_given_to_the_next_client_asking_the_same() {
    for echo in [true, false] {
        let mut rig = Rig::quiet(echo);
        let net = rig.connect().unwrap();
        rig.atom = numbering_atom();
        // The USB client's request is answered after the Basic's 400 ms deadline...
        rig.atom_delay_ns = 450_000_000;
        rig.host.send(&frame(GET_ANGLES, &[]));
        rig.run_us(BasicConfig::default().reply_timeout_us + 10_000);
        assert_eq!(rig.basic.status().timeouts, 1, "echo {echo}");
        // ... while the network client's same question is on the bus.
        rig.atom_delay_ns = 1_000_000;
        rig.client(net).send(&frame(GET_ANGLES, &[]));
        rig.run_us(200_000);
        assert_eq!(
            times_got(&rig, GET_ANGLES),
            2,
            "echo {echo}: each request once"
        );
        assert_eq!(
            rig.client(net).frames(),
            [Frame::new(GET_ANGLES, &[2]).unwrap()],
            "echo {echo}: the network client gets its own answer"
        );
        assert!(rig.host.frames().is_empty(), "echo {echo}");
        assert_eq!(rig.basic.status().late_replies, 1, "echo {echo}");
    }
}

#[test]
fn a_late_reply_answers_the_same_clients_resend_and_the_resend_is_forwarded_once() {
    let mut rig = Rig::quiet(true);
    rig.atom = numbering_atom();
    rig.atom_delay_ns = 600_000_000;
    rig.host.send(&frame(GET_ANGLES, &[]));
    // pymycobot resends after 0.5 s; the first reply comes 0.1 s after that.
    rig.run_us(500_000);
    rig.atom_delay_ns = 1_000_000;
    rig.host.send(&frame(GET_ANGLES, &[]));
    rig.run_us(300_000);
    assert_eq!(
        times_got(&rig, GET_ANGLES),
        2,
        "the request and its resend, once each"
    );
    assert_eq!(rig.host.frames(), [Frame::new(GET_ANGLES, &[1]).unwrap()]);
    assert_eq!(rig.basic.status().late_replies, 1);
}

#[test]
fn garbage_after_a_late_reply_does_not_crash_or_leak() {
    let mut rig = Rig::quiet(false);
    rig.atom = numbering_atom();
    rig.atom_delay_ns = 450_000_000;
    rig.host.send(&frame(GET_ANGLES, &[]));
    rig.run_us(420_000);
    // Servo noise and half frames around the late reply.
    rig.wire()
        .inject(440_000_000, &[0xFE, 0xFE, 0x05, 0xFF, 0x00]);
    rig.wire()
        .inject(460_000_000, &[0xFF, 0xFF, 0x01, 0x02, 0x00, 0xFC]);
    rig.run_us(200_000);
    assert!(rig.host.frames().is_empty());
    rig.atom_delay_ns = 1_000_000;
    rig.host.send(&frame(IS_POWERED_ON, &[]));
    rig.run_us(50_000);
    assert_eq!(
        rig.host.frames(),
        [Frame::new(IS_POWERED_ON, &[2]).unwrap()]
    );
    assert_eq!(times_got(&rig, GET_ANGLES), 1);
}
