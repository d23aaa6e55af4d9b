//! The virtual robot's Basic keeps its Wi-Fi settings in its flash, with the library's own
//! handling of 0xB0..0xB2 and of network clients: set over USB or a network client, read back,
//! kept across a reset of the Basic, and a failing flash answered with `00` changing nothing.
#![allow(clippy::unwrap_used, clippy::indexing_slicing)]

use open_mycobot::sim::{HostLink, RobotConfig, VirtualRobot};
use protocol_core::Frame;

const ACK: [u8; 6] = [0xFE, 0xFE, 0x03, 0xB0, 0x01, 0xFA];
const NAK: [u8; 6] = [0xFE, 0xFE, 0x03, 0xB0, 0x00, 0xFA];

fn robot() -> VirtualRobot {
    let mut robot = VirtualRobot::new(RobotConfig::default());
    robot.run_for(100_000);
    robot
}

/// Writes `bytes` on `link`, runs 50 ms (pymycobot's read) and returns what came back.
fn exchange(robot: &mut VirtualRobot, link: HostLink, bytes: &[u8]) -> Vec<u8> {
    robot.link_write(link, bytes);
    robot.run_for(50_000);
    let mut out = Vec::new();
    robot.link_read(link, &mut out);
    out
}

/// pymycobot's set_ssid_pwd: the announcing frame, 20 ms, the bare text.
fn set_ssid_pwd(robot: &mut VirtualRobot, link: HostLink, text: &[u8]) -> (Vec<u8>, Vec<u8>) {
    let first = exchange(robot, link, &Frame::new(0xB0, &[]).unwrap().to_bytes());
    robot.run_for(20_000);
    (first, exchange(robot, link, text))
}

fn get_ssid_pwd(robot: &mut VirtualRobot, link: HostLink) -> Vec<u8> {
    exchange(robot, link, &Frame::new(0xB1, &[]).unwrap().to_bytes())
}

#[test]
fn settings_set_over_either_link_read_back_and_survive_a_reset_of_the_basic() {
    let mut robot = robot();
    let (first, second) = set_ssid_pwd(&mut robot, HostLink::Basic, b"'robots'(12345678)");
    assert_eq!((first, second), (ACK.to_vec(), ACK.to_vec()));
    let net = robot.connect().unwrap();
    assert_eq!(
        get_ssid_pwd(&mut robot, net),
        b"ssid: robots password: 12345678"
    );
    let port = Frame::new(0xB2, &[0x23, 0x29]).unwrap().to_bytes();
    assert_eq!(
        exchange(&mut robot, net, &port),
        Frame::new(0xB2, &[1]).unwrap().to_bytes().to_vec()
    );
    robot.reset_basic();
    robot.run_for(100_000);
    assert!(!robot.link_connected(net), "the reset dropped the client");
    assert_eq!(
        get_ssid_pwd(&mut robot, HostLink::Basic),
        b"ssid: robots password: 12345678"
    );
    let wifi = robot.basic().unwrap().wifi().unwrap();
    assert_eq!(wifi.settings().port(), 9001);
}

#[test]
fn a_failing_flash_is_answered_00_and_changes_nothing() {
    let mut robot = robot();
    set_ssid_pwd(&mut robot, HostLink::Basic, b"'robots'(12345678)");
    let flash = robot.basic_flash_mut().unwrap().flash_mut().unwrap();
    flash.fail_writes(true);
    let (_, second) = set_ssid_pwd(&mut robot, HostLink::Basic, b"'other'(12345678)");
    assert_eq!(second, NAK);
    assert_eq!(
        get_ssid_pwd(&mut robot, HostLink::Basic),
        b"ssid: robots password: 12345678"
    );
    robot.reset_basic();
    robot.run_for(100_000);
    assert_eq!(
        get_ssid_pwd(&mut robot, HostLink::Basic),
        b"ssid: robots password: 12345678"
    );
}
