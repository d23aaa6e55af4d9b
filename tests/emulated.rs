//! `cargo test --release --test emulated`: the pymycobot 4.0.7 subset (tests/e2e/emulated_subset.py:
//! status, versions, IO, bad input, errors) and the seed dialect's
//! (tests/e2e/emulated_seed_subset.py: the manual's frames, raw, after 0xC5 switches the Basic)
//! through the whole emulated arm, then the pymycobot subset's moves (angles, coordinates, a
//! line, jog and stop) on the emulated Atom alone (`tools/emulate --atom-only`: with both boards'
//! emulators on two cores the Atom's servo answers come too late, docs/boards.md), against the
//! exact board images on emulated chips, started by tools/emulate with Espressif's QEMU:
//! the ESP32 images when `ESP_QEMU_XTENSA` names its `qemu-system-xtensa`, the ESP32-C3 images
//! when `ESP_QEMU_RISCV32` names its `qemu-system-riscv32`. Without either it says so in one
//! line and passes (CI has no emulator). It prints, per image, what passed. The machine is
//! tools/emulate's choice, so the test and a person running tools/emulate see the same one:
//! `esp32-picsimlab` where the ESP32 emulator has it (PICSimLab's fork), else `esp32`
//! (`ESP_QEMU_MACHINE_ESP32` overrides it); `esp32c3` for the C3.
#![allow(clippy::unwrap_used, clippy::expect_used, clippy::indexing_slicing)] // a test harness: a panic is a failed check

use std::io::{BufRead, BufReader, Write};
use std::path::PathBuf;
use std::process::{Child, Command, Stdio};
use std::sync::mpsc;
use std::thread;
use std::time::{Duration, Instant};

use nix::sys::signal::{Signal, kill};
use nix::unistd::Pid;

#[path = "e2e/venv.rs"]
mod venv;
use venv::{python, workspace};

/// Longest tools/emulate may take to build the images and start the boards (a first ESP32
/// link builds the linker: minutes).
const START_DEADLINE: Duration = Duration::from_secs(900);
/// Longest the subset may run against one image set.
const SUBSET_DEADLINE: Duration = Duration::from_secs(300);

/// One set of images on one chip: the emulator variable and tools/emulate's `--chip`.
const CHIPS: [(&str, &str); 2] = [
    ("ESP_QEMU_XTENSA", "esp32"),
    ("ESP_QEMU_RISCV32", "esp32c3"),
];

/// What tools/emulate runs: the whole arm, or the Atom alone (`--atom-only`).
#[derive(Clone, Copy, PartialEq, Eq)]
enum Boards {
    Arm,
    Atom,
}

impl Boards {
    /// As the subsets' `EMULATED_BOARDS` names it.
    fn name(self) -> &'static str {
        match self {
            Self::Arm => "arm",
            Self::Atom => "atom",
        }
    }
}

/// tools/emulate running `Boards`; stopped (with its emulators) when dropped.
struct Emulated {
    child: Child,
    link: PathBuf,
}

impl Emulated {
    fn start(chip: &str, boards: Boards) -> Emulated {
        let link = std::env::temp_dir().join(format!(
            "open-mycobot-emulated-{chip}-{}-{}",
            boards.name(),
            std::process::id()
        ));
        let mut args = vec!["--chip", chip, "--pty-link", link.to_str().unwrap()];
        if boards == Boards::Atom {
            args.push("--atom-only");
        }
        let mut child = Command::new(workspace().join("tools/emulate"))
            .args(&args)
            .stdout(Stdio::piped())
            .spawn()
            .expect("start tools/emulate");
        let stdout = child.stdout.take().unwrap();
        let (tx, lines) = mpsc::channel();
        thread::spawn(move || {
            for line in BufReader::new(stdout).lines().map_while(Result::ok) {
                let _ = tx.send(line);
            }
        });
        let deadline = Instant::now() + START_DEADLINE;
        loop {
            let left = deadline.saturating_duration_since(Instant::now());
            match lines.recv_timeout(left) {
                Ok(line) if line.starts_with("ready") => break,
                Ok(_) => {}
                Err(_) => panic!("tools/emulate --chip {chip} printed no ready line"),
            }
        }
        Emulated { child, link }
    }
}

impl Drop for Emulated {
    fn drop(&mut self) {
        if let Ok(pid) = i32::try_from(self.child.id()) {
            let _ = kill(Pid::from_raw(pid), Signal::SIGTERM);
        }
        let deadline = Instant::now() + Duration::from_secs(10);
        while Instant::now() < deadline {
            if matches!(self.child.try_wait(), Ok(Some(_))) {
                return;
            }
            thread::sleep(Duration::from_millis(50));
        }
        let _ = self.child.kill();
        let _ = self.child.wait();
    }
}

/// The subsets, in the order they run, each on the boards it needs: one per dialect through the
/// whole arm, then the moves on the Atom alone.
const SUBSETS: [(Boards, &str); 3] = [
    (Boards::Arm, "emulated_subset.py"),
    (Boards::Arm, "emulated_seed_subset.py"),
    (Boards::Atom, "emulated_subset.py"),
];

/// Runs `subset` against `port` on `boards`; returns whether it passed and unittest's report.
fn run_subset(python: &PathBuf, subset: &str, boards: Boards, port: &PathBuf) -> (bool, String) {
    let mut child = Command::new(python)
        .args([subset, "-v"])
        .current_dir(workspace().join("tests/e2e"))
        .env("MYCOBOT_PORT", port)
        .env("EMULATED_BOARDS", boards.name())
        .stdout(Stdio::piped())
        .stderr(Stdio::piped())
        .spawn()
        .expect("start the Python subset");
    let deadline = Instant::now() + SUBSET_DEADLINE;
    while matches!(child.try_wait(), Ok(None)) && Instant::now() < deadline {
        thread::sleep(Duration::from_millis(100));
    }
    if matches!(child.try_wait(), Ok(None)) {
        let _ = child.kill();
    }
    let output = child.wait_with_output().expect("the subset's output");
    let report = String::from_utf8_lossy(&output.stderr).into_owned();
    (output.status.success(), report)
}

/// A line for the person running the tests: straight to stderr, which the test harness does
/// not capture (its capture takes only `print!` and `eprint!`).
fn say(line: &str) {
    let _ = writeln!(std::io::stderr(), "{line}");
}

#[test]
fn pymycobot_subset_on_the_emulated_images() {
    let chips: Vec<&str> = CHIPS
        .iter()
        .filter(|(var, _)| std::env::var_os(var).is_some_and(|v| !v.is_empty()))
        .map(|&(_, chip)| chip)
        .collect();
    if chips.is_empty() {
        say(
            "emulated: skipped, neither ESP_QEMU_XTENSA nor ESP_QEMU_RISCV32 is set (no emulator here)",
        );
        return;
    }
    let python = python();
    let mut failed = Vec::new();
    for chip in chips {
        let mut running: Option<(Boards, Emulated)> = None;
        for (boards, subset) in SUBSETS {
            if running.as_ref().is_none_or(|(b, _)| *b != boards) {
                // One emulated set at a time: the last one stops before the next starts.
                drop(running.take());
                running = Some((boards, Emulated::start(chip, boards)));
            }
            let Some((_, emulated)) = &running else {
                continue;
            };
            let (passed, report) = run_subset(&python, subset, boards, &emulated.link);
            say(&format!(
                "== {chip} images (tools/emulate --chip {chip}, {}), {subset}: {}",
                boards.name(),
                if passed { "passed" } else { "FAILED" }
            ));
            for line in report.lines().filter(|l| {
                l.ends_with(" ok")
                    || l.contains("skipped")
                    || l.contains("... FAIL")
                    || l.contains("... ERROR")
                    || l.starts_with("AssertionError")
            }) {
                say(&format!("   {line}"));
            }
            if !passed {
                say(&report);
                failed.push(format!("{chip} {} {subset}", boards.name()));
            }
        }
    }
    assert!(
        failed.is_empty(),
        "failed on the emulated images: {failed:?}"
    );
}
