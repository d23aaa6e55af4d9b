//! What the 3D view costs the simulation: `get_angles` round trips per second over the
//! pseudo-terminal (`tools/bench_get_angles.py`, pymycobot 4.0.7, real time) with the view off
//! (`--no-web`), on with no page open, and with 1 and with several pages open in headless
//! Chromium (software WebGL, on the same 2 cores as the robot). Also prints how many state
//! messages each page received per second and the robot process's CPU use.
//!
//! `cargo bench -p open-mycobot --bench view_cost [-- --calls 5000 --rounds 3 --pages 4]`
//!
//! Rounds alternate the configurations, so a machine that gets busier or quieter during the
//! run shifts them all alike. Needs Chromium and the pymycobot venv, like the browser test.
#![allow(clippy::unwrap_used, clippy::expect_used, clippy::indexing_slicing)] // a test harness: a panic is a failed check

use std::path::PathBuf;
use std::process::Command;
use std::thread;
use std::time::{Duration, Instant};

#[path = "../tests/e2e/chromium.rs"]
mod chromium;
#[path = "../tests/e2e/launcher.rs"]
mod launcher;
#[path = "../tests/e2e/venv.rs"]
mod venv;
#[path = "../tests/e2e/view_page.rs"]
mod view_page;

use chromium::{Chromium, Page};
use launcher::{Launched, launch};

/// Time the pages get to settle (load, first draws) before the measurement.
const SETTLE: Duration = Duration::from_secs(2);

/// One configuration of the view.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
enum Setup {
    /// `--no-web`.
    Off,
    /// The view served, this many pages open.
    Pages(usize),
}

impl Setup {
    fn label(self) -> String {
        match self {
            Setup::Off => "view off (--no-web)".into(),
            Setup::Pages(0) => "view on, no page".into(),
            Setup::Pages(1) => "1 page open".into(),
            Setup::Pages(n) => format!("{n} pages open"),
        }
    }
}

/// One run of the get_angles benchmark.
#[derive(Clone, Copy, Debug, Default)]
struct Measured {
    rate_per_s: f64,
    p99_ms: f64,
    failed: u64,
    /// State messages each page received per second (0 without pages).
    messages_per_s: f64,
    /// CPU the robot process used, percent of one core.
    robot_cpu_percent: f64,
}

struct Options {
    calls: u32,
    rounds: u32,
    pages: usize,
}

fn options() -> Options {
    let mut options = Options {
        calls: 5_000,
        rounds: 3,
        pages: 4,
    };
    let args: Vec<String> = std::env::args().skip(1).collect();
    for pair in args.windows(2) {
        let value = pair[1].parse().ok();
        match (pair[0].as_str(), value) {
            ("--calls", Some(v)) => options.calls = v,
            ("--rounds", Some(v)) => options.rounds = v,
            ("--pages", Some(v)) => options.pages = v as usize,
            _ => {}
        }
    }
    options
}

fn scratch(name: &str) -> PathBuf {
    PathBuf::from(env!("CARGO_TARGET_TMPDIR")).join(format!("view-cost-{name}"))
}

/// CPU time the process has used, in clock ticks (user + system, /proc/PID/stat).
fn cpu_ticks(pid: u32) -> u64 {
    let stat = std::fs::read_to_string(format!("/proc/{pid}/stat")).unwrap_or_default();
    let after_name = stat.rsplit_once(')').map_or("", |(_, rest)| rest);
    let fields: Vec<&str> = after_name.split_whitespace().collect();
    // Fields 14 and 15 of stat (utime, stime) are 12 and 13 after the name.
    [11, 12]
        .iter()
        .filter_map(|&i| fields.get(i)?.parse::<u64>().ok())
        .sum()
}

/// Clock ticks per second (`getconf CLK_TCK`; 100 on Linux).
const TICKS_PER_S: f64 = 100.0;

/// Runs tools/bench_get_angles.py against the robot's link.
fn get_angles(python: &PathBuf, link: &PathBuf, calls: u32) -> (f64, f64, u64) {
    let output = Command::new(python)
        .arg(venv::workspace().join("tools/bench_get_angles.py"))
        .arg(link)
        .args(["--calls", &calls.to_string()])
        .env("PYTHONWARNINGS", "ignore")
        .output()
        .expect("run tools/bench_get_angles.py");
    let text = String::from_utf8_lossy(&output.stdout);
    let number_after = |prefix: &str, end: &str| -> f64 {
        text.split(prefix)
            .nth(1)
            .and_then(|rest| rest.split(end).next())
            .and_then(|v| v.trim().parse().ok())
            .unwrap_or_else(|| panic!("no {prefix:?} in the benchmark's output:\n{text}"))
    };
    let rate = number_after("s = ", "round trips/s");
    let p99 = number_after("p99 ", ",");
    let failed = number_after("failed calls: ", "\n") as u64;
    (rate, p99, failed)
}

/// Measures one configuration on a running robot with `pages` pages of `url` open.
fn measure(
    robot: &Launched,
    link: &PathBuf,
    python: &PathBuf,
    browser: &mut Chromium,
    url: Option<&str>,
    pages: usize,
    calls: u32,
) -> Measured {
    let mut opened: Vec<Page> = Vec::new();
    if let Some(url) = url {
        for _ in 0..pages {
            let page = browser.open(url, 1000, 640).expect("open the view");
            view_page::wait_until_drawn(browser, &page);
            opened.push(page);
        }
    }
    thread::sleep(SETTLE);
    let received = |browser: &mut Chromium| -> f64 {
        opened
            .iter()
            .filter_map(|p| browser.evaluate(p, view_page::RECEIVED).ok()?.as_f64())
            .sum()
    };
    let messages_before = received(browser);
    let ticks_before = cpu_ticks(robot.child.id());
    let start = Instant::now();
    let (rate_per_s, p99_ms, failed) = get_angles(python, link, calls);
    let elapsed = start.elapsed().as_secs_f64();
    let ticks = cpu_ticks(robot.child.id()) - ticks_before;
    let messages = received(browser) - messages_before;
    for page in &opened {
        let _ = browser.close(page);
    }
    Measured {
        rate_per_s,
        p99_ms,
        failed,
        messages_per_s: messages / elapsed / opened.len().max(1) as f64,
        robot_cpu_percent: 100.0 * ticks as f64 / TICKS_PER_S / elapsed,
    }
}

fn main() {
    let options = options();
    let python = venv::python();
    let setups = [
        Setup::Off,
        Setup::Pages(0),
        Setup::Pages(1),
        Setup::Pages(options.pages),
    ];
    let mut browser = Chromium::launch(scratch("profile")).unwrap_or_else(|e| panic!("{e}"));
    let mut results: Vec<(Setup, Vec<Measured>)> =
        setups.iter().map(|&s| (s, Vec::new())).collect();

    for round in 1..=options.rounds {
        for (setup, runs) in &mut results {
            let link = scratch("link");
            let _ = std::fs::remove_file(&link);
            let link_arg = link.to_str().expect("UTF-8 path").to_string();
            let mut args = vec!["--pty-link", link_arg.as_str()];
            let pages = match setup {
                Setup::Off => {
                    args.push("--no-web");
                    0
                }
                Setup::Pages(n) => {
                    args.extend(["--web", "127.0.0.1:0"]);
                    *n
                }
            };
            let robot = launch(&args);
            let url = robot.banner_value("view on ").map(str::to_string);
            let measured = measure(
                &robot,
                &link,
                &python,
                &mut browser,
                url.as_deref(),
                pages,
                options.calls,
            );
            println!(
                "round {round}: {:<22} {:>5.0} get_angles/s  p99 {:>5.2} ms  failed {}  \
                 {:>4.1} state msgs/s per page  robot CPU {:>4.1} %",
                setup.label(),
                measured.rate_per_s,
                measured.p99_ms,
                measured.failed,
                measured.messages_per_s,
                measured.robot_cpu_percent
            );
            runs.push(measured);
        }
    }

    let mean = |runs: &[Measured], f: fn(&Measured) -> f64| {
        runs.iter().map(f).sum::<f64>() / runs.len().max(1) as f64
    };
    let baseline = results
        .first()
        .map_or(0.0, |(_, runs)| mean(runs, |m| m.rate_per_s));
    println!(
        "\nmean over {} rounds of {} calls:",
        options.rounds, options.calls
    );
    for (setup, runs) in &results {
        let rate = mean(runs, |m| m.rate_per_s);
        println!(
            "  {:<22} {:>5.0} get_angles/s ({:+.1} % vs view off), {:>4.1} state msgs/s per \
             page, robot CPU {:>4.1} %",
            setup.label(),
            rate,
            100.0 * (rate / baseline - 1.0),
            mean(runs, |m| m.messages_per_s),
            mean(runs, |m| m.robot_cpu_percent)
        );
    }
}
