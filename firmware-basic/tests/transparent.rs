//! Transparent mode: raw bytes both ways, until the host sends `FE FE 03 C2 00 FA`.
#![allow(clippy::unwrap_used, clippy::indexing_slicing)]

mod common;

use common::{BUS_BYTE_NS, PING, PING_REPLY, Rig, frame};
use firmware_basic::{LinkId, TransponderMode};

fn enter(rig: &mut Rig) {
    rig.host.send(&frame(0xC2, &[1]));
    rig.run_us(2_000);
    assert_eq!(rig.host.received(), frame(0xC2, &[1]));
    assert_eq!(rig.basic.status().mode, TransponderMode::Transparent);
    rig.host.from_basic.clear();
}

#[test]
fn raw_servo_traffic_passes_both_ways_without_the_echo() {
    for echo in [true, false] {
        let mut rig = Rig::quiet(echo);
        // One framed exchange first, so the Basic knows whether the wire echoes.
        rig.host.send(&frame(0x20, &[]));
        rig.run_us(5_000);
        rig.host.from_basic.clear();
        enter(&mut rig);
        rig.atom = Box::new(|_| None);
        let (sent, received) = rig.ping_servo_raw(LinkId::USB);
        assert!(sent.ends_with(&PING), "echo {echo}: {sent:02x?}");
        assert_eq!(received, PING_REPLY, "echo {echo}");
    }
}

#[test]
fn host_frames_are_not_interpreted_in_transparent_mode() {
    let mut rig = Rig::quiet(true);
    rig.atom = Box::new(|_| None);
    enter(&mut rig);
    // 0xC1 (Basic version) would be answered in framed mode; here it goes to the bus as is.
    let version = frame(0xC1, &[]);
    rig.host.send(&version);
    rig.run_us(3_000);
    assert!(rig.host.received().is_empty());
    let sent: Vec<u8> = rig.wire().basic_sent.iter().map(|&(_, b)| b).collect();
    assert_eq!(sent, version);
}

#[test]
fn the_exit_frame_returns_to_framed_mode_and_is_acknowledged() {
    let mut rig = Rig::quiet(true);
    enter(&mut rig);
    let sent_before = rig.wire().basic_sent.len();
    rig.host.send(&frame(0xC2, &[0]));
    rig.run_us(2_000);
    assert_eq!(rig.host.received(), frame(0xC2, &[1]));
    assert_eq!(rig.basic.status().mode, TransponderMode::Framed);
    assert_eq!(
        rig.wire().basic_sent.len(),
        sent_before,
        "the exit frame stays off the bus"
    );
    // Framed again: own commands answered, Atom commands forwarded.
    rig.host.from_basic.clear();
    rig.host.send(&frame(0xC3, &[]));
    rig.run_us(2_000);
    assert_eq!(rig.host.received(), frame(0xC3, &[0]));
    rig.host.from_basic.clear();
    rig.host.send(&frame(0x12, &[]));
    rig.run_us(5_000);
    assert_eq!(rig.host.received(), frame(0x12, &[1]));
}

#[test]
fn bus_bytes_faster_than_the_host_link_are_queued_not_lost() {
    let mut rig = Rig::quiet(false);
    enter(&mut rig);
    // 300 bytes at 1 Mbaud arrive in 3 ms; the host link needs 26 ms for them.
    let burst: Vec<u8> = (0..300u32).map(|i| (i % 251) as u8).collect();
    let now = rig.now_ns;
    rig.wire().inject(now + 10 * BUS_BYTE_NS, &burst);
    rig.run_us(40_000);
    assert_eq!(rig.host.received(), burst);
}

#[test]
fn the_mode_can_still_be_asked_and_set_in_transparent_mode() {
    let mut rig = Rig::quiet(true);
    enter(&mut rig);
    rig.host.send(&frame(0xC3, &[]));
    rig.run_us(2_000);
    assert_eq!(rig.host.received(), frame(0xC3, &[1]));
    rig.host.from_basic.clear();
    rig.host.send(&frame(0xC2, &[1]));
    rig.run_us(2_000);
    assert_eq!(rig.host.received(), frame(0xC2, &[1]));
    assert_eq!(rig.basic.status().mode, TransponderMode::Transparent);
    assert!(
        rig.wire().basic_sent.is_empty(),
        "none of it reached the bus"
    );
}

#[test]
fn on_a_busy_bus_the_host_gets_the_newest_bytes_and_the_mode_answer() {
    let mut rig = Rig::quiet(false);
    enter(&mut rig);
    // 2000 bytes of servo traffic in 20 ms: far more than 115200 baud carries.
    let flood: Vec<u8> = (0..2_000u32).map(|i| (i % 200) as u8).collect();
    let now = rig.now_ns;
    rig.wire().inject(now + 10_000, &flood);
    rig.run_us(25_000);
    let now = rig.now_ns;
    rig.wire().inject(now + 10_000, &PING_REPLY);
    rig.run_us(60_000);
    let got = rig.host.received();
    assert!(got.ends_with(&PING_REPLY), "the newest bytes arrive");
    assert!(got.len() < 1_000, "the backlog was cut");
    // The mode answer is not lost behind a backlog.
    let now = rig.now_ns;
    rig.wire().inject(now + 10_000, &flood);
    rig.run_us(5_000);
    rig.host.from_basic.clear();
    rig.host.send(&frame(0xC3, &[]));
    // At most the one 64-byte chunk already handed to the port (5.6 ms) comes first.
    rig.run_us(8_000);
    let got = rig.host.received();
    let answer = frame(0xC3, &[1]);
    assert!(got.windows(answer.len()).any(|w| w == answer), "{got:02x?}");
}
