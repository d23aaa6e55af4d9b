//! The `mycobot` command line and the std client (mycobot-api's transports) against the virtual
//! robot, in both dialects. Each test serves its own robot in-process (the root package's
//! library, as `open-mycobot` serves it: a pseudo-terminal and a TCP port, in real time) and
//! runs the `mycobot` binary on it.
#![allow(clippy::unwrap_used, clippy::expect_used, clippy::indexing_slicing)] // a test harness: a panic is a failed check

use std::net::SocketAddr;
use std::path::PathBuf;
use std::process::{Child, Command, Output, Stdio};
use std::sync::Arc;
use std::sync::atomic::{AtomicBool, Ordering};
use std::sync::mpsc;
use std::thread::{self, JoinHandle};
use std::time::{Duration, Instant};

use mycobot_api::MyCobot;
use mycobot_api::convert::{angles, to_deg};
use open_mycobot::host::pty::PseudoTerminal;
use open_mycobot::host::realtime::{RealtimeDriver, ServedRobot};
use open_mycobot::host::tcp::TcpServer;
use open_mycobot::sim::{BasicFlashStore, HostLink, RobotConfig, VirtualRobot};
use protocol_core::dialect::Dialect;
use protocol_core::units::SpeedPercent;

/// Longest anything here waits for the arm (it moves at full speed in a second or two).
const PATIENCE: Duration = Duration::from_secs(30);

/// Virtual time the robot runs before it is served.
const BOOTED_US: u64 = 500_000;

/// A virtual robot served on a pseudo-terminal and a TCP port until dropped.
struct Robot {
    pty: PathBuf,
    tcp: SocketAddr,
    dialect: Dialect,
    stop: Arc<AtomicBool>,
    served: Option<JoinHandle<()>>,
}

impl Robot {
    /// A robot whose Basic speaks `dialect`, powered on with every joint at 0.
    fn start(dialect: Dialect) -> Self {
        let stop = Arc::new(AtomicBool::new(false));
        let (tx, rx) = mpsc::channel();
        let stopped = Arc::clone(&stop);
        let served = thread::spawn(move || {
            let pty = PseudoTerminal::open().unwrap();
            let tcp = TcpServer::bind(([127, 0, 0, 1], 0).into()).unwrap();
            let mut config = RobotConfig::default();
            config.basic.dialect = Some(dialect);
            let mut robot =
                VirtualRobot::new(config).with_basic_flash(BasicFlashStore::in_memory());
            // Booted, with every joint read, before the first client comes (a motion asked in
            // the robot's first milliseconds is refused: the Atom does not yet know where the
            // joints are).
            robot.run_until(BOOTED_US);
            tx.send((pty.slave_path().to_owned(), tcp.local_addr().unwrap()))
                .unwrap();
            let robot = ServedRobot {
                robot,
                link: HostLink::Basic,
            };
            RealtimeDriver::new(robot, pty, Some(tcp))
                .on_late(|_| {})
                .run(&stopped)
                .unwrap();
        });
        let (pty, tcp) = rx.recv_timeout(PATIENCE).unwrap();
        Self {
            pty,
            tcp,
            dialect,
            stop,
            served: Some(served),
        }
    }

    /// `mycobot` with the global options for this robot's pseudo-terminal, then `args`.
    fn cli(&self, args: &[&str]) -> Command {
        self.cli_on("--port", self.pty.to_str().unwrap(), args)
    }

    /// `mycobot` on this robot's TCP port.
    fn cli_tcp(&self, args: &[&str]) -> Command {
        self.cli_on("--tcp", &self.tcp.to_string(), args)
    }

    fn cli_on(&self, option: &str, value: &str, args: &[&str]) -> Command {
        let dialect = match self.dialect {
            Dialect::Pymycobot => "pymycobot",
            Dialect::Seed => "seed",
        };
        let mut command = mycobot(&[option, value, "--dialect", dialect]);
        command.args(args);
        command
    }

    /// Runs `mycobot args` on the pseudo-terminal; it must succeed. Its stdout.
    fn ok(&self, args: &[&str]) -> String {
        succeeded(&self.cli(args).output().unwrap(), args)
    }

    /// The angles `mycobot angles` prints.
    fn angles(&self) -> [f32; 6] {
        six(&self.ok(&["angles"]))
    }

    /// Asks until the arm says it does not move.
    fn wait_still(&self) {
        let deadline = Instant::now() + PATIENCE;
        while !self.ok(&["status"]).contains("moving: no") {
            assert!(Instant::now() < deadline, "the arm never came to rest");
            thread::sleep(Duration::from_millis(50));
        }
    }
}

impl Drop for Robot {
    fn drop(&mut self) {
        self.stop.store(true, Ordering::Relaxed);
        if let Some(served) = self.served.take() {
            let _ = served.join();
        }
    }
}

/// The `mycobot` binary with `args`.
fn mycobot(args: &[&str]) -> Command {
    let mut command = Command::new(env!("CARGO_BIN_EXE_mycobot"));
    command.args(args).stdin(Stdio::null());
    command
}

/// The stdout of a run that must have succeeded, with nothing on stderr.
fn succeeded(out: &Output, args: &[&str]) -> String {
    let stdout = String::from_utf8_lossy(&out.stdout).into_owned();
    let stderr = String::from_utf8_lossy(&out.stderr);
    assert!(
        out.status.success(),
        "mycobot {args:?} failed: {stderr}{stdout}"
    );
    assert!(
        stderr.is_empty(),
        "mycobot {args:?} wrote on stderr: {stderr}"
    );
    stdout
}

/// The one line a failed run wrote on stderr (no panic, no debug output), and it failed.
fn failed(out: &Output) -> String {
    let stderr = String::from_utf8_lossy(&out.stderr).into_owned();
    assert!(!out.status.success(), "it succeeded: {stderr}");
    assert_eq!(out.status.code(), Some(1), "{stderr}");
    assert_eq!(stderr.lines().count(), 1, "not one line: {stderr}");
    assert!(stderr.starts_with("mycobot: "), "{stderr}");
    assert!(!stderr.contains("panicked"), "{stderr}");
    stderr
}

/// Six numbers on one line.
fn six(line: &str) -> [f32; 6] {
    assert_eq!(line.lines().count(), 1, "not one line: {line:?}");
    let values: Vec<f32> = line
        .split_whitespace()
        .map(|v| v.parse().unwrap())
        .collect();
    values
        .try_into()
        .unwrap_or_else(|v| panic!("not six values: {v:?}"))
}

fn assert_near(got: [f32; 6], want: [f32; 6], within: f32) {
    for (g, w) in got.iter().zip(want) {
        assert!(
            (g - w).abs() <= within,
            "{got:?} is not {want:?} within {within}"
        );
    }
}

#[test]
fn help_lists_every_command() {
    let out = mycobot(&["--help"]).output().unwrap();
    let help = succeeded(&out, &["--help"]);
    for command in [
        "status",
        "angles",
        "coords",
        "move-angles",
        "move-coords",
        "jog",
        "stop",
        "gripper",
        "led",
        "backup",
        "restore",
        "watch",
    ] {
        assert!(help.contains(command), "{command} missing from:\n{help}");
    }
}

#[test]
fn a_missing_port_is_one_line_and_a_failure() {
    let out = mycobot(&["--port", "/dev/no-such-mycobot", "angles"])
        .output()
        .unwrap();
    let line = failed(&out);
    assert!(line.contains("no such port /dev/no-such-mycobot"), "{line}");
}

#[test]
fn a_port_nobody_answers_on_is_one_line_naming_the_wait() {
    // A pseudo-terminal with no robot behind it.
    let silent = PseudoTerminal::open().unwrap();
    let out = mycobot(&[
        "--port",
        silent.slave_path().to_str().unwrap(),
        "--timeout-ms",
        "200",
        "angles",
    ])
    .output()
    .unwrap();
    let line = failed(&out);
    assert!(line.contains("no reply in 0.2 s"), "{line}");
}

#[test]
fn status_angles_and_coords() {
    let robot = Robot::start(Dialect::Pymycobot);
    let status = robot.ok(&["status"]);
    for line in [
        "powered on: yes",
        "angles (deg): ",
        "coords (mm, deg): ",
        "error: none",
        "moving: no",
    ] {
        assert!(status.contains(line), "{line} missing from:\n{status}");
    }
    assert_eq!(robot.angles(), [0.0; 6]);
    // x y z rx ry rz of the arm standing straight up.
    let coords = six(&robot.ok(&["coords"]));
    assert!(coords[2] > 300.0, "{coords:?}");
}

/// The angles of the moves, negative ones among them.
const ANGLES: [&str; 6] = ["10", "20", "-30", "15", "-25", "40"];
/// The pose of the moves.
const POSE: [&str; 6] = ["150", "-60", "250", "-170", "0", "-90"];

/// Six numbers given as arguments.
fn numbers(values: [&str; 6]) -> [f32; 6] {
    values.map(|v| v.parse().unwrap())
}

/// The arguments `SUBCOMMAND VALUES.. OPTIONS..`.
fn move_args<'a>(subcommand: &'a str, values: [&'a str; 6], options: &[&'a str]) -> Vec<&'a str> {
    let mut args = vec![subcommand];
    args.extend(values);
    args.extend(options);
    args
}

/// `mycobot SUBCOMMAND VALUES.. OPTIONS..`, which must succeed.
fn run_move(robot: &Robot, subcommand: &str, values: [&str; 6], options: &[&str]) {
    robot.ok(&move_args(subcommand, values, options));
}

/// move-angles to [`ANGLES`], then move-coords to [`POSE`] (joint-interpolated), at full
/// speed: each arrives.
fn moves_arrive(robot: &Robot) {
    run_move(robot, "move-angles", ANGLES, &["--speed", "100"]);
    assert_near(robot.angles(), numbers(ANGLES), 0.5);
    run_move(robot, "move-coords", POSE, &["--speed", "100"]);
    assert_near(six(&robot.ok(&["coords"])), numbers(POSE), 1.0);
}

#[test]
fn move_angles_with_negative_values_arrives_and_move_coords_too() {
    let robot = Robot::start(Dialect::Pymycobot);
    moves_arrive(&robot);
    let lower = ["150", "-60", "200", "-170", "0", "-90"];
    run_move(
        &robot,
        "move-coords",
        lower,
        &["--speed", "100", "--linear"],
    );
    assert_near(six(&robot.ok(&["coords"])), numbers(lower), 1.0);
}

#[test]
fn no_wait_returns_while_the_arm_moves_and_stop_stops_a_waiting_move() {
    let robot = Robot::start(Dialect::Pymycobot);
    // A slow move: it has far to go when the command returns.
    robot.ok(&move_args(
        "move-angles",
        ["-90", "0", "0", "0", "0", "0"],
        &["--speed", "10", "--no-wait"],
    ));
    assert!(robot.angles()[0] > -80.0);
    robot.ok(&["stop"]);
    robot.wait_still();
    let stopped = robot.angles();
    assert!(stopped[0] > -80.0, "{stopped:?}");

    // A move waited for over TCP, stopped through the serial port: the wait reports it.
    let mover: Child = robot
        .cli_tcp(&move_args(
            "move-angles",
            ["90", "0", "0", "0", "0", "0"],
            &["--speed", "10"],
        ))
        .stdout(Stdio::null())
        .stderr(Stdio::piped())
        .spawn()
        .unwrap();
    let deadline = Instant::now() + PATIENCE;
    while robot.angles()[0] < stopped[0] + 5.0 {
        assert!(Instant::now() < deadline, "the move never began");
        thread::sleep(Duration::from_millis(20));
    }
    robot.ok(&["stop"]);
    let out = mover.wait_with_output().unwrap();
    let line = failed(&out);
    assert!(line.contains("short of the target"), "{line}");
    assert!(robot.angles()[0] < 80.0);
}

#[test]
fn jog_for_a_while_then_it_stops() {
    let robot = Robot::start(Dialect::Pymycobot);
    robot.ok(&["jog", "1", "+", "--speed", "50", "--for", "0.3"]);
    robot.wait_still();
    let after = robot.angles();
    assert!(after[0] > 1.0, "{after:?}");
    thread::sleep(Duration::from_millis(200));
    assert_eq!(robot.angles(), after);
    robot.ok(&["jog", "z", "-", "--for", "0.1"]);
}

#[test]
fn gripper_led_backup_and_restore_are_answered() {
    let robot = Robot::start(Dialect::Pymycobot);
    robot.ok(&["gripper", "open"]);
    robot.ok(&["gripper", "30", "--speed", "80"]);
    robot.ok(&["gripper", "close"]);
    robot.ok(&["led", "255", "0", "10"]);
    robot.ok(&["backup"]);
    robot.ok(&["backup", "3"]);
    robot.ok(&["restore", "all"]);
    let out = robot.cli(&["led", "256", "0", "0"]).output().unwrap();
    assert!(!out.status.success());
}

#[test]
fn watch_prints_a_header_and_count_rows() {
    let robot = Robot::start(Dialect::Pymycobot);
    let table = robot.ok(&["watch", "--count", "3", "--interval-ms", "50"]);
    let lines: Vec<&str> = table.lines().collect();
    assert_eq!(lines.len(), 4, "{table}");
    assert!(lines[0].contains("j1") && lines[0].contains("rz") && lines[0].contains("error"));
    for row in &lines[1..] {
        let fields: Vec<&str> = row.split_whitespace().collect();
        // t, six angles, six coordinates, "none".
        assert_eq!(fields.len(), 14, "{row}");
        assert_eq!(fields[13], "none", "{row}");
    }
}

#[test]
fn an_out_of_limit_move_is_refused_in_one_line() {
    let robot = Robot::start(Dialect::Pymycobot);
    let out = robot
        .cli(&move_args(
            "move-angles",
            ["0", "0", "200", "0", "0", "0"],
            &[],
        ))
        .output()
        .unwrap();
    let line = failed(&out);
    assert!(
        line.contains("refused: joint 3 is at or beyond its limit"),
        "{line}"
    );
    assert_eq!(robot.angles(), [0.0; 6]);
}

#[test]
fn the_seed_dialect_basics() {
    let robot = Robot::start(Dialect::Seed);
    assert!(robot.ok(&["status"]).contains("powered on: yes"));
    assert_eq!(robot.angles(), [0.0; 6]);
    moves_arrive(&robot);
    robot.ok(&["gripper", "close"]);
    robot.ok(&["led", "0", "0", "255"]);
    robot.ok(&["backup"]);
    robot.ok(&["restore"]);
    let table = robot.ok(&["watch", "--count", "1", "--interval-ms", "50"]);
    assert_eq!(table.lines().count(), 2, "{table}");
    // Unanswered in this dialect, the move is not refused: the wait sees the arm not go.
    let out = robot
        .cli(&move_args(
            "move-angles",
            ["0", "0", "200", "0", "0", "0"],
            &["--speed", "100"],
        ))
        .output()
        .unwrap();
    let line = failed(&out);
    assert!(
        line.contains("short of the target: joint 3 is at or beyond its limit"),
        "{line}"
    );
}

/// Moves with the std client and waits until it says the arm is still at `target`.
fn client_moves<P: protocol_core::BytePort, C: mycobot_api::Clock>(
    arm: &mut MyCobot<P, C>,
    target: [f32; 6],
) {
    arm.power_on().unwrap();
    arm.write_angles(angles(target), SpeedPercent::MAX).unwrap();
    let deadline = Instant::now() + PATIENCE;
    loop {
        let now = arm.get_angles().unwrap().map(to_deg);
        if !arm.check_running().unwrap()
            && now.iter().zip(target).all(|(n, t)| (n - t).abs() <= 0.5)
        {
            break;
        }
        assert!(Instant::now() < deadline, "not there: {now:?}");
        thread::sleep(Duration::from_millis(20));
    }
}

#[test]
fn the_std_client_over_tcp_and_serial_in_both_dialects() {
    for dialect in [Dialect::Pymycobot, Dialect::Seed] {
        let robot = Robot::start(dialect);
        let mut tcp = MyCobot::connect_tcp(robot.tcp, dialect).unwrap();
        client_moves(&mut tcp, [-10.0, 15.0, -20.0, 5.0, 30.0, -45.0]);
        assert!(tcp.get_coords().is_ok());
        drop(tcp);
        let mut serial = MyCobot::open_serial(&robot.pty, dialect).unwrap();
        client_moves(&mut serial, [5.0, -5.0, 10.0, -10.0, 20.0, 0.0]);
        assert!(serial.is_powered_on().unwrap());
    }
}
