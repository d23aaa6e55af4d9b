//! A pseudo-terminal that stands in for the Basic's USB serial port.
//!
//! Clients (pymycobot, `minicom`, a ROS driver) open the slave side, `/dev/pts/N`, as if it were
//! `/dev/ttyUSB0`; the robot reads and writes the master side. Two details make it behave like
//! a real USB-serial adapter instead of a terminal:
//!
//! * the line discipline is put in raw mode (no echo, no CR/LF translation, no signals) before
//!   anyone can open it, so a request is never echoed back as a fake reply;
//! * we keep a slave descriptor open ourselves for the whole run, so a client closing the port
//!   does not hang up the master (Linux then returns EIO on every master read until someone
//!   reopens it) and the next client that opens the path is served normally.

use std::fs::{File, OpenOptions};
use std::io::{self, Read, Write};
use std::os::fd::{AsFd, BorrowedFd};
use std::os::unix::fs::OpenOptionsExt;
use std::path::{Path, PathBuf};

use nix::fcntl::OFlag;
use nix::pty::{PtyMaster, grantpt, posix_openpt, ptsname_r, unlockpt};
use nix::sys::termios::{SetArg, cfmakeraw, tcgetattr, tcsetattr};

/// The master side of a raw-mode pseudo-terminal, with its slave kept open.
pub struct PseudoTerminal {
    master: PtyMaster,
    /// Held only so the line never hangs up when a client closes its end.
    _slave: File,
    slave_path: PathBuf,
}

impl PseudoTerminal {
    /// Creates the pseudo-terminal: master non-blocking, slave in raw mode and held open.
    pub fn open() -> io::Result<Self> {
        let master = posix_openpt(OFlag::O_RDWR | OFlag::O_NOCTTY | OFlag::O_NONBLOCK)?;
        grantpt(&master)?;
        unlockpt(&master)?;
        let slave_path = PathBuf::from(ptsname_r(&master)?);
        let slave = OpenOptions::new()
            .read(true)
            .write(true)
            .custom_flags(o_noctty())
            .open(&slave_path)?;
        let mut termios = tcgetattr(&slave)?;
        cfmakeraw(&mut termios);
        tcsetattr(&slave, SetArg::TCSANOW, &termios)?;
        Ok(Self {
            master,
            _slave: slave,
            slave_path,
        })
    }

    /// The path clients open, e.g. `/dev/pts/5`.
    pub fn slave_path(&self) -> &Path {
        &self.slave_path
    }

    /// Reads what clients wrote, without blocking; `Ok(0)` when nothing is waiting.
    pub fn read_available(&mut self, buf: &mut [u8]) -> io::Result<usize> {
        match self.master.read(buf) {
            Ok(n) => Ok(n),
            Err(e) if is_transient(&e) => Ok(0),
            Err(e) => Err(e),
        }
    }

    /// Queues bytes for the client without blocking. Bytes that do not fit in the kernel's
    /// buffer (nobody is reading) are dropped, as a UART drops them when nobody listens.
    /// Returns how many bytes were accepted.
    pub fn write_or_drop(&mut self, bytes: &[u8]) -> io::Result<usize> {
        let mut sent = 0;
        while let Some(rest) = bytes.get(sent..).filter(|rest| !rest.is_empty()) {
            match self.master.write(rest) {
                Ok(0) => break,
                Ok(n) => sent += n,
                Err(e) if e.kind() == io::ErrorKind::Interrupted => {}
                Err(e) if is_transient(&e) => break,
                Err(e) => return Err(e),
            }
        }
        Ok(sent)
    }
}

impl AsFd for PseudoTerminal {
    fn as_fd(&self) -> BorrowedFd<'_> {
        self.master.as_fd()
    }
}

/// `O_NOCTTY` as the raw flag `OpenOptionsExt::custom_flags` wants: opening the slave must not
/// make it our controlling terminal (a client's hang-up would then signal us).
fn o_noctty() -> i32 {
    OFlag::O_NOCTTY.bits()
}

/// "Nothing to do right now": no data, buffer full, or (on some kernels) no slave open yet.
fn is_transient(error: &io::Error) -> bool {
    matches!(
        error.kind(),
        io::ErrorKind::WouldBlock | io::ErrorKind::Interrupted
    ) || error.raw_os_error() == Some(nix::errno::Errno::EIO as i32)
}

#[cfg(test)]
mod tests {
    use super::*;
    use std::time::{Duration, Instant};

    fn read_some(pty: &mut PseudoTerminal, want: usize) -> Vec<u8> {
        let deadline = Instant::now() + Duration::from_secs(2);
        let mut got = Vec::new();
        let mut buf = [0u8; 64];
        while got.len() < want && Instant::now() < deadline {
            let n = pty.read_available(&mut buf).unwrap();
            got.extend_from_slice(&buf[..n]);
            std::thread::sleep(Duration::from_millis(1));
        }
        got
    }

    #[test]
    fn binary_bytes_pass_unchanged_both_ways_and_are_not_echoed() {
        let mut pty = PseudoTerminal::open().unwrap();
        let mut client = OpenOptions::new()
            .read(true)
            .write(true)
            .open(pty.slave_path())
            .unwrap();
        // CR, LF, ^C, ^D, XON/XOFF and 0xFE/0xFA would all be mangled by a cooked terminal.
        let request = [0xFE, 0xFE, 0x0D, 0x0A, 0x03, 0x04, 0x11, 0x13, 0xFA];
        client.write_all(&request).unwrap();
        assert_eq!(read_some(&mut pty, request.len()), request);

        let reply = [0xFE, 0xFE, 0x03, 0x0D, 0x0A, 0xFA];
        assert_eq!(pty.write_or_drop(&reply).unwrap(), reply.len());
        let mut got = [0u8; 6];
        client.read_exact(&mut got).unwrap();
        assert_eq!(got, reply);
    }

    #[test]
    fn the_next_client_is_served_after_one_closes() {
        let mut pty = PseudoTerminal::open().unwrap();
        for round in 0..3u8 {
            let mut client = OpenOptions::new()
                .read(true)
                .write(true)
                .open(pty.slave_path())
                .unwrap();
            client.write_all(&[round]).unwrap();
            assert_eq!(read_some(&mut pty, 1), [round]);
            drop(client);
            // With the client gone the master neither errors nor reports data.
            let mut buf = [0u8; 8];
            assert_eq!(pty.read_available(&mut buf).unwrap(), 0);
        }
    }
}
