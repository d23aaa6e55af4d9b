//! The Python that runs pymycobot 4.0.7 for the end-to-end tests and benches (included with
//! `#[path]`).
//!
//! It is `$MYCOBOT_PYTHON`, else the workspace's `.venv/bin/python`; on a fresh clone the venv
//! is created (`python3 -m venv .venv && pip install pymycobot==4.0.7`) under a file lock, so
//! parallel test binaries do not race. Nothing is skipped silently: a missing Python or a
//! failed install fails with the reason.

use std::fs::File;
use std::path::{Path, PathBuf};
use std::process::{Command, Stdio};

const PYMYCOBOT: &str = "pymycobot==4.0.7";

/// The workspace root.
pub fn workspace() -> PathBuf {
    PathBuf::from(env!("CARGO_MANIFEST_DIR"))
}

/// The Python to run pymycobot with; creates the workspace venv if needed.
pub fn python() -> PathBuf {
    if let Some(explicit) = std::env::var_os("MYCOBOT_PYTHON") {
        return PathBuf::from(explicit);
    }
    let root = workspace();
    let python = root.join(".venv/bin/python");
    let lock = File::create(Path::new(env!("CARGO_TARGET_TMPDIR")).join("venv.lock"))
        .expect("create the venv lock file");
    lock.lock().expect("lock the venv lock file");
    if !imports_pymycobot(&python) {
        if !python.exists() {
            run_checked(
                Command::new("python3")
                    .args(["-m", "venv"])
                    .arg(root.join(".venv")),
            );
        }
        run_checked(
            Command::new(root.join(".venv/bin/pip")).args(["install", "--quiet", PYMYCOBOT]),
        );
        assert!(
            imports_pymycobot(&python),
            "pymycobot still not importable after installing it into {}",
            python.display()
        );
    }
    python
}

fn imports_pymycobot(python: &Path) -> bool {
    Command::new(python)
        .args(["-c", "import pymycobot, serial"])
        .stdout(Stdio::null())
        .stderr(Stdio::null())
        .status()
        .is_ok_and(|s| s.success())
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
