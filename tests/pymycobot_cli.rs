//! The command line of the virtual robot as a user meets it: start-up banner (naming the board
//! whose port it serves), the pty symlink (stale ones replaced, user files never clobbered,
//! removed on Ctrl-C, one robot per link: a second one refuses, a link taken over is left to
//! its new owner), Ctrl-C with clients connected, the 3D view's address, and clear errors.
//! Speaks raw frames on the pseudo-terminal, so it needs no Python.
#![allow(clippy::unwrap_used, clippy::expect_used, clippy::indexing_slicing)] // a test harness: a panic is a failed check

use std::fs::{self, OpenOptions};
use std::io::{Read, Write};
use std::net::{TcpListener, TcpStream};
use std::os::unix::fs::symlink;
use std::path::{Path, PathBuf};
use std::process::{Command, Output};
use std::sync::mpsc;
use std::thread;
use std::time::Duration;

use nix::sys::signal::Signal;

#[path = "e2e/launcher.rs"]
mod launcher;
use launcher::launch;

fn scratch(name: &str) -> PathBuf {
    let dir = PathBuf::from(env!("CARGO_TARGET_TMPDIR")).join(format!("cli-{name}"));
    let _ = fs::remove_dir_all(&dir);
    fs::create_dir_all(&dir).unwrap();
    dir
}

fn run_to_end(args: &[&str]) -> Output {
    Command::new(env!("CARGO_BIN_EXE_open-mycobot"))
        .args(args)
        .output()
        .unwrap()
}

#[test]
fn serves_the_link_replaces_a_stale_one_and_removes_it_on_ctrl_c() {
    let dir = scratch("link");
    let link = dir.join("mycobot");
    symlink("/dev/pts/stale-from-a-killed-run", &link).unwrap();

    let mut robot = launch(&["--pty-link", link.to_str().unwrap(), "--no-web"]);
    let pts = robot
        .banner_value("virtual myCobot 280: the Basic's USB serial on ")
        .unwrap_or_else(|| panic!("no pty path in the banner: {}", robot.banner));
    assert_eq!(fs::read_link(&link).unwrap(), PathBuf::from(pts));

    // Through the link, a raw is_power_on request gets the answer "powered on".
    assert_powered_on(&link);

    let exit = robot.stop_with(Signal::SIGINT);
    assert!(
        exit.is_some_and(|s| s.success()),
        "exit after Ctrl-C: {exit:?}"
    );
    assert!(
        fs::symlink_metadata(&link).is_err(),
        "link left behind after Ctrl-C"
    );
}

/// Asks the robot on `port` (a path) whether it is powered on; it must say yes within 5 s.
fn assert_powered_on(port: &Path) {
    let mut port = OpenOptions::new()
        .read(true)
        .write(true)
        .open(port)
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
}

#[test]
fn the_start_up_line_names_the_board_whose_port_is_served() {
    let robot = launch(&["--port", "atom-usb", "--no-web"]);
    let pts = robot
        .banner_value("virtual myCobot 280: the Atom's USB serial on ")
        .unwrap_or_else(|| panic!("no Atom port in the banner: {}", robot.banner));
    // The Atom answers on its own link, with no Basic in between.
    assert_powered_on(Path::new(pts));
}

#[test]
fn the_seed_dialect_on_the_atoms_own_port_is_refused_with_one_line() {
    let out = run_to_end(&["--port", "atom-usb", "--dialect", "seed", "--no-web"]);
    assert!(!out.status.success());
    let stderr = String::from_utf8_lossy(&out.stderr);
    assert!(
        stderr.contains("the Atom's own port speaks pymycobot's"),
        "{stderr}"
    );
    assert_eq!(stderr.trim().lines().count(), 1, "{stderr}");
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
fn a_busy_tcp_or_view_port_is_a_clear_error() {
    for (option, what) in [("--tcp", "listen"), ("--web", "view")] {
        let taken = TcpListener::bind("127.0.0.1:0").unwrap();
        let addr = taken.local_addr().unwrap().to_string();
        let out = run_to_end(&[option, &addr]);
        assert!(!out.status.success(), "{option} {addr} started");
        let stderr = String::from_utf8_lossy(&out.stderr);
        assert!(
            stderr.contains(what) && stderr.contains(&addr) && stderr.contains("in use"),
            "{option}: {stderr}"
        );
    }
}

/// The first bytes of the answer to `GET path` at `url` (`http://host:port`).
fn http_get(url: &str, path: &str) -> String {
    let addr = url.strip_prefix("http://").unwrap();
    let mut stream = TcpStream::connect(addr).unwrap();
    write!(stream, "GET {path} HTTP/1.1\r\nHost: {addr}\r\n\r\n").unwrap();
    let mut reply = String::new();
    stream.read_to_string(&mut reply).unwrap();
    reply
}

#[test]
fn the_view_is_served_where_the_banner_says_and_can_be_turned_off() {
    let robot = launch(&["--web", "127.0.0.1:0"]);
    let url = robot
        .banner_value("view on ")
        .unwrap_or_else(|| panic!("no view address in the banner: {}", robot.banner));
    let page = http_get(url, "/");
    assert!(
        page.starts_with("HTTP/1.1 200") && page.contains("<canvas"),
        "{page}"
    );
    assert!(http_get(url, "/model.json").contains("\"d_mm\":[131.22,"));

    let quiet = launch(&["--no-web"]);
    assert!(quiet.banner_value("view on ").is_none(), "{}", quiet.banner);
}

#[test]
fn when_the_default_view_port_is_taken_another_is_used_and_said() {
    // Held here, or already held by someone else: either way it is taken.
    let _held = TcpListener::bind("127.0.0.1:8280");
    let robot = launch(&[]);
    let line = robot
        .banner_value("view on ")
        .unwrap_or_else(|| panic!("no view address in the banner: {}", robot.banner));
    let (url, note) = line.split_once(' ').unwrap_or((line, ""));
    assert_eq!(note, "(127.0.0.1:8280 is in use)", "{line}");
    assert!(!url.ends_with(":8280"), "{line}");
    assert!(http_get(url, "/").starts_with("HTTP/1.1 200"));
}

/// The one line a robot prints when the link it was asked for is served by another.
const LINK_TAKEN: &str = "is served by another running virtual robot";

/// The pseudo-terminal `robot` serves, from its banner.
fn pts_of(robot: &launcher::Launched) -> PathBuf {
    let pts = robot
        .banner_value("virtual myCobot 280: the Basic's USB serial on ")
        .unwrap_or_else(|| panic!("no pty path in the banner: {}", robot.banner));
    PathBuf::from(pts)
}

/// `link` with `.lock` appended: the lock file a robot holds beside its link.
fn lock_of(link: &Path) -> PathBuf {
    let mut name = link.as_os_str().to_owned();
    name.push(".lock");
    PathBuf::from(name)
}

#[test]
fn a_second_robot_on_a_served_link_refuses_with_one_line_and_the_first_still_serves() {
    let dir = scratch("second");
    let link = dir.join("mycobot");
    let first = launch(&["--pty-link", link.to_str().unwrap(), "--no-web"]);
    let first_pts = pts_of(&first);

    let second = run_to_end(&["--pty-link", link.to_str().unwrap(), "--no-web"]);
    assert!(!second.status.success(), "the second robot started");
    let stderr = String::from_utf8_lossy(&second.stderr);
    let lines: Vec<&str> = stderr.lines().collect();
    assert_eq!(lines.len(), 1, "not one line: {stderr}");
    assert!(
        lines[0].contains(LINK_TAKEN)
            && lines[0].contains(link.to_str().unwrap())
            && lines[0].contains(&format!("pid {}", first.child.id())),
        "{stderr}"
    );

    assert_eq!(fs::read_link(&link).unwrap(), first_pts);
    assert_powered_on(&link);
}

#[test]
fn a_robot_whose_link_was_taken_over_leaves_it_to_the_new_owner() {
    let dir = scratch("taken-over");
    let link = dir.join("mycobot");
    let mut first = launch(&["--pty-link", link.to_str().unwrap(), "--no-web"]);
    // Someone deletes the first robot's lock file (a cleaner of /tmp, say): a second robot
    // then takes the name over.
    fs::remove_file(lock_of(&link)).unwrap();
    let mut second = launch(&["--pty-link", link.to_str().unwrap(), "--no-web"]);
    let second_pts = pts_of(&second);
    assert_eq!(fs::read_link(&link).unwrap(), second_pts);

    let exit = first.stop_with(Signal::SIGINT);
    assert!(exit.is_some_and(|s| s.success()), "first robot: {exit:?}");
    assert_eq!(
        fs::read_link(&link).unwrap(),
        second_pts,
        "the first robot removed or changed the second's link"
    );
    let pid = fs::read_to_string(lock_of(&link)).unwrap();
    assert_eq!(pid.trim(), second.child.id().to_string(), "lock file");
    assert_powered_on(&link);

    let exit = second.stop_with(Signal::SIGINT);
    assert!(exit.is_some_and(|s| s.success()), "second robot: {exit:?}");
    assert!(fs::symlink_metadata(&link).is_err(), "link left behind");
    assert!(fs::symlink_metadata(lock_of(&link)).is_err(), "lock left");
}

#[test]
fn the_link_of_a_killed_robot_is_taken_over() {
    let dir = scratch("killed");
    let link = dir.join("mycobot");
    let mut killed = launch(&["--pty-link", link.to_str().unwrap(), "--no-web"]);
    killed.child.kill().unwrap(); // SIGKILL: no clean-up at all
    killed.child.wait().unwrap();
    assert!(fs::symlink_metadata(&link).is_ok() && fs::metadata(lock_of(&link)).is_ok());

    let next = launch(&["--pty-link", link.to_str().unwrap(), "--no-web"]);
    assert_eq!(fs::read_link(&link).unwrap(), pts_of(&next));
    assert_powered_on(&link);
}

/// Longest a test lets the robot take to exit after Ctrl-C: generous, for a loaded machine
/// (an idle one takes a few milliseconds).
const CTRL_C_DEADLINE: Duration = Duration::from_secs(3);

#[test]
fn ctrl_c_with_clients_connected_exits_at_once() {
    let dir = scratch("ctrl-c");
    let link = dir.join("mycobot");
    let mut robot = launch(&[
        "--pty-link",
        link.to_str().unwrap(),
        "--tcp",
        "127.0.0.1:0",
        "--web",
        "127.0.0.1:0",
        "--basic-flash",
        dir.join("flash.bin").to_str().unwrap(),
    ]);
    // A serial client that keeps the port open, a TCP client, and a page's state stream.
    assert_powered_on(&link);
    let _serial = OpenOptions::new()
        .read(true)
        .write(true)
        .open(&link)
        .unwrap();
    let mut tcp = TcpStream::connect(robot.banner_value("tcp on ").unwrap()).unwrap();
    tcp.set_read_timeout(Some(Duration::from_secs(5))).unwrap();
    tcp.write_all(&[0xFE, 0xFE, 0x02, 0x12, 0xFA]).unwrap();
    let mut reply = [0u8; 6];
    tcp.read_exact(&mut reply).unwrap();
    assert_eq!(reply, [0xFE, 0xFE, 0x03, 0x12, 0x01, 0xFA]);
    let view = robot.banner_value("view on http://").unwrap();
    let mut stream = TcpStream::connect(view).unwrap();
    write!(
        stream,
        "GET /state HTTP/1.1\r\nHost: {view}\r\nUpgrade: websocket\r\nConnection: Upgrade\r\n\
         Sec-WebSocket-Key: dGhlIHNhbXBsZSBub25jZQ==\r\nSec-WebSocket-Version: 13\r\n\r\n"
    )
    .unwrap();
    stream
        .set_read_timeout(Some(Duration::from_secs(5)))
        .unwrap();
    let mut head = [0u8; 12];
    stream.read_exact(&mut head).unwrap();
    assert_eq!(&head, b"HTTP/1.1 101", "the stream did not open");

    let asked = std::time::Instant::now();
    let exit = robot.stop_with(Signal::SIGINT);
    let took = asked.elapsed();
    eprintln!("exit after Ctrl-C with clients connected: {took:?}");
    assert!(exit.is_some_and(|s| s.success()), "exit: {exit:?}");
    assert!(took < CTRL_C_DEADLINE, "took {took:?}");
    assert!(fs::symlink_metadata(&link).is_err(), "link left behind");
}
