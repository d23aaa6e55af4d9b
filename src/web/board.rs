//! Where the simulation loop leaves the latest [`Snapshot`] and the web threads pick it up.
//!
//! The loop must never wait for the web: [`StateBoard::publish`] only tries the lock and, if a
//! reader holds it this instant (for the copy of a few dozen bytes), skips this snapshot; the
//! next one follows a frame later. Readers wait on a condition variable for a snapshot newer
//! than the one they sent, so each connection sends every snapshot at most once.

use std::sync::{Condvar, Mutex, MutexGuard, TryLockError};
use std::time::Duration;

use super::snapshot::Snapshot;

/// The latest snapshot and its sequence number (0 = none yet).
#[derive(Debug, Default)]
struct Latest {
    seq: u64,
    snapshot: Option<Snapshot>,
}

/// One writer (the simulation loop), any number of readers (one per open page).
#[derive(Debug, Default)]
pub struct StateBoard {
    latest: Mutex<Latest>,
    fresh: Condvar,
}

impl StateBoard {
    /// An empty board.
    pub fn new() -> Self {
        Self::default()
    }

    /// Leaves `snapshot` for the readers without ever blocking; `false` if a reader held the
    /// board this instant and the snapshot was dropped.
    pub fn publish(&self, snapshot: Snapshot) -> bool {
        let mut latest = match self.latest.try_lock() {
            Ok(latest) => latest,
            Err(TryLockError::Poisoned(poisoned)) => poisoned.into_inner(),
            Err(TryLockError::WouldBlock) => return false,
        };
        latest.seq += 1;
        latest.snapshot = Some(snapshot);
        drop(latest);
        self.fresh.notify_all();
        true
    }

    /// The latest snapshot and its sequence number, if one was published after `seen`;
    /// otherwise waits up to `timeout` for one.
    pub fn newer_than(&self, seen: u64, timeout: Duration) -> Option<(u64, Snapshot)> {
        let latest = self.lock();
        let (latest, _) = self
            .fresh
            .wait_timeout_while(latest, timeout, |l| l.seq <= seen)
            .unwrap_or_else(std::sync::PoisonError::into_inner);
        latest
            .snapshot
            .filter(|_| latest.seq > seen)
            .map(|s| (latest.seq, s))
    }

    fn lock(&self) -> MutexGuard<'_, Latest> {
        self.latest
            .lock()
            .unwrap_or_else(std::sync::PoisonError::into_inner)
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::sim::{RobotConfig, VirtualRobot};
    use std::sync::Arc;
    use std::thread;

    fn snapshot_at(time_us: u64) -> Snapshot {
        let mut robot = VirtualRobot::new(RobotConfig::default());
        robot.run_for(time_us);
        Snapshot::of(&robot)
    }

    #[test]
    fn a_reader_gets_each_snapshot_once_and_then_the_next() {
        let board = StateBoard::new();
        assert!(board.newer_than(0, Duration::ZERO).is_none(), "nothing yet");
        assert!(board.publish(snapshot_at(10)));
        let (seq, first) = board.newer_than(0, Duration::ZERO).expect("the first");
        assert_eq!(first.time_us, 10);
        assert!(board.newer_than(seq, Duration::from_millis(5)).is_none());
        assert!(board.publish(snapshot_at(20)));
        let (_, second) = board.newer_than(seq, Duration::ZERO).expect("the second");
        assert_eq!(second.time_us, 20);
    }

    #[test]
    fn a_waiting_reader_wakes_when_a_snapshot_is_published() {
        let board = Arc::new(StateBoard::new());
        let reader = {
            let board = Arc::clone(&board);
            thread::spawn(move || board.newer_than(0, Duration::from_secs(10)))
        };
        thread::sleep(Duration::from_millis(20));
        board.publish(snapshot_at(30));
        let got = reader.join().expect("reader");
        assert_eq!(got.map(|(_, s)| s.time_us), Some(30));
    }

    #[test]
    fn publishing_while_a_reader_holds_the_board_skips_instead_of_waiting() {
        let board = StateBoard::new();
        let held = board.lock();
        assert!(!board.publish(snapshot_at(10)), "dropped, not blocked");
        drop(held);
        assert!(board.publish(snapshot_at(10)));
    }
}
