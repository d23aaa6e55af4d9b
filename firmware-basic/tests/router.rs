//! Several host links at once: the USB serial and network clients, each with its own answers.
#![allow(clippy::unwrap_used, clippy::indexing_slicing)]

mod common;

use common::clients::{ASK, echo_atom, run_clients};
use common::{PING, PING_REPLY, Rig, frame};
use firmware_basic::{BasicError, LinkId, LinksFull, MAX_HOST_LINKS, TransponderMode};
use protocol_core::Frame;

const GET_ANGLES: u8 = 0x20;

/// A rig whose Atom echoes every request's data, with `n` network clients connected.
fn rig_with_clients(n: usize) -> (Rig, Vec<LinkId>) {
    let mut rig = Rig::quiet(true);
    rig.atom = echo_atom();
    rig.atom_delay_ns = 100_000;
    let links = (0..n).map(|_| rig.connect().unwrap()).collect();
    (rig, links)
}

#[test]
fn four_clients_one_sending_garbage_each_get_exactly_their_own_answers() {
    let (mut rig, net) = rig_with_clients(3);
    rig.step_ns = 5_000;
    let links = [LinkId::USB, net[0], net[1], net[2]];
    let (tallies, _) = run_clients(&mut rig, &links, true, 300, 7);
    for (link, tally) in links.iter().zip(&tallies) {
        assert_eq!(tally.answered, 300, "{link:?}: {tally:?}");
        assert_eq!((tally.wrong, tally.lost), (0, 0), "{link:?}: {tally:?}");
    }
    assert!(tallies[3].garbage_bursts == 300);
}

#[test]
fn a_half_frame_from_one_client_does_not_delay_another() {
    let (mut rig, net) = rig_with_clients(1);
    // A network client starts a long frame and goes quiet (it would hold its own link for the
    // network gap, 20 ms); the USB client's request is answered as if alone.
    rig.client(net[0]).send(&[0xFE, 0xFE, 0x40, 0x22, 1, 2]);
    rig.run_us(100);
    rig.host.send(&frame(GET_ANGLES, &[]));
    // The echoed reply is 5 bytes: 0.43 ms of 115200; the request as long.
    assert!(rig.run_until_host_has(5, 2_000), "no prompt reply");
    assert_eq!(rig.host_frames(), [Frame::new(GET_ANGLES, &[]).unwrap()]);
    assert!(rig.client(net[0]).received().is_empty());
}

#[test]
fn the_basics_own_commands_are_answered_to_the_client_that_asked() {
    let (mut rig, net) = rig_with_clients(2);
    rig.io.tof_mm = Some(250);
    rig.client(net[0]).send(&frame(0xC1, &[]));
    rig.client(net[1]).send(&frame(0xC0, &[]));
    rig.host.send(&frame(0xC3, &[]));
    rig.run_us(5_000);
    assert_eq!(rig.client(net[0]).received(), frame(0xC1, &[10]));
    assert_eq!(rig.client(net[1]).received(), frame(0xC0, &[0, 250]));
    assert_eq!(rig.host.received(), frame(0xC3, &[0]));
    assert!(rig.atom_got.is_empty(), "none of them reached the bus");
}

#[test]
fn the_bus_is_shared_round_robin() {
    let (mut rig, net) = rig_with_clients(2);
    // Client A pipelines five requests, then B asks one: B waits for one of A's at most.
    for seq in 0..5u8 {
        rig.client(net[0]).send(&frame(ASK, &[0, 0, seq]));
    }
    rig.run_us(10);
    rig.client(net[1]).send(&frame(ASK, &[1, 0, 0]));
    rig.run_us(20_000);
    let order: Vec<u8> = rig.atom_got.iter().map(|(_, f)| f.data()[0]).collect();
    assert_eq!(order, [0, 1, 0, 0, 0, 0]);
    assert_eq!(
        rig.client(net[1]).frames(),
        [Frame::new(ASK, &[1, 0, 0]).unwrap()]
    );
    assert_eq!(rig.client(net[0]).frames().len(), 5);
}

#[test]
fn the_client_limit_refuses_the_next_client_and_a_freed_slot_is_reused() {
    let (mut rig, net) = rig_with_clients(MAX_HOST_LINKS - 1);
    assert_eq!(rig.connect(), Err(LinksFull), "USB + {} clients", net.len());
    rig.disconnect(net[3]);
    let again = rig.connect().unwrap();
    assert_eq!(again, net[3]);
    rig.client(again).send(&frame(GET_ANGLES, &[]));
    rig.run_us(5_000);
    assert_eq!(
        rig.client(again).frames(),
        [Frame::new(GET_ANGLES, &[]).unwrap()]
    );
}

#[test]
fn the_reply_for_a_client_that_left_is_not_given_to_the_next_one() {
    let (mut rig, net) = rig_with_clients(1);
    rig.atom_delay_ns = 2_000_000;
    rig.client(net[0]).send(&frame(ASK, &[0, 0, 1]));
    rig.run_us(500);
    assert_eq!(rig.atom_got.len(), 1, "on the bus");
    rig.disconnect(net[0]);
    let next = rig.connect().unwrap();
    assert_eq!(next, net[0], "the same slot");
    rig.run_us(5_000);
    assert!(rig.client(next).received().is_empty());
    // The newcomer is served normally.
    rig.client(next).send(&frame(ASK, &[1, 0, 1]));
    rig.run_us(5_000);
    assert_eq!(
        rig.client(next).frames(),
        [Frame::new(ASK, &[1, 0, 1]).unwrap()]
    );
}

#[test]
fn in_transparent_mode_only_the_client_that_switched_gets_the_bus() {
    let (mut rig, net) = rig_with_clients(1);
    let (owner, other) = (net[0], LinkId::USB);
    rig.client(owner).send(&frame(0xC2, &[1]));
    rig.run_us(2_000);
    assert_eq!(rig.client(owner).received(), frame(0xC2, &[1]));
    rig.client(owner).from_basic.clear();
    rig.atom = Box::new(|_| None);

    // The owner's raw bytes reach the bus, and the bus's reach the owner only.
    let (sent, received) = rig.ping_servo_raw(owner);
    assert!(sent.ends_with(&PING), "{sent:02x?}");
    assert_eq!(received, PING_REPLY);
    assert!(rig.client(other).received().is_empty());

    // Another client: its requests for the Atom are dropped unanswered, 0xC2 is refused,
    // 0xC3 tells it why, the Basic's other commands are answered.
    let sent_before = rig.wire().basic_sent.len();
    rig.client(other).send(&frame(GET_ANGLES, &[]));
    rig.run_us(10_000);
    assert!(rig.client(other).received().is_empty());
    assert_eq!(
        rig.wire().basic_sent.len(),
        sent_before,
        "nothing of it on the bus"
    );
    assert_eq!(
        rig.basic.status().last_error,
        Some(BasicError::TransparentElsewhere { cmd: GET_ANGLES })
    );
    for (request, answer) in [
        (frame(0xC2, &[0]), frame(0xC2, &[0])),
        (frame(0xC2, &[1]), frame(0xC2, &[0])),
        (frame(0xC3, &[]), frame(0xC3, &[1])),
        (frame(0xC1, &[]), frame(0xC1, &[10])),
    ] {
        rig.client(other).from_basic.clear();
        rig.client(other).send(&request);
        rig.run_us(3_000);
        assert_eq!(rig.client(other).received(), answer, "{request:02x?}");
    }
    assert_eq!(rig.basic.status().mode, TransponderMode::Transparent);
    assert!(
        rig.client(owner).received().ends_with(&PING_REPLY),
        "nothing else reached the owner"
    );

    // The owner switches back: everyone is served again.
    rig.atom = common::ack_everything();
    rig.client(owner).from_basic.clear();
    rig.client(owner).send(&frame(0xC2, &[0]));
    rig.run_us(2_000);
    assert_eq!(rig.client(owner).received(), frame(0xC2, &[1]));
    rig.client(other).from_basic.clear();
    rig.client(other).send(&frame(0x12, &[]));
    rig.run_us(5_000);
    assert_eq!(rig.client(other).received(), frame(0x12, &[1]));
}

#[test]
fn the_owner_leaving_returns_the_bus_to_framed_mode() {
    let (mut rig, net) = rig_with_clients(1);
    rig.atom = common::ack_everything();
    rig.client(net[0]).send(&frame(0xC2, &[1]));
    rig.run_us(2_000);
    assert_eq!(rig.basic.status().mode, TransponderMode::Transparent);
    rig.disconnect(net[0]);
    assert_eq!(rig.basic.status().mode, TransponderMode::Framed);
    rig.host.send(&frame(0x12, &[]));
    rig.run_us(5_000);
    assert_eq!(rig.host.received(), frame(0x12, &[1]));
}

#[test]
fn switching_to_transparent_waits_for_the_reply_on_the_bus() {
    let (mut rig, net) = rig_with_clients(1);
    rig.atom = echo_atom();
    rig.atom_delay_ns = 1_000_000;
    // The USB client's request is on the bus when the network client switches.
    rig.host.send(&frame(ASK, &[7, 7, 7]));
    rig.run_us(1_000);
    assert_eq!(rig.atom_got.len(), 1);
    rig.client(net[0]).send(&frame(0xC2, &[1]));
    rig.run_us(5_000);
    assert_eq!(rig.host_frames(), [Frame::new(ASK, &[7, 7, 7]).unwrap()]);
    assert_eq!(rig.client(net[0]).received(), frame(0xC2, &[1]));
}
