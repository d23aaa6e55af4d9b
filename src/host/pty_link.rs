//! A stable name for the pseudo-terminal (`--pty-link /tmp/mycobot`), so scripts need not
//! parse which `/dev/pts/N` the kernel handed out this time.

use std::fs;
use std::io;
use std::os::unix::fs::symlink;
use std::path::{Path, PathBuf};

/// A symbolic link to the pseudo-terminal; removed again when dropped.
#[derive(Debug)]
pub struct PtyLink {
    link: PathBuf,
    target: PathBuf,
}

impl PtyLink {
    /// Points `link` at `target`. A symlink already at `link` (left by a run that was killed)
    /// is replaced; any other file there is left alone and reported as an error, so a typo
    /// cannot delete a user's file.
    pub fn create(link: &Path, target: &Path) -> io::Result<Self> {
        match fs::symlink_metadata(link) {
            Ok(meta) if meta.file_type().is_symlink() => fs::remove_file(link)?,
            Ok(_) => {
                return Err(io::Error::new(
                    io::ErrorKind::AlreadyExists,
                    format!(
                        "{} exists and is not a symlink; not replacing it",
                        link.display()
                    ),
                ));
            }
            Err(e) if e.kind() == io::ErrorKind::NotFound => {}
            Err(e) => return Err(e),
        }
        symlink(target, link)?;
        Ok(Self {
            link: link.to_path_buf(),
            target: target.to_path_buf(),
        })
    }

    /// Where the link is.
    pub fn path(&self) -> &Path {
        &self.link
    }
}

impl Drop for PtyLink {
    fn drop(&mut self) {
        // Remove it only if it is still ours: another instance may have taken the name over.
        if fs::read_link(&self.link).is_ok_and(|points_to| points_to == self.target) {
            let _ = fs::remove_file(&self.link);
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn scratch_dir(name: &str) -> PathBuf {
        let dir = std::env::temp_dir().join(format!("pty-link-{}-{name}", std::process::id()));
        let _ = fs::remove_dir_all(&dir);
        fs::create_dir_all(&dir).unwrap();
        dir
    }

    #[test]
    fn replaces_a_stale_link_and_removes_it_on_drop() {
        let dir = scratch_dir("stale");
        let link = dir.join("robot");
        symlink("/dev/pts/does-not-exist", &link).unwrap();
        let guard = PtyLink::create(&link, Path::new("/dev/null")).unwrap();
        assert_eq!(fs::read_link(&link).unwrap(), Path::new("/dev/null"));
        drop(guard);
        assert!(fs::symlink_metadata(&link).is_err());
        fs::remove_dir_all(dir).unwrap();
    }

    #[test]
    fn refuses_to_replace_a_regular_file() {
        let dir = scratch_dir("file");
        let link = dir.join("notes.txt");
        fs::write(&link, "keep me").unwrap();
        assert!(PtyLink::create(&link, Path::new("/dev/null")).is_err());
        assert_eq!(fs::read_to_string(&link).unwrap(), "keep me");
        fs::remove_dir_all(dir).unwrap();
    }
}
