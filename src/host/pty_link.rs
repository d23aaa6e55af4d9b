//! A stable name for the pseudo-terminal (`--pty-link /tmp/mycobot`), so scripts need not
//! parse which `/dev/pts/N` the kernel handed out this time.
//!
//! One robot per name. Beside the link, `PATH.lock` holds the pid of the robot that serves it,
//! and that robot keeps the file locked (`flock`) for as long as it runs. The kernel drops the
//! lock when the process ends, however it ends (Ctrl-C, `kill -9`, a crash), so the lock is
//! the test of life, not the pid (which may be reused) nor the pty (whose number may be):
//!
//! * the lock is held: a live robot serves the link, and a second one refuses to start
//!   ([`LinkError::Taken`]) instead of taking the name over;
//! * no lock file, or one nobody holds: whatever symlink is at the name was left by a robot
//!   that is gone, and is replaced;
//! * on exit a robot removes the link only while it still points to its own pty, and the lock
//!   file only while it is still the one it locked: a name someone else took over is left to
//!   them.

use std::fs::{self, File, OpenOptions, TryLockError};
use std::io::{self, Read, Write};
use std::os::unix::fs::{MetadataExt, symlink};
use std::path::{Path, PathBuf};

/// How often [`PtyLink::create`] tries again when the lock file it locked was removed under it
/// (its robot was just stopping): once is enough unless robots start and stop in a tight loop.
const LOCK_ATTEMPTS: usize = 8;

/// Why a link could not be made.
#[derive(Debug)]
pub enum LinkError {
    /// A running robot serves the link (it holds the lock file); `pid` as it wrote it there.
    Taken {
        /// The link asked for.
        link: PathBuf,
        /// The pid in the lock file, if it could be read.
        pid: Option<u32>,
    },
    /// Something other than a symlink is at the link's path (never replaced: a typo must not
    /// delete a user's file).
    NotASymlink(PathBuf),
    /// The link or its lock file could not be made.
    Io {
        /// The link asked for.
        link: PathBuf,
        /// What failed.
        source: io::Error,
    },
}

impl std::fmt::Display for LinkError {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        match self {
            Self::Taken { link, pid } => {
                let who = pid.map_or_else(String::new, |pid| format!(" (pid {pid})"));
                write!(
                    f,
                    "{} is served by another running virtual robot{who}; stop it, or give this \
                     one another --pty-link",
                    link.display()
                )
            }
            Self::NotASymlink(link) => write!(
                f,
                "{} exists and is not a symlink; not replacing it",
                link.display()
            ),
            Self::Io { link, source } => {
                write!(f, "cannot create the link {}: {source}", link.display())
            }
        }
    }
}

impl std::error::Error for LinkError {
    fn source(&self) -> Option<&(dyn std::error::Error + 'static)> {
        match self {
            Self::Io { source, .. } => Some(source),
            _ => None,
        }
    }
}

/// A symbolic link to the pseudo-terminal, with the lock that says a robot serves it; both
/// removed again when dropped, if still this robot's.
#[derive(Debug)]
pub struct PtyLink {
    link: PathBuf,
    target: PathBuf,
    lock_path: PathBuf,
    /// Locked while this value lives; closing it unlocks.
    lock: File,
}

impl PtyLink {
    /// Points `link` at `target`, unless a running robot serves `link` already. A symlink at
    /// `link` that no running robot holds (left by a run that was killed) is replaced; any
    /// other file there is left alone and reported.
    pub fn create(link: &Path, target: &Path) -> Result<Self, LinkError> {
        let io_error = |source| LinkError::Io {
            link: link.to_path_buf(),
            source,
        };
        let lock_path = lock_path(link);
        let mut lock = lock_file(link, &lock_path)?;
        lock.set_len(0).map_err(io_error)?;
        writeln!(lock, "{}", std::process::id()).map_err(io_error)?;
        let this = Self {
            link: link.to_path_buf(),
            target: target.to_path_buf(),
            lock_path,
            lock,
        };
        // From here on, dropping `this` on an error removes the lock file again.
        match fs::symlink_metadata(link) {
            Ok(meta) if meta.file_type().is_symlink() => fs::remove_file(link).map_err(io_error)?,
            Ok(_) => return Err(LinkError::NotASymlink(link.to_path_buf())),
            Err(e) if e.kind() == io::ErrorKind::NotFound => {}
            Err(e) => return Err(io_error(e)),
        }
        symlink(target, link).map_err(io_error)?;
        Ok(this)
    }

    /// Where the link is.
    pub fn path(&self) -> &Path {
        &self.link
    }

    /// The lock file beside it (`PATH.lock`).
    pub fn lock_path(&self) -> &Path {
        &self.lock_path
    }
}

impl Drop for PtyLink {
    fn drop(&mut self) {
        // Remove them only if they are still ours: another robot may have taken the name over
        // (if someone deleted our lock file). The link goes first, while we still hold the
        // lock, so no robot starting now can be handed a link we then delete.
        if fs::read_link(&self.link).is_ok_and(|points_to| points_to == self.target) {
            let _ = fs::remove_file(&self.link);
        }
        if same_file(&self.lock, &self.lock_path) {
            let _ = fs::remove_file(&self.lock_path);
        }
    }
}

/// `link` with `.lock` appended.
fn lock_path(link: &Path) -> PathBuf {
    let mut name = link.as_os_str().to_owned();
    name.push(".lock");
    PathBuf::from(name)
}

/// Opens (creating it if need be) and locks the lock file at `path`. A robot that stops
/// removes its lock file while holding the lock: a file locked after that is no longer at
/// `path`, so the lock is taken again on the file that is.
fn lock_file(link: &Path, path: &Path) -> Result<File, LinkError> {
    let io_error = |source| LinkError::Io {
        link: link.to_path_buf(),
        source,
    };
    for _ in 0..LOCK_ATTEMPTS {
        let mut file = OpenOptions::new()
            .read(true)
            .write(true)
            .create(true)
            .truncate(false)
            .open(path)
            .map_err(io_error)?;
        match file.try_lock() {
            Ok(()) if same_file(&file, path) => return Ok(file),
            Ok(()) => {}
            Err(TryLockError::WouldBlock) => {
                let mut pid = String::new();
                let _ = file.read_to_string(&mut pid);
                return Err(LinkError::Taken {
                    link: link.to_path_buf(),
                    pid: pid.trim().parse().ok(),
                });
            }
            Err(TryLockError::Error(e)) => return Err(io_error(e)),
        }
    }
    Err(io_error(io::Error::other(format!(
        "{} keeps being removed",
        path.display()
    ))))
}

/// True if `path` is the file `file` has open.
fn same_file(file: &File, path: &Path) -> bool {
    match (file.metadata(), fs::metadata(path)) {
        (Ok(open), Ok(named)) => open.dev() == named.dev() && open.ino() == named.ino(),
        _ => false,
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A fresh scratch directory and the path of a link in it.
    fn scratch_link(name: &str) -> (PathBuf, PathBuf) {
        let dir = std::env::temp_dir().join(format!("pty-link-{}-{name}", std::process::id()));
        let _ = fs::remove_dir_all(&dir);
        fs::create_dir_all(&dir).unwrap();
        let link = dir.join("robot");
        (dir, link)
    }

    /// Asserts that `guard`'s lock file names this process.
    fn assert_lock_names_us(guard: &PtyLink) {
        let pid = fs::read_to_string(guard.lock_path()).unwrap();
        assert_eq!(pid.trim(), std::process::id().to_string());
    }

    #[test]
    fn replaces_a_stale_link_and_removes_it_and_its_lock_on_drop() {
        let (dir, link) = scratch_link("stale");
        symlink("/dev/pts/does-not-exist", &link).unwrap();
        // A lock file nobody holds: its robot was killed.
        fs::write(lock_path(&link), "999999\n").unwrap();
        let guard = PtyLink::create(&link, Path::new("/dev/null")).unwrap();
        assert_eq!(fs::read_link(&link).unwrap(), Path::new("/dev/null"));
        assert_lock_names_us(&guard);
        drop(guard);
        assert!(fs::symlink_metadata(&link).is_err());
        assert!(fs::symlink_metadata(lock_path(&link)).is_err());
        fs::remove_dir_all(dir).unwrap();
    }

    #[test]
    fn a_held_link_is_refused_and_left_as_it_is() {
        let (dir, link) = scratch_link("held");
        let first = PtyLink::create(&link, Path::new("/dev/null")).unwrap();
        let second = PtyLink::create(&link, Path::new("/dev/zero"));
        let Err(LinkError::Taken { pid, .. }) = second else {
            panic!("a second robot took the link: {second:?}");
        };
        assert_eq!(pid, Some(std::process::id()));
        assert_eq!(fs::read_link(&link).unwrap(), Path::new("/dev/null"));
        drop(first);
        // Free again once the first is gone.
        let third = PtyLink::create(&link, Path::new("/dev/zero")).unwrap();
        assert_eq!(fs::read_link(third.path()).unwrap(), Path::new("/dev/zero"));
        drop(third);
        fs::remove_dir_all(dir).unwrap();
    }

    #[test]
    fn a_name_taken_over_is_left_to_its_new_owner() {
        let (dir, link) = scratch_link("taken-over");
        let first = PtyLink::create(&link, Path::new("/dev/null")).unwrap();
        // Someone deletes the first robot's lock file; a second robot then takes the name.
        fs::remove_file(first.lock_path()).unwrap();
        let second = PtyLink::create(&link, Path::new("/dev/zero")).unwrap();
        drop(first);
        assert_eq!(fs::read_link(&link).unwrap(), Path::new("/dev/zero"));
        assert_lock_names_us(&second);
        drop(second);
        assert!(fs::symlink_metadata(&link).is_err());
        fs::remove_dir_all(dir).unwrap();
    }

    #[test]
    fn refuses_to_replace_a_regular_file() {
        let (dir, link) = scratch_link("file");
        fs::write(&link, "keep me").unwrap();
        let refused = PtyLink::create(&link, Path::new("/dev/null"));
        assert!(matches!(refused, Err(LinkError::NotASymlink(_))));
        assert_eq!(fs::read_to_string(&link).unwrap(), "keep me");
        assert!(
            fs::symlink_metadata(lock_path(&link)).is_err(),
            "no lock file left behind"
        );
        fs::remove_dir_all(dir).unwrap();
    }
}
