//! The Python that runs pymycobot 4.0.7 for the end-to-end tests and benches (included with
//! `#[path]`, also by protocol-core's reply test).
//!
//! It is `$MYCOBOT_PYTHON`, else the workspace's `.venv/bin/python`. On a fresh clone the
//! first test that needs it creates the venv (`python3 -m venv .venv`) and installs the client
//! (`pip install pymycobot==4.0.7`, from PyPI), under a file lock so parallel test binaries do
//! not race.
//!
//! A person running `cargo test` sees this happen: the steps are announced and pip's own
//! output (with its progress bars, in a terminal) is shown as it runs. The test harness
//! captures only `print!`/`eprint!`, so the announcements are written to stderr directly and
//! pip inherits the terminal. If the setup fails (no `python3`, no venv module, PyPI out of
//! reach), the test binary prints one message saying what failed and what to do, and exits
//! with status 1 at once: cargo then stops with that binary, instead of every test that needs
//! the client failing in turn.

// Included by several test crates, each using a part of it.
#![allow(dead_code)]

use std::fs::File;
use std::io::Write;
use std::path::{Path, PathBuf};
use std::process::{Command, ExitStatus, Stdio};

/// The client the tests drive the robot with, as pip names it.
pub const PYMYCOBOT: &str = "pymycobot==4.0.7";

/// The workspace root: the nearest directory above this package that holds `Cargo.lock`.
pub fn workspace() -> PathBuf {
    let manifest = Path::new(env!("CARGO_MANIFEST_DIR"));
    manifest
        .ancestors()
        .find(|dir| dir.join("Cargo.lock").is_file())
        .unwrap_or(manifest)
        .to_path_buf()
}

/// The Python to run pymycobot with; sets up the workspace venv if needed. Exits the test
/// binary with a message if that fails (see the [module doc](self)).
pub fn python() -> PathBuf {
    if let Some(explicit) = std::env::var_os("MYCOBOT_PYTHON") {
        return PathBuf::from(explicit);
    }
    let lock = File::create(Path::new(env!("CARGO_TARGET_TMPDIR")).join("venv.lock"))
        .and_then(|lock| lock.lock().map(|()| lock));
    let venv = workspace().join(".venv");
    let result = lock
        .map_err(|e| {
            format!(
                "cannot take the venv lock in {}: {e}",
                env!("CARGO_TARGET_TMPDIR")
            )
        })
        .and_then(|_lock| set_up(&venv, &[], Shown::Yes));
    match result {
        Ok(python) => python,
        Err(why) => {
            say("error: the end-to-end tests cannot run.");
            for line in why.lines() {
                let _ = writeln!(std::io::stderr(), "  {line}");
            }
            let _ = writeln!(
                std::io::stderr(),
                "  Or set MYCOBOT_PYTHON to a Python that has {PYMYCOBOT}."
            );
            std::process::exit(1);
        }
    }
}

/// Whether [`set_up`] shows what it does on the terminal.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Shown {
    /// Announce each step and let python and pip write to the terminal.
    Yes,
    /// Say nothing; a failed step's output goes into the error.
    No,
}

/// Makes `venv` a venv with pymycobot 4.0.7, creating it and installing the client if needed
/// (`pip_options` are added to pip's command line). Returns its Python, or why it could not.
pub fn set_up(venv: &Path, pip_options: &[&str], shown: Shown) -> Result<PathBuf, String> {
    let python = venv.join("bin/python");
    if has_client(&python) {
        return Ok(python);
    }
    if !python.exists() {
        if shown == Shown::Yes {
            say(&format!(
                "first run: creating the Python venv {} for the end-to-end tests",
                venv.display()
            ));
        }
        let (status, output) = run(
            Command::new("python3").args(["-m", "venv"]).arg(venv),
            shown,
        )
        .map_err(|e| format!("cannot run python3 ({e}).\nInstall Python 3."))?;
        if !status.success() {
            return Err(format!(
                "`python3 -m venv {}` failed ({status}{output}).\n\
                 On Debian or Ubuntu install python3-venv.",
                venv.display()
            ));
        }
    }
    if shown == Shown::Yes {
        say(&format!(
            "installing {PYMYCOBOT} from PyPI into {} (once; pip's output follows)",
            venv.display()
        ));
    }
    let (status, output) = run(
        Command::new(&python)
            .args(["-m", "pip", "install", "--disable-pip-version-check"])
            .args(pip_options)
            .arg(PYMYCOBOT),
        shown,
    )
    .map_err(|e| format!("cannot run {} ({e})", python.display()))?;
    if !status.success() {
        return Err(format!(
            "pip could not install {PYMYCOBOT} into {} ({status}{output}).\n\
             Is PyPI reachable from this machine? Behind a proxy set HTTPS_PROXY, for a mirror \
             PIP_INDEX_URL; then run the tests again.",
            venv.display()
        ));
    }
    if !has_client(&python) {
        return Err(format!(
            "{PYMYCOBOT} is still not importable by {} after installing it.",
            python.display()
        ));
    }
    if shown == Shown::Yes {
        say(&format!("{PYMYCOBOT} is installed; the tests go on"));
    }
    Ok(python)
}

/// True if `python` imports pymycobot 4.0.7 and pyserial.
fn has_client(python: &Path) -> bool {
    python.exists()
        && Command::new(python)
            .args([
                "-c",
                "import pymycobot, serial; assert pymycobot.__version__ == '4.0.7'",
            ])
            .stdout(Stdio::null())
            .stderr(Stdio::null())
            .status()
            .is_ok_and(|s| s.success())
}

/// Runs `command`. Shown: with the terminal as its stdout and stderr, so a person watching
/// sees its output as it comes (the test harness does not capture a child's output); the
/// text returned is "; its output is above". Not shown: its output is returned, after "; ".
fn run(command: &mut Command, shown: Shown) -> std::io::Result<(ExitStatus, String)> {
    command.stdin(Stdio::null());
    if shown == Shown::Yes {
        let status = command
            .stdout(Stdio::inherit())
            .stderr(Stdio::inherit())
            .status()?;
        return Ok((status, "; its output is above".into()));
    }
    let output = command.output()?;
    let text = format!(
        "; it said:\n{}{}",
        String::from_utf8_lossy(&output.stdout),
        String::from_utf8_lossy(&output.stderr)
    );
    Ok((output.status, text))
}

/// Tells the person running the tests, past the harness's capture of `eprintln!`.
fn say(line: &str) {
    let _ = writeln!(std::io::stderr(), "open-mycobot e2e: {line}");
}

/// Runs `command`; panics with its output if it fails. Returns its standard output.
pub fn run_checked(command: &mut Command) -> String {
    let output = command
        .output()
        .unwrap_or_else(|e| panic!("cannot run {command:?}: {e}"));
    assert!(
        output.status.success(),
        "{command:?} failed:\n{}{}",
        String::from_utf8_lossy(&output.stdout),
        String::from_utf8_lossy(&output.stderr)
    );
    String::from_utf8_lossy(&output.stdout).into_owned()
}
