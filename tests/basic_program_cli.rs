//! The Basic's own program on the virtual robot as a user meets it (`--basic-program teach`):
//! the start-up line, the keys a, b, c on the robot's standard input and the 3D view's
//! buttons (`POST /button/a`) pressing the Basic's buttons, the view's state carrying what the
//! program does, and a clear refusal with the emulated boards. Raw frames on the
//! pseudo-terminal and the view's own routes: no Python, no browser.
#![allow(clippy::unwrap_used, clippy::expect_used, clippy::indexing_slicing)] // a test harness: a panic is a failed check

use std::fs::{File, OpenOptions};
use std::io::{Read, Write};
use std::net::{SocketAddr, TcpStream};
use std::process::Command;
use std::sync::mpsc;
use std::thread;
use std::time::{Duration, Instant};

use serde_json::Value;
use tungstenite::Message;

#[path = "e2e/launcher.rs"]
mod launcher;
use launcher::{Launched, launch};

/// Longest the robot may take to act on a press or answer a request (generous: a loaded
/// machine; a press takes effect within a few milliseconds normally).
const DEADLINE: Duration = Duration::from_secs(15);

/// The banner line a robot running teach prints.
const TEACH_LINE: &str = "basic program teach (keys a, b, c or the view's buttons: A records a \
                          hand move, B plays it, C stops)";

fn pty_of(robot: &Launched) -> File {
    let path = robot
        .banner_value("virtual myCobot 280: the Basic's USB serial on ")
        .unwrap_or_else(|| panic!("no pty in the banner: {}", robot.banner));
    OpenOptions::new()
        .read(true)
        .write(true)
        .open(path)
        .unwrap()
}

/// Asks "are all servos enabled" (0x51) on `port`; the answer's byte.
fn all_servos_enabled(port: &mut File) -> u8 {
    port.write_all(&[0xFE, 0xFE, 0x02, 0x51, 0xFA]).unwrap();
    let mut reader = port.try_clone().unwrap();
    let (tx, rx) = mpsc::channel();
    thread::spawn(move || {
        let mut reply = [0u8; 6];
        let _ = tx.send(reader.read_exact(&mut reply).map(|()| reply));
    });
    let reply = rx.recv_timeout(DEADLINE).expect("no reply").unwrap();
    assert_eq!(reply[..4], [0xFE, 0xFE, 0x03, 0x51], "{reply:02x?}");
    assert_eq!(reply[5], 0xFA, "{reply:02x?}");
    reply[4]
}

/// Asks until `enabled` is the answer, within [`DEADLINE`].
fn wait_for_servos(port: &mut File, enabled: u8) {
    let deadline = Instant::now() + DEADLINE;
    loop {
        let now = all_servos_enabled(port);
        if now == enabled {
            return;
        }
        assert!(
            Instant::now() < deadline,
            "all servos enabled stayed {now}, not {enabled}"
        );
        thread::sleep(Duration::from_millis(20));
    }
}

#[test]
fn the_keys_on_stdin_press_the_basics_buttons() {
    let mut robot = launch(&["--basic-program", "teach", "--no-web"]);
    assert!(robot.banner.contains(TEACH_LINE), "{}", robot.banner);
    let mut port = pty_of(&robot);
    // Powered on once the Atom has booted and read its servos.
    wait_for_servos(&mut port, 1);

    // A: teach releases the arm to be moved by hand and records. Noise around it is ignored.
    robot.type_keys("x a\n");
    wait_for_servos(&mut port, 0);
    // A again (either case): the record ends, the arm holds where it was left.
    robot.type_keys("A\n");
    wait_for_servos(&mut port, 1);
}

#[test]
fn the_end_of_stdin_does_not_stop_the_robot() {
    let mut robot = launch(&["--basic-program", "teach", "--no-web"]);
    let mut port = pty_of(&robot);
    wait_for_servos(&mut port, 1);
    robot.type_keys("a");
    drop(robot.child.stdin.take());
    wait_for_servos(&mut port, 0);
    assert!(robot.child.try_wait().unwrap().is_none(), "still running");
    assert_eq!(all_servos_enabled(&mut port), 0, "still answering");
}

/// The view's address from the banner.
fn view_addr(robot: &Launched) -> SocketAddr {
    let url = robot
        .banner_value("view on ")
        .unwrap_or_else(|| panic!("no view in the banner: {}", robot.banner));
    url.trim_start_matches("http://").parse().unwrap()
}

/// Sends `method path` to the view as its page would (same `Origin`); the status code.
fn request(addr: SocketAddr, method: &str, path: &str) -> u16 {
    let mut stream = TcpStream::connect(addr).unwrap();
    stream.set_read_timeout(Some(DEADLINE)).unwrap();
    write!(
        stream,
        "{method} {path} HTTP/1.1\r\nHost: {addr}\r\nOrigin: http://{addr}\r\n\
         Content-Length: 0\r\n\r\n"
    )
    .unwrap();
    let mut reply = String::new();
    stream.read_to_string(&mut reply).unwrap();
    reply
        .split(' ')
        .nth(1)
        .and_then(|code| code.parse().ok())
        .unwrap_or_else(|| panic!("no status: {reply}"))
}

/// The view's state stream.
struct State(tungstenite::WebSocket<tungstenite::stream::MaybeTlsStream<TcpStream>>);

impl State {
    fn open(addr: SocketAddr) -> Self {
        let (socket, _) = tungstenite::connect(format!("ws://{addr}/state")).unwrap();
        Self(socket)
    }

    /// Reads snapshots until one's `basic_program` satisfies `done`, within [`DEADLINE`];
    /// returns that `basic_program`.
    fn until(&mut self, what: &str, done: impl Fn(&Value) -> bool) -> Value {
        let deadline = Instant::now() + DEADLINE;
        let mut last = Value::Null;
        while Instant::now() < deadline {
            if let Message::Text(text) = self.0.read().unwrap() {
                let state: Value = serde_json::from_str(text.as_str()).unwrap();
                last = state["basic_program"].clone();
                if done(&last) {
                    return last;
                }
            }
        }
        panic!("the view never showed {what}; last: {last}");
    }
}

#[test]
fn the_views_buttons_press_and_its_state_shows_the_program() {
    let mut robot = launch(&["--basic-program", "teach", "--web", "127.0.0.1:0"]);
    let addr = view_addr(&robot);
    let mut state = State::open(addr);
    let idle = state.until("the program", |p| p["name"] == "teach");
    assert_eq!(idle["activity"], "idle");
    assert_eq!(idle["lines"][0], "now       move by hand after A");

    assert_eq!(request(addr, "POST", "/button/a"), 204);
    state.until("recording", |p| p["activity"] == "recording");
    let some = state.until("points recorded", |p| p["points"].as_u64() >= Some(5));
    assert_eq!(some["lines"][0], "now       RECORDING");
    // C ends the record.
    assert_eq!(request(addr, "POST", "/button/c"), 204);
    let recorded = state.until("the record ended", |p| p["activity"] == "idle");
    assert_eq!(recorded["error"], Value::Null);
    assert_eq!(recorded["lines"][0], "now       ready");

    // B from the keyboard plays it back: the arm stood still, so it is over quickly.
    robot.type_keys("b\n");
    let played = state.until("a playback", |p| p["plays"] == 1 && p["activity"] == "idle");
    assert_eq!(played["error"], Value::Null, "{played}");
    assert_eq!(played["lines"][2], "played    1 times");

    assert_eq!(request(addr, "POST", "/button/x"), 404);
    assert_eq!(request(addr, "GET", "/button/a"), 405);
}

#[test]
fn without_a_program_the_view_has_no_buttons() {
    let robot = launch(&["--web", "127.0.0.1:0"]);
    assert!(!robot.banner.contains("basic program"), "{}", robot.banner);
    let addr = view_addr(&robot);
    let mut state = State::open(addr);
    let deadline = Instant::now() + DEADLINE;
    let snapshot = loop {
        assert!(Instant::now() < deadline, "no snapshot");
        if let Message::Text(text) = state.0.read().unwrap() {
            break serde_json::from_str::<Value>(text.as_str()).unwrap();
        }
    };
    assert_eq!(snapshot["basic_program"], Value::Null);
    assert_eq!(request(addr, "POST", "/button/a"), 409);
}

#[test]
fn the_emulated_boards_refuse_a_program_with_one_line() {
    let out = Command::new(env!("CARGO_BIN_EXE_open-mycobot"))
        .args([
            "--basic-program",
            "teach",
            "--emulated-atom",
            "127.0.0.1:1",
            "--emulated-host",
            "127.0.0.1:2",
        ])
        .output()
        .unwrap();
    assert!(!out.status.success());
    let stderr = String::from_utf8_lossy(&out.stderr);
    assert!(stderr.contains("basic-teach"), "{stderr}");
    assert_eq!(stderr.trim().lines().count(), 1, "{stderr}");
}
