//! The Wi-Fi settings through the Basic's host links, as pymycobot 4.0.7 sets and reads them:
//! 0xB0's announcing frame and bare text (caught per link), 0xB1's bare text, 0xB2's port; kept
//! in the flash store the board lends; bad input and a failing flash refused with `00` and
//! changing nothing; a change written only once the bus is quiet.
#![allow(clippy::unwrap_used, clippy::indexing_slicing)]

mod common;

use common::{Rig, WifiFlash, frame, wifi_flash};
use firmware_basic::wifi::WIFI_WRITE_WAIT_US;
use firmware_basic::wifi::{WifiConfig, WifiSettings};
use firmware_basic::{BasicError, LinkId};

const ACK: [u8; 6] = [0xFE, 0xFE, 0x03, 0xB0, 0x01, 0xFA];
const NAK: [u8; 6] = [0xFE, 0xFE, 0x03, 0xB0, 0x00, 0xFA];

/// A rig whose Basic has Wi-Fi, with an erased settings flash.
fn rig() -> Rig {
    let mut rig = Rig::quiet(true);
    rig.io.wifi = Some(wifi_flash());
    rig.run_us(1_000);
    rig
}

fn store(rig: &mut Rig) -> &mut WifiFlash {
    rig.io.wifi.as_mut().unwrap()
}

/// What a Basic starting from this flash would load.
fn stored(rig: &mut Rig) -> WifiSettings {
    WifiConfig::load(store(rig)).settings().clone()
}

/// Runs until `link`'s client has received `n` more bytes than `before`, at most `max_us`;
/// returns those bytes and when they started arriving (ns).
fn answer_on(rig: &mut Rig, link: LinkId, before: usize, n: usize, max_us: u64) -> (Vec<u8>, u64) {
    let end = rig.now_ns + max_us * 1_000;
    while rig.client(link).from_basic.len() < before + n && rig.now_ns < end {
        rig.step();
    }
    let got = &rig.client(link).from_basic[before..];
    let at = got.first().map_or(u64::MAX, |&(t, _)| t);
    (got.iter().map(|&(_, b)| b).collect(), at)
}

/// pymycobot's `set_ssid_pwd` on `link`: the announcing frame, 20 ms, the bare text. Returns
/// the two answers and how long after the text was sent the second began (us).
fn set_ssid_pwd(rig: &mut Rig, link: LinkId, text: &[u8]) -> (Vec<u8>, Vec<u8>, u64) {
    let before = rig.client(link).from_basic.len();
    rig.client(link).send(&frame(0xB0, &[]));
    let (first, _) = answer_on(rig, link, before, 6, 20_000);
    rig.run_us(20_000);
    let sent_ns = rig.now_ns;
    rig.client(link).send(text);
    let (second, at) = answer_on(rig, link, before + 6, 6, 100_000);
    (first, second, at.saturating_sub(sent_ns) / 1_000)
}

fn get_ssid_pwd(rig: &mut Rig, link: LinkId) -> Vec<u8> {
    let before = rig.client(link).from_basic.len();
    rig.client(link).send(&frame(0xB1, &[]));
    rig.run_us(20_000);
    rig.client(link).received()[before..].to_vec()
}

fn set_server_port(rig: &mut Rig, link: LinkId, port: &[u8]) -> Vec<u8> {
    let before = rig.client(link).from_basic.len();
    rig.client(link).send(&frame(0xB2, port));
    answer_on(rig, link, before, 6, 100_000).0
}

#[test]
fn pymycobots_calls_over_usb_round_trip_and_are_kept_in_flash() {
    let mut rig = rig();
    let (first, second, late_us) = set_ssid_pwd(&mut rig, LinkId::USB, b"'robots'(12345678)");
    assert_eq!((first, second), (ACK.to_vec(), ACK.to_vec()));
    // Inside pymycobot's 50 ms read: the text's 18 bytes (1.6 ms), the 2 ms end gap.
    assert!(
        late_us < 10_000,
        "answered {late_us} us after the text was sent"
    );
    assert_eq!(
        get_ssid_pwd(&mut rig, LinkId::USB),
        b"ssid: robots password: 12345678"
    );
    assert_eq!(
        set_server_port(&mut rig, LinkId::USB, &[0x23, 0x29]),
        frame(0xB2, &[1])
    );
    let settings = stored(&mut rig);
    assert_eq!(settings.credentials().unwrap().ssid(), "robots");
    assert_eq!(settings.port(), 9001);
    assert!(rig.atom_got.is_empty(), "none of it reached the bus");
    let wifi = rig.basic.wifi_status(0).unwrap();
    assert_eq!((wifi.ssid.as_deref(), wifi.port), (Some("robots"), 9001));
}

#[test]
fn a_network_client_sets_and_reads_them_too() {
    let mut rig = rig();
    let net = rig.connect().unwrap();
    let (first, second, late_us) = set_ssid_pwd(&mut rig, net, b"'lab'(abcdefgh)");
    assert_eq!((first, second), (ACK.to_vec(), ACK.to_vec()));
    assert!(
        late_us < 10_000,
        "answered {late_us} us after the text was sent"
    );
    assert_eq!(get_ssid_pwd(&mut rig, net), b"ssid: lab password: abcdefgh");
    assert!(rig.host.received().is_empty(), "nothing for the USB client");
}

#[test]
fn bad_input_is_refused_with_00_and_changes_nothing() {
    let mut rig = rig();
    let (_, ok, _) = set_ssid_pwd(&mut rig, LinkId::USB, b"'lab'(abcdefgh)");
    assert_eq!(ok, ACK);
    let flash_before = store(&mut rig).flash().unwrap().clone();
    let long_ssid = format!("'{}'(abcdefgh)", "s".repeat(33));
    let long_password = format!("'lab'({})", "p".repeat(64));
    let far_too_long = format!("'{}'({})", "s".repeat(32), "p".repeat(200));
    for text in [
        long_ssid.as_bytes(),
        long_password.as_bytes(),
        far_too_long.as_bytes(),
        b"''(abcdefgh)",
        b"'lab'(short)",
    ] {
        let (first, second, _) = set_ssid_pwd(&mut rig, LinkId::USB, text);
        assert_eq!((first, second), (ACK.to_vec(), NAK.to_vec()), "{text:?}");
        assert!(matches!(
            rig.basic.status().last_error,
            Some(BasicError::Wifi(_))
        ));
    }
    assert_eq!(
        set_server_port(&mut rig, LinkId::USB, &[0, 0]),
        frame(0xB2, &[0])
    );
    assert_eq!(store(&mut rig).flash().unwrap(), &flash_before, "no write");
    assert_eq!(
        get_ssid_pwd(&mut rig, LinkId::USB),
        b"ssid: lab password: abcdefgh"
    );
    assert_eq!(rig.basic.wifi().unwrap().settings().port(), 9000);
}

#[test]
fn a_failed_flash_write_is_refused_with_00_and_nothing_is_half_written() {
    let mut rig = rig();
    set_ssid_pwd(&mut rig, LinkId::USB, b"'lab'(abcdefgh)");
    store(&mut rig).flash_mut().unwrap().fail_writes(true);
    let (_, second, _) = set_ssid_pwd(&mut rig, LinkId::USB, b"'other'(abcdefgh)");
    assert_eq!(second, NAK);
    assert_eq!(
        set_server_port(&mut rig, LinkId::USB, &[0x23, 0x29]),
        frame(0xB2, &[0])
    );
    assert_eq!(
        get_ssid_pwd(&mut rig, LinkId::USB),
        b"ssid: lab password: abcdefgh"
    );
    store(&mut rig).flash_mut().unwrap().fail_writes(false);
    let settings = stored(&mut rig);
    assert_eq!(settings.credentials().unwrap().ssid(), "lab");
    assert_eq!(settings.port(), 9000);
}

#[test]
fn a_link_waiting_for_its_text_does_not_hold_up_the_others() {
    let mut rig = rig();
    let net = rig.connect().unwrap();
    rig.client(net).send(&frame(0xB0, &[]));
    rig.run_us(1_000);
    assert_eq!(rig.client(net).received(), ACK);
    // The USB client's frames go on being answered; the network client's next bytes are its
    // text.
    rig.host.send(&frame(0xC1, &[]));
    rig.run_us(2_000);
    assert_eq!(rig.host.received(), frame(0xC1, &[10]));
    rig.client(net).send(b"'lab'(abcdefgh)");
    rig.run_us(10_000);
    assert_eq!(rig.client(net).received()[6..], ACK);
    assert!(rig.host.received().len() == 6, "nothing more for USB");
}

#[test]
fn a_frame_after_the_announcing_frame_is_a_frame_and_no_text_means_no_answer() {
    let mut rig = rig();
    rig.host.send(&frame(0xB0, &[]));
    rig.run_us(2_000);
    rig.host.send(&frame(0xC1, &[]));
    rig.run_us(2_000);
    assert_eq!(rig.host.received()[6..], frame(0xC1, &[10]));
    let net = rig.connect().unwrap();
    rig.client(net).send(&frame(0xB0, &[]));
    rig.run_us(1_200_000);
    assert_eq!(rig.client(net).received(), ACK, "no second answer");
    rig.client(net).send(&frame(0xC3, &[]));
    rig.run_us(1_000);
    assert_eq!(rig.client(net).received()[6..], frame(0xC3, &[0]));
}

#[test]
fn a_change_waits_for_the_request_on_the_bus_but_not_past_pymycobots_read() {
    let mut rig = rig();
    // An Atom that does not answer: the bus stays busy for the reply timeout (0.4 s).
    rig.atom = Box::new(|_| None);
    let net = rig.connect().unwrap();
    rig.host.send(&frame(0x20, &[]));
    rig.run_us(1_000);
    assert_eq!(rig.atom_got.len(), 1, "get_angles is on the bus");
    let sent_ns = rig.now_ns;
    let flash_before = store(&mut rig).flash().unwrap().clone();
    rig.client(net).send(&frame(0xB2, &[0x23, 0x29]));
    rig.run_us(WIFI_WRITE_WAIT_US / 2);
    assert!(rig.client(net).received().is_empty(), "waiting for the bus");
    assert_eq!(store(&mut rig).flash().unwrap(), &flash_before);
    let (answer, at) = answer_on(&mut rig, net, 0, 6, 100_000);
    assert_eq!(answer, frame(0xB2, &[1]));
    let waited_us = (at - sent_ns) / 1_000;
    assert!(
        (WIFI_WRITE_WAIT_US..WIFI_WRITE_WAIT_US + 2_000).contains(&waited_us),
        "answered after {waited_us} us"
    );
    // With an Atom that answers, the change follows its reply at once.
    let mut rig = self::rig();
    rig.atom_delay_ns = 300_000;
    let net = rig.connect().unwrap();
    rig.host.send(&frame(0x20, &[]));
    rig.run_us(600);
    rig.client(net).send(&frame(0xB2, &[0x23, 0x2A]));
    let (answer, at) = answer_on(&mut rig, net, 0, 6, 100_000);
    assert_eq!(answer, frame(0xB2, &[1]));
    let reply_end = rig.atom_sent[0].0 + 20 * common::BUS_BYTE_NS;
    assert!(
        at >= rig.atom_sent[0].0,
        "written after the Atom's reply began"
    );
    assert!(at < reply_end + 2_000_000, "and promptly after it");
    assert_eq!(stored(&mut rig).port(), 9002);
}

#[test]
fn without_a_store_the_basic_has_no_wifi() {
    let mut rig = Rig::quiet(true);
    rig.host.send(&frame(0xB0, &[]));
    rig.run_us(2_000);
    rig.host.send(b"'lab'(abcdefgh)");
    rig.run_us(5_000);
    assert_eq!(rig.host.received(), NAK);
    assert_eq!(get_ssid_pwd(&mut rig, LinkId::USB), b"ssid:  password: ");
    assert!(rig.basic.wifi().is_none());
    assert_eq!(rig.basic.wifi_status(0), None);
}

#[test]
fn the_network_going_down_does_not_disturb_the_usb_link() {
    let mut rig = rig();
    rig.atom_delay_ns = 300_000;
    let a = rig.connect().unwrap();
    let b = rig.connect().unwrap();
    // Both network clients are busy, one of them mid-frame, and the USB client waits for the
    // Atom's reply when Wi-Fi is lost (the board closes every network link at once).
    rig.client(a).send(&frame(0x20, &[]));
    rig.client(b).send(&[0xFE, 0xFE, 0x04]);
    rig.host.send(&frame(0x20, &[]));
    rig.run_us(700);
    rig.disconnect(a);
    rig.disconnect(b);
    assert!(
        rig.run_until_host_has(17, 20_000),
        "{:02x?}",
        rig.host.received()
    );
    assert_eq!(rig.host.frames()[0].cmd(), 0x20);
    // And the USB link goes on as before.
    rig.host.send(&frame(0xC1, &[]));
    rig.run_us(3_000);
    assert_eq!(rig.host.frames().last().unwrap(), &frame_of(0xC1, &[10]));
}

fn frame_of(cmd: u8, data: &[u8]) -> protocol_core::Frame {
    protocol_core::Frame::new(cmd, data).unwrap()
}
