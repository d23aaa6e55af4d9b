//! The command line of the virtual robot as a user meets it: start-up banner, the pty symlink
//! (stale ones replaced, user files never clobbered, removed on Ctrl-C), and clear errors.
//! Speaks raw frames on the pseudo-terminal, so it needs no Python.

use std::fs::{self, OpenOptions};
use std::io::{BufRead, BufReader, Read, Write};
use std::net::TcpListener;
use std::os::unix::fs::symlink;
use std::path::PathBuf;
use std::process::{Child, Command, Output, Stdio};
use std::sync::mpsc;
use std::thread;
use std::time::{Duration, Instant};

use nix::sys::signal::{Signal, kill};
use nix::unistd::Pid;

fn robot() -> Command {
    Command::new(env!("CARGO_BIN_EXE_open-mycobot"))
}

fn scratch(name: &str) -> PathBuf {
    let dir = PathBuf::from(env!("CARGO_TARGET_TMPDIR")).join(format!("cli-{name}"));
    let _ = fs::remove_dir_all(&dir);
    fs::create_dir_all(&dir).unwrap();
    dir
}

/// Starts the robot and reads its banner up to "ready"; returns the child and the banner.
fn start(args: &[&str]) -> (Child, String) {
    let mut child = robot().args(args).stdout(Stdio::piped()).spawn().unwrap();
    let mut stdout = BufReader::new(child.stdout.take().unwrap());
    let mut banner = String::new();
    while !banner.contains("ready") {
        let mut line = String::new();
        if stdout.read_line(&mut line).unwrap() == 0 {
            panic!("the robot exited during start-up: {banner}");
        }
        banner.push_str(&line);
    }
    // Keep draining stdout so the final "stopped" line never hits a closed pipe.
    thread::spawn(move || {
        let mut rest = String::new();
        let _ = stdout.read_to_string(&mut rest);
    });
    (child, banner)
}

fn signal_and_wait(child: &mut Child, signal: Signal) -> bool {
    kill(Pid::from_raw(child.id() as i32), signal).unwrap();
    let deadline = Instant::now() + Duration::from_secs(5);
    while Instant::now() < deadline {
        if let Some(status) = child.try_wait().unwrap() {
            return status.success();
        }
        thread::sleep(Duration::from_millis(20));
    }
    let _ = child.kill();
    panic!("the robot did not stop within 5 s of {signal:?}");
}

fn run_to_end(args: &[&str]) -> Output {
    robot().args(args).output().unwrap()
}

#[test]
fn serves_the_link_replaces_a_stale_one_and_removes_it_on_ctrl_c() {
    let dir = scratch("link");
    let link = dir.join("mycobot");
    symlink("/dev/pts/stale-from-a-killed-run", &link).unwrap();

    let (mut child, banner) = start(&["--pty-link", link.to_str().unwrap()]);
    let pts = banner
        .lines()
        .find_map(|l| l.strip_prefix("virtual myCobot 280 on "))
        .unwrap_or_else(|| panic!("no pty path in the banner: {banner}"));
    assert_eq!(fs::read_link(&link).unwrap(), PathBuf::from(pts));

    // Through the link, a raw is_power_on request gets the answer "powered on".
    let mut port = OpenOptions::new()
        .read(true)
        .write(true)
        .open(&link)
        .unwrap();
    port.write_all(&[0xFE, 0xFE, 0x02, 0x12, 0xFA]).unwrap();
    let (tx, rx) = mpsc::channel();
    thread::spawn(move || {
        let mut reply = [0u8; 6];
        let _ = tx.send(port.read_exact(&mut reply).map(|()| reply));
    });
    let reply = rx
        .recv_timeout(Duration::from_secs(5))
        .expect("no reply within 5 s");
    assert_eq!(reply.unwrap(), [0xFE, 0xFE, 0x03, 0x12, 0x01, 0xFA]);

    assert!(signal_and_wait(&mut child, Signal::SIGINT), "exit status");
    assert!(
        fs::symlink_metadata(&link).is_err(),
        "link left behind after Ctrl-C"
    );
}

#[test]
fn refuses_to_replace_a_regular_file_with_the_link() {
    let dir = scratch("file");
    let notes = dir.join("notes.txt");
    fs::write(&notes, "keep me").unwrap();
    let out = run_to_end(&["--pty-link", notes.to_str().unwrap()]);
    assert!(!out.status.success());
    assert!(
        String::from_utf8_lossy(&out.stderr).contains("not a symlink"),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    assert_eq!(fs::read_to_string(&notes).unwrap(), "keep me");
}

#[test]
fn a_busy_tcp_port_is_a_clear_error() {
    let taken = TcpListener::bind("127.0.0.1:0").unwrap();
    let addr = taken.local_addr().unwrap().to_string();
    let out = run_to_end(&["--tcp", &addr]);
    assert!(!out.status.success());
    let stderr = String::from_utf8_lossy(&out.stderr);
    assert!(
        stderr.contains(&addr) && stderr.contains("in use"),
        "{stderr}"
    );
}
