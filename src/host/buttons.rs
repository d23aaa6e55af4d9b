//! The Basic's front buttons pressed from outside the virtual robot: the keys a, b and c on its
//! standard input ([`read_keys`]) and the 3D view's buttons (`POST /button/a`) push presses
//! into one [`PressQueue`]; the real-time loop's [`Presser`] takes them one at a time and holds
//! each button down for [`PRESS_US`] of virtual time, as a finger does.
//!
//! Only a Basic that runs a program (`--basic-program`) is given presses: its buttons are the
//! program's. The shipped Basic's own uses of them (A powers on, C held changes the dialect)
//! are left to the library (`VirtualRobot::basic_io_mut`).

use std::collections::VecDeque;
use std::io::{self, Read};
use std::sync::{Arc, Mutex, PoisonError};
use std::thread;
use std::time::Duration;

use firmware_basic::Buttons;

/// How long a press holds its button down, virtual microseconds.
pub const PRESS_US: u64 = 150_000;

/// How long the buttons stay up between two presses, virtual microseconds: the program sees
/// each press as a button going down.
pub const RELEASE_US: u64 = 50_000;

/// Most presses waiting at once; more are dropped (a key held down, a pasted text, a flood of
/// clicks), as a finger cannot press faster than the buttons are read either.
pub const MAX_PENDING: usize = 16;

/// How long the key reader waits before reading again when its terminal is not its own (the
/// robot runs in the background of a shell; `fg` gives the terminal back).
const BACKGROUND_RETRY: Duration = Duration::from_millis(250);

/// One of the Basic's three front buttons.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Button {
    /// The left button.
    A,
    /// The middle button.
    B,
    /// The right button.
    C,
}

impl Button {
    /// The button a key or a letter names: a, b or c in either case.
    pub fn from_letter(letter: char) -> Option<Self> {
        match letter.to_ascii_lowercase() {
            'a' => Some(Self::A),
            'b' => Some(Self::B),
            'c' => Some(Self::C),
            _ => None,
        }
    }

    /// `buttons` with this one held down.
    fn held(self) -> Buttons {
        Buttons {
            a: self == Self::A,
            b: self == Self::B,
            c: self == Self::C,
        }
    }
}

/// Presses waiting for the real-time loop, shared by whoever presses (clones share the queue).
#[derive(Clone, Debug, Default)]
pub struct PressQueue {
    pending: Arc<Mutex<VecDeque<Button>>>,
}

impl PressQueue {
    /// An empty queue.
    pub fn new() -> Self {
        Self::default()
    }

    /// Queues a press of `button`; `false` if [`MAX_PENDING`] presses already wait (then it is
    /// dropped).
    pub fn push(&self, button: Button) -> bool {
        let mut pending = self.pending.lock().unwrap_or_else(PoisonError::into_inner);
        if pending.len() >= MAX_PENDING {
            return false;
        }
        pending.push_back(button);
        true
    }

    /// Takes the oldest press waiting, if any.
    fn pop(&self) -> Option<Button> {
        self.pending
            .lock()
            .unwrap_or_else(PoisonError::into_inner)
            .pop_front()
    }
}

/// Turns queued presses into the buttons' levels over virtual time: one press at a time, each
/// held [`PRESS_US`], then all buttons up for [`RELEASE_US`] before the next.
#[derive(Debug)]
pub struct Presser {
    queue: PressQueue,
    /// The button held and when it is let go, or when the next press may start.
    state: PressState,
}

#[derive(Clone, Copy, Debug)]
enum PressState {
    /// Nothing under way from this time on.
    Free { from_us: u64 },
    /// `button` held until `until_us`.
    Holding { button: Button, until_us: u64 },
}

impl Presser {
    /// Takes its presses from `queue`.
    pub fn new(queue: PressQueue) -> Self {
        Self {
            queue,
            state: PressState::Free { from_us: 0 },
        }
    }

    /// At virtual time `now_us`, sets `buttons` for the press under way: lets a held button go
    /// when its time is up, starts the next queued press when the buttons have been up long
    /// enough. Called on every pass of the loop, after virtual time has advanced.
    pub fn apply(&mut self, now_us: u64, buttons: &mut Buttons) {
        if let PressState::Holding { until_us, .. } = self.state
            && now_us >= until_us
        {
            *buttons = Buttons::default();
            self.state = PressState::Free {
                from_us: now_us.saturating_add(RELEASE_US),
            };
        }
        if let PressState::Free { from_us } = self.state
            && now_us >= from_us
            && let Some(button) = self.queue.pop()
        {
            *buttons = button.held();
            self.state = PressState::Holding {
                button,
                until_us: now_us.saturating_add(PRESS_US),
            };
        }
    }

    /// The button held down now, if any.
    pub fn holding(&self) -> Option<Button> {
        match self.state {
            PressState::Holding { button, .. } => Some(button),
            PressState::Free { .. } => None,
        }
    }
}

/// Reads `input` until its end, queueing a press for every a, b or c (either case); anything
/// else (other characters, whitespace, line ends) is ignored. A read the terminal refuses
/// because the robot runs in a shell's background (`EIO` with `SIGTTIN` blocked) is tried
/// again a little later; any other error ends the reading, as the end does.
pub fn read_keys(mut input: impl Read, queue: &PressQueue) {
    let mut buf = [0u8; 256];
    loop {
        match input.read(&mut buf) {
            Ok(0) => return,
            Ok(n) => {
                for &byte in buf.get(..n).unwrap_or_default() {
                    if let Some(button) = Button::from_letter(char::from(byte)) {
                        queue.push(button);
                    }
                }
            }
            Err(e) if e.kind() == io::ErrorKind::Interrupted => {}
            Err(e) if e.raw_os_error() == Some(nix::libc::EIO) => thread::sleep(BACKGROUND_RETRY),
            Err(_) => return,
        }
    }
}

/// Reads the robot's standard input in a thread of its own ([`read_keys`]), so the keys a, b
/// and c press the Basic's buttons. The thread blocks `SIGTTIN` first: a robot started in a
/// shell's background is not stopped for reading the terminal, its reads fail (and are tried
/// again) until it is brought to the foreground. The end of the input ends the thread, never
/// the robot.
pub fn spawn_key_reader(queue: PressQueue) -> io::Result<()> {
    use nix::sys::signal::{SigSet, SigmaskHow, Signal, pthread_sigmask};
    thread::Builder::new().name("keys".into()).spawn(move || {
        let ttin = SigSet::from(Signal::SIGTTIN);
        if pthread_sigmask(SigmaskHow::SIG_BLOCK, Some(&ttin), None).is_ok() {
            read_keys(io::stdin().lock(), &queue);
        }
    })?;
    Ok(())
}

#[cfg(test)]
mod tests {
    #![allow(clippy::unwrap_used, clippy::expect_used, clippy::indexing_slicing)]

    use super::*;

    /// Runs `presser` from `from_us` to `to_us` in 1 ms passes; the buttons at every pass.
    fn run(presser: &mut Presser, buttons: &mut Buttons, from_us: u64, to_us: u64) -> Vec<Buttons> {
        (from_us..to_us)
            .step_by(1_000)
            .map(|t| {
                presser.apply(t, buttons);
                *buttons
            })
            .collect()
    }

    #[test]
    fn letters_name_buttons_in_either_case_and_nothing_else_does() {
        assert_eq!(Button::from_letter('a'), Some(Button::A));
        assert_eq!(Button::from_letter('B'), Some(Button::B));
        assert_eq!(Button::from_letter('c'), Some(Button::C));
        for other in ['d', ' ', '\n', '1', 'é'] {
            assert_eq!(Button::from_letter(other), None);
        }
    }

    #[test]
    fn keys_queue_presses_and_the_rest_of_the_input_is_ignored() {
        let queue = PressQueue::new();
        read_keys(&b"a\nxB c\r\n?\tz"[..], &queue);
        let presses: Vec<_> = std::iter::from_fn(|| queue.pop()).collect();
        assert_eq!(presses, [Button::A, Button::B, Button::C]);
    }

    #[test]
    fn a_flood_of_presses_is_capped() {
        let queue = PressQueue::new();
        read_keys(&[b'a'; 100][..], &queue);
        assert_eq!(std::iter::from_fn(|| queue.pop()).count(), MAX_PENDING);
        assert!(queue.push(Button::A), "room again once taken");
    }

    #[test]
    fn a_press_holds_its_button_150_ms_then_the_next_follows_a_release_later() {
        let queue = PressQueue::new();
        let mut presser = Presser::new(queue.clone());
        let mut buttons = Buttons::default();
        assert!(
            run(&mut presser, &mut buttons, 0, 10_000)
                .iter()
                .all(|b| *b == Buttons::default())
        );

        queue.push(Button::A);
        queue.push(Button::C);
        let seen = run(&mut presser, &mut buttons, 10_000, 600_000);
        let a = Button::A.held();
        let c = Button::C.held();
        // A from 10 ms to 160 ms, up until 210 ms, C from 210 ms to 360 ms, then up.
        let at = |t_us: u64| seen[((t_us - 10_000) / 1_000) as usize];
        assert_eq!(at(10_000), a);
        assert_eq!(at(159_000), a);
        assert_eq!(at(160_000), Buttons::default());
        assert_eq!(at(209_000), Buttons::default());
        assert_eq!(at(210_000), c);
        assert_eq!(at(359_000), c);
        assert_eq!(at(360_000), Buttons::default());
        assert_eq!(*seen.last().unwrap(), Buttons::default());
        assert_eq!(seen.iter().filter(|b| **b == a).count(), 150);
        assert_eq!(presser.holding(), None);
    }

    #[test]
    fn a_press_spans_long_passes_and_is_never_shorter_than_the_loop_sees() {
        let queue = PressQueue::new();
        let mut presser = Presser::new(queue.clone());
        let mut buttons = Buttons::default();
        queue.push(Button::B);
        presser.apply(1_000, &mut buttons);
        assert!(buttons.b && presser.holding() == Some(Button::B));
        // The loop idles 5 ms per pass: still held at 150 ms, let go at the first pass after.
        presser.apply(150_999, &mut buttons);
        assert!(buttons.b);
        presser.apply(155_000, &mut buttons);
        assert_eq!(buttons, Buttons::default());
    }
}
