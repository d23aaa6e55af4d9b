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
//!
//! `atom_loop_passes_on_the_emulated_esp32` and `basic_loop_passes_on_the_emulated_esp32`: the
//! cost of the Atom's and the Basic's loop passes on the ESP32, in instructions, against their
//! budgets (docs/boards.md, "Loop passes on the chip").
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

/// `-icount` shift of the pass-cost run: every emulated instruction takes 2^2 = 4 ns of the
/// emulated chip's time, about a 240 MHz chip's cycle, so the loop's timing stays realistic.
const ICOUNT_SHIFT: u32 = 2;
/// Longest the pass-cost image may run (about 75 s on a quiet machine).
const STEPS_DEADLINE: Duration = Duration::from_secs(600);
/// Cycles an instruction is allowed at 240 MHz when a budget in time becomes one in
/// instructions: the LX6 issues at most one a cycle; the rest is room for flash-cache misses.
const CYCLES_PER_INSTRUCTION: u64 = 3; // over 2: 1.5 cycles
/// The ESP32's clock, MHz.
const CHIP_MHZ: u64 = 240;

/// Instructions a pass may take to stay within `us` at 240 MHz, 1.5 cycles each.
const fn budget(us: u64) -> u64 {
    us * CHIP_MHZ * 2 / CYCLES_PER_INSTRUCTION
}
/// The pass that takes a command (and plans its motion): the bus is quiet then (the Basic
/// forwards in the Atom's gap, with no servo transaction under way), so the deadline is that
/// of the motion under way, whose next point is due within its 20 ms period: half of it.
const COMMAND_PASS_BUDGET: u64 = budget(10_000);
/// Every other pass: a servo answer that comes during it is still taken up to 5 ms after its
/// deadline (the Atom's late-answer window), and fits the UART's 128-byte FIFO.
const OTHER_PASS_BUDGET: u64 = budget(5_000);
/// The bus's reply margin (150 us): a pass within it never needs the late-answer window.
const REPLY_MARGIN_BUDGET: u64 = budget(150);
/// Every pass of the Basic's loop: the bus UART's 128-byte receive FIFO holds 1.28 ms of a
/// 1 Mbaud wire that is never idle; a longer pass while the Atom answers loses bytes.
const BASIC_PASS_BUDGET: u64 = budget(1_000);
/// The part of the Atom's 100 us gap where the Basic may start a request (60 to 80 us of
/// quiet, `forwarder::may_start_after_quiet`): a pass within it never misses a gap.
const GAP_WINDOW_BUDGET: u64 = budget(20);

/// One step of the pass-cost image's report.
#[derive(Debug)]
struct StepCost {
    name: String,
    passes: u64,
    first_cycles: u64,
    other_cycles: u64,
    reply: String,
    error: String,
}

/// A pass-cost report's `step NAME: REST` line: the name, the rest, and the number after a key
/// in the rest.
fn step_line(line: &str) -> Option<(&str, &str, impl Fn(&str) -> Option<u64> + '_)> {
    let (name, rest) = line.strip_prefix("step ")?.split_once(": ")?;
    let number = move |key: &str| -> Option<u64> {
        let at = rest.find(key)? + key.len();
        rest[at..]
            .split(|c: char| !c.is_ascii_digit())
            .next()?
            .parse()
            .ok()
    };
    Some((name, rest, number))
}

/// Parses `step NAME: passes P, first F cycles, longest other L cycles (pass K), mean M,
/// reply [..], error E`.
fn step_cost(line: &str) -> Option<StepCost> {
    let (name, rest, number) = step_line(line)?;
    let reply = rest.split("reply ").nth(1)?.split(", error").next()?;
    Some(StepCost {
        name: name.to_string(),
        passes: number("passes ")?,
        first_cycles: number("first ")?,
        other_cycles: number("longest other ")?,
        reply: reply.to_string(),
        error: rest.rsplit("error ").next()?.trim().to_string(),
    })
}

/// Runs the pass-cost image `name` (`.ci/link-esp32 --only NAME`) on the emulated ESP32 under
/// `-icount` until it prints `NAME: done`; its UART0 report, the machine, and a function from
/// cycles to instructions (from the report's clock line). `None`, said in one line, without
/// an emulator.
fn run_steps_image(name: &str) -> Option<(String, String, impl Fn(u64) -> u64)> {
    let Some(qemu) = std::env::var_os("ESP_QEMU_XTENSA").filter(|v| !v.is_empty()) else {
        say(&format!(
            "emulated passes ({name}): skipped, ESP_QEMU_XTENSA is not set (no ESP32 emulator here)"
        ));
        return None;
    };
    let root = workspace();
    let link = Command::new(root.join(".ci/link-esp32"))
        .args(["--only", name])
        .current_dir(&root)
        .output()
        .expect("run .ci/link-esp32");
    assert!(
        link.status.success(),
        ".ci/link-esp32 --only {name} failed:\n{}",
        String::from_utf8_lossy(&link.stdout)
    );
    let work = std::env::temp_dir().join(format!("open-mycobot-{name}-{}", std::process::id()));
    std::fs::create_dir_all(&work).unwrap();
    let flash = work.join("flash.bin");
    std::fs::copy(
        root.join(format!("target/esp32-images/{name}-merged.bin")),
        &flash,
    )
    .unwrap();
    let efuse = work.join("efuse.bin");
    let made = Command::new(root.join("tools/qemu-efuse"))
        .arg("esp32")
        .arg(&efuse)
        .status()
        .unwrap();
    assert!(made.success(), "tools/qemu-efuse failed");
    let machines = Command::new(&qemu)
        .args(["-machine", "help"])
        .output()
        .unwrap();
    let machine = std::env::var("ESP_QEMU_MACHINE_ESP32").unwrap_or_else(|_| {
        let list = String::from_utf8_lossy(&machines.stdout);
        if list.lines().any(|l| l.starts_with("esp32-picsimlab ")) {
            "esp32-picsimlab".into()
        } else {
            "esp32".into()
        }
    });
    let uart0 = work.join("uart0.txt");
    let mut emulator = Command::new(&qemu)
        .args(["-nographic", "-machine", &machine, "-monitor", "none"])
        .args(["-icount", &format!("shift={ICOUNT_SHIFT}")])
        .arg("-drive")
        .arg(format!("file={},if=mtd,format=raw", flash.display()))
        .arg("-drive")
        .arg(format!(
            "file={},if=none,format=raw,id=efuse",
            efuse.display()
        ))
        .args([
            "-global",
            "driver=nvram.esp32.efuse,property=drive,value=efuse",
        ])
        .arg("-serial")
        .arg(format!("file:{}", uart0.display()))
        .args(["-serial", "null"])
        .stdout(Stdio::null())
        .stderr(Stdio::null())
        .spawn()
        .expect("start the ESP32 emulator");
    let done = format!("{name}: done");
    let deadline = Instant::now() + STEPS_DEADLINE;
    let report = loop {
        let text = std::fs::read_to_string(&uart0).unwrap_or_default();
        if text.contains(&done) || Instant::now() > deadline {
            break text;
        }
        thread::sleep(Duration::from_millis(500));
    };
    let _ = emulator.kill();
    let _ = emulator.wait();
    let _ = std::fs::remove_dir_all(&work);
    assert!(
        report.contains(&done),
        "the pass-cost image {name} did not finish in {STEPS_DEADLINE:?}:\n{report}"
    );

    // Cycles per microsecond of the emulated chip's time; an instruction takes 2^shift ns.
    let clock = report
        .lines()
        .find_map(|l| l.strip_prefix("clock: "))
        .expect("a clock line");
    let numbers: Vec<f64> = clock
        .split(|c: char| !c.is_ascii_digit())
        .filter_map(|n| n.parse().ok())
        .collect();
    let cycles_per_instruction = numbers[0] / numbers[1] * f64::from(1u32 << ICOUNT_SHIFT) / 1000.0;
    let instructions = move |cycles: u64| (cycles as f64 / cycles_per_instruction).round() as u64;
    Some((report, machine, instructions))
}

/// The Atom's loop on the emulated ESP32, pass by pass (firmware-atom's `atom-steps` image:
/// the real loop against servos inside the image): every step answered as on the host, and
/// each pass within its budget in instructions (docs/boards.md, "Loop passes on the chip").
#[test]
fn atom_loop_passes_on_the_emulated_esp32() {
    let Some((report, machine, instructions)) = run_steps_image("atom-steps") else {
        return;
    };
    let steps: Vec<StepCost> = report.lines().filter_map(step_cost).collect();
    assert_eq!(steps.len(), 11, "every step reported:\n{report}");
    say(&format!(
        "== the Atom's loop passes on the emulated ESP32 ({machine}, -icount shift={ICOUNT_SHIFT}), instructions (budget: command {COMMAND_PASS_BUDGET}, other {OTHER_PASS_BUDGET}; the reply margin is {REPLY_MARGIN_BUDGET})"
    ));
    let mut over = Vec::new();
    for step in &steps {
        let (first, other) = (
            instructions(step.first_cycles),
            instructions(step.other_cycles),
        );
        let margin = if first.max(other) <= REPLY_MARGIN_BUDGET {
            "within the reply margin"
        } else {
            "past the reply margin"
        };
        say(&format!(
            "   {:<24} {:>7} passes, command pass {:>9}, longest other {:>9}: {margin}, reply {}, error {}",
            step.name, step.passes, first, other, step.reply, step.error
        ));
        if first > COMMAND_PASS_BUDGET || other > OTHER_PASS_BUDGET {
            over.push(step.name.clone());
        }
        assert_eq!(step.error, "0", "{} left error {}", step.name, step.error);
        if step.name != "idle" {
            assert!(
                step.reply != "[]" && step.reply != "[00]",
                "{} answered {}",
                step.name,
                step.reply
            );
        }
    }
    assert!(over.is_empty(), "over their budget: {over:?}");
}

/// The Basic's loop on the emulated ESP32, pass by pass (firmware-basic's `basic-steps` image:
/// the real loop and the status text against a busy Atom inside the image): every request
/// answered, and each pass within the bus FIFO's budget in instructions (docs/boards.md, "Loop
/// passes on the chip").
#[test]
fn basic_loop_passes_on_the_emulated_esp32() {
    let Some((report, machine, instructions)) = run_steps_image("basic-steps") else {
        return;
    };
    // `step NAME: passes P, longest L cycles (pass K), mean M, replies R of A, forwarded F`.
    let steps: Vec<(String, u64, u64, u64, u64)> = report
        .lines()
        .filter_map(|line| {
            let (name, _, number) = step_line(line)?;
            Some((
                name.to_string(),
                number("passes ")?,
                number("longest ")?,
                number("replies ")?,
                number(" of ")?,
            ))
        })
        .collect();
    assert_eq!(steps.len(), 9, "every step reported:\n{report}");
    say(&format!(
        "== the Basic's loop passes on the emulated ESP32 ({machine}, -icount shift={ICOUNT_SHIFT}), instructions (budget {BASIC_PASS_BUDGET}; the gap window is {GAP_WINDOW_BUDGET})"
    ));
    let mut over = Vec::new();
    for (name, passes, longest, replies, asked) in &steps {
        let longest = instructions(*longest);
        let window = if longest <= GAP_WINDOW_BUDGET {
            "within the gap window"
        } else {
            "past the gap window"
        };
        say(&format!(
            "   {name:<32} {passes:>7} passes, longest {longest:>7}: {window}, replies {replies} of {asked}"
        ));
        if longest > BASIC_PASS_BUDGET {
            over.push(name.clone());
        }
        assert_eq!(
            replies, asked,
            "{name}: {replies} replies to {asked} requests"
        );
    }
    assert!(over.is_empty(), "over their budget: {over:?}");
}
