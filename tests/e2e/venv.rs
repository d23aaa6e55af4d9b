//! The Python that runs pymycobot for the end-to-end tests and benches (included with
//! `#[path]`, also by protocol-core's reply test): 4.0.7, the reference client, for nearly all
//! of them, and 2.9.8 for the seed dialect's suite ([`Client`]).
//!
//! It is `$MYCOBOT_PYTHON`, else the workspace's `.venv/bin/python` (2.9.8:
//! `$MYCOBOT_PYTHON_298`, else `.venv-298/bin/python`). On a fresh clone the first test that
//! needs it creates the venv (`python3 -m venv .venv`) and installs the client (`pip install
//! pymycobot==4.0.7`, from PyPI), under a file lock so parallel test binaries do not race.
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

/// A pymycobot release the tests drive the robot with, each in a venv of its own.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Client {
    /// pymycobot 4.0.7 (`MyCobot280`), the reference client: the end-to-end suite.
    V407,
    /// pymycobot 2.9.8 (`MyCobot`), which reads no reply to a set command: the seed dialect's
    /// suite. On Linux its package imports OpenCV (`pymycobot/__init__.py` imports its
    /// MyBuddy emoticon player), so `from pymycobot.mycobot import MyCobot` needs `cv2`: the
    /// headless wheel (with numpy) is installed beside it, unpinned, as only its import counts.
    V298,
}

impl Client {
    /// The release, as `pymycobot.__version__` says it.
    const fn version(self) -> &'static str {
        match self {
            Self::V407 => "4.0.7",
            Self::V298 => "2.9.8",
        }
    }

    /// What pip installs, the client first.
    const fn packages(self) -> &'static [&'static str] {
        match self {
            Self::V407 => &["pymycobot==4.0.7"],
            Self::V298 => &["pymycobot==2.9.8", "opencv-python-headless"],
        }
    }

    /// Its venv, in the workspace.
    const fn venv(self) -> &'static str {
        match self {
            Self::V407 => ".venv",
            Self::V298 => ".venv-298",
        }
    }

    /// The environment variable that names a Python to use instead of the venv's.
    const fn python_var(self) -> &'static str {
        match self {
            Self::V407 => "MYCOBOT_PYTHON",
            Self::V298 => "MYCOBOT_PYTHON_298",
        }
    }

    /// The packages, as a person reads them: "pymycobot==2.9.8 and opencv-python-headless".
    fn named(self) -> String {
        self.packages().join(" and ")
    }
}

/// The workspace root: the nearest directory above this package that holds `Cargo.lock`.
pub fn workspace() -> PathBuf {
    let manifest = Path::new(env!("CARGO_MANIFEST_DIR"));
    manifest
        .ancestors()
        .find(|dir| dir.join("Cargo.lock").is_file())
        .unwrap_or(manifest)
        .to_path_buf()
}

/// The Python to run pymycobot 4.0.7 with: [`python_for`] the reference client.
pub fn python() -> PathBuf {
    python_for(Client::V407)
}

/// The Python to run `client` with; sets up its workspace venv if needed. Exits the test
/// binary with a message if that fails (see the [module doc](self)).
pub fn python_for(client: Client) -> PathBuf {
    if let Some(explicit) = std::env::var_os(client.python_var()) {
        return PathBuf::from(explicit);
    }
    // venv.lock for .venv, venv-298.lock for .venv-298.
    let lock_name = format!("{}.lock", client.venv().trim_start_matches('.'));
    let lock = File::create(Path::new(env!("CARGO_TARGET_TMPDIR")).join(lock_name))
        .and_then(|lock| lock.lock().map(|()| lock));
    let venv = workspace().join(client.venv());
    let result = lock
        .map_err(|e| {
            format!(
                "cannot take the venv lock in {}: {e}",
                env!("CARGO_TARGET_TMPDIR")
            )
        })
        .and_then(|_lock| set_up_for(client, &venv, &[], Shown::Yes));
    match result {
        Ok(python) => python,
        Err(why) => {
            say("error: the end-to-end tests cannot run.");
            for line in why.lines() {
                let _ = writeln!(std::io::stderr(), "  {line}");
            }
            let _ = writeln!(
                std::io::stderr(),
                "  Or set {} to a Python that has {}.",
                client.python_var(),
                client.named()
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

/// Makes `venv` a venv with pymycobot 4.0.7: [`set_up_for`] the reference client.
pub fn set_up(venv: &Path, pip_options: &[&str], shown: Shown) -> Result<PathBuf, String> {
    set_up_for(Client::V407, venv, pip_options, shown)
}

/// Makes `venv` a venv with `client`, creating it and installing the client if needed
/// (`pip_options` are added to pip's command line). Returns its Python, or why it could not.
pub fn set_up_for(
    client: Client,
    venv: &Path,
    pip_options: &[&str],
    shown: Shown,
) -> Result<PathBuf, String> {
    let python = venv.join("bin/python");
    let packages = client.named();
    if has_client(&python, client) {
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
            "installing {packages} from PyPI into {} (once; pip's output follows)",
            venv.display()
        ));
    }
    let (status, output) = run(
        Command::new(&python)
            .args(["-m", "pip", "install", "--disable-pip-version-check"])
            .args(pip_options)
            .args(client.packages()),
        shown,
    )
    .map_err(|e| format!("cannot run {} ({e})", python.display()))?;
    if !status.success() {
        return Err(format!(
            "pip could not install {packages} into {} ({status}{output}).\n\
             Is PyPI reachable from this machine? Behind a proxy set HTTPS_PROXY, for a mirror \
             PIP_INDEX_URL; then run the tests again.",
            venv.display()
        ));
    }
    if !has_client(&python, client) {
        return Err(format!(
            "pymycobot {} is still not importable by {} after installing {packages}.",
            client.version(),
            python.display()
        ));
    }
    if shown == Shown::Yes {
        say(&format!("installed {packages}; the tests go on"));
    }
    Ok(python)
}

/// True if `python` imports `client`'s pymycobot (and so what its package imports) and pyserial.
fn has_client(python: &Path, client: Client) -> bool {
    let check = format!(
        "import pymycobot, serial; assert pymycobot.__version__ == '{}'",
        client.version()
    );
    python.exists()
        && Command::new(python)
            .args(["-c", &check])
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
