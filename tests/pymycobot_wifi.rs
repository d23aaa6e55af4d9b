//! The simulated Basic keeps its Wi-Fi settings in its flash file: what pymycobot 4.0.7 sets
//! (`set_ssid_pwd`, `set_server_port`) is still there after the virtual robot is stopped and
//! started again with the same `--basic-flash`, and `--tcp` alone serves on the stored port and
//! moves when a client sets another, as the board does.
#![allow(clippy::unwrap_used, clippy::expect_used, clippy::indexing_slicing)] // a test harness: a panic is a failed check

use std::fs;
use std::net::TcpListener;
use std::path::{Path, PathBuf};
use std::process::Command;

use nix::sys::signal::Signal;

#[path = "e2e/launcher.rs"]
mod launcher;
use launcher::{Launched, launch};
#[path = "e2e/venv.rs"]
mod venv;
use venv::{python, run_checked};

/// A port nobody listens on now, from `from` up to 32767 (pymycobot packs the port as a signed
/// int16, so the OS's ephemeral ports are out of its reach).
fn free_port(from: u16) -> u16 {
    (from..32_768)
        .find(|&port| TcpListener::bind(("127.0.0.1", port)).is_ok())
        .expect("a free port below 32768")
}

/// Runs `script` with pymycobot; `PORT` is the robot's pty. Returns what it printed.
fn pymycobot(script: &str, pty: &Path) -> String {
    let program = format!(
        "import sys\nfrom pymycobot import MyCobot280, MyCobot280Socket\n\
         PORT = sys.argv[1]\n{script}"
    );
    run_checked(
        Command::new(python())
            .arg("-c")
            .arg(program)
            .arg(pty)
            .env("PYTHONDONTWRITEBYTECODE", "1"),
    )
}

fn start(flash: &Path, pty: &Path, tcp: Option<&str>) -> Launched {
    let mut args = vec![
        "--no-web",
        "--basic-flash",
        flash.to_str().unwrap(),
        "--pty-link",
        pty.to_str().unwrap(),
        "--tcp",
    ];
    args.extend(tcp);
    launch(&args)
}

/// An empty directory for one test.
fn scratch(name: &str) -> PathBuf {
    let dir = PathBuf::from(env!("CARGO_TARGET_TMPDIR")).join(name);
    let _ = fs::remove_dir_all(&dir);
    fs::create_dir_all(&dir).unwrap();
    dir
}

fn stop(mut robot: Launched) {
    let exit = robot.stop_with(Signal::SIGTERM);
    assert!(exit.is_some_and(|s| s.success()), "{exit:?}");
}

#[test]
fn the_settings_survive_a_restart_and_the_tcp_server_follows_the_stored_port() {
    let dir = scratch("wifi-restart");
    let flash = dir.join("state/basic-flash.bin");
    let pty = dir.join("mycobot");
    let first_port = free_port(20_000 + (std::process::id() % 5_000) as u16);
    let second_port = free_port(first_port + 1);

    // First run: set over the USB serial, as the vendor documents it.
    let robot = start(&flash, &pty, Some("127.0.0.1:0"));
    let out = pymycobot(
        &format!(
            "mc = MyCobot280(PORT)\n\
             print(mc.set_ssid_pwd('robots', '12345678'), mc.set_server_port({first_port}))\n\
             print(mc.get_ssid_pwd())"
        ),
        &pty,
    );
    assert_eq!(out, "1 1\n('robots', '12345678')\n");
    stop(robot);
    assert!(flash.is_file(), "the flash file was written");

    // Second run: `--tcp` alone listens on the stored port; the settings read back over TCP
    // and over USB; a new port set over TCP takes new connections, the old client stays.
    let robot = start(&flash, &pty, None);
    assert_eq!(
        robot.banner_value("tcp on "),
        Some(format!("127.0.0.1:{first_port}").as_str()),
        "{}",
        robot.banner
    );
    let out = pymycobot(
        &format!(
            "import time\n\
             net = MyCobot280Socket('127.0.0.1', {first_port})\n\
             print(net.get_ssid_pwd())\n\
             print(MyCobot280(PORT).get_ssid_pwd())\n\
             print(net.set_server_port({second_port}))\n\
             time.sleep(0.2)\n\
             other = MyCobot280Socket('127.0.0.1', {second_port})\n\
             print(other.get_basic_version() > 0, net.get_basic_version() > 0)"
        ),
        &pty,
    );
    assert_eq!(
        out,
        "('robots', '12345678')\n('robots', '12345678')\n1\nTrue True\n"
    );
    stop(robot);

    // Third run: the port set over TCP was kept too.
    let robot = start(&flash, &pty, None);
    assert_eq!(
        robot.banner_value("tcp on "),
        Some(format!("127.0.0.1:{second_port}").as_str())
    );
    stop(robot);
    fs::remove_dir_all(&dir).unwrap();
}

#[test]
fn a_flash_file_that_is_not_one_is_a_clear_error() {
    let dir = scratch("wifi-bad-flash");
    let flash = dir.join("notes.txt");
    fs::write(&flash, "not a flash image").unwrap();
    let out = Command::new(env!("CARGO_BIN_EXE_open-mycobot"))
        .args(["--no-web", "--basic-flash", flash.to_str().unwrap()])
        .output()
        .unwrap();
    assert!(!out.status.success());
    let stderr = String::from_utf8_lossy(&out.stderr);
    assert!(
        stderr.contains("the Basic's flash") && stderr.contains("notes.txt"),
        "{stderr}"
    );
    assert_eq!(fs::read_to_string(&flash).unwrap(), "not a flash image");
}
