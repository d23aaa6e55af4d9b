//! Why a command-line value of the virtual robot (`--obstacle`, `--late-replies`,
//! `--lost-replies`) was refused: one line naming the text, the reason and the form expected.

use std::fmt;

/// A refused command-line value, as clap prints it.
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct ArgError(String);

impl ArgError {
    /// `text` was refused for `why`; `form` is what was expected (e.g. `J:DEG`).
    pub fn new(text: &str, why: &str, form: &str) -> Self {
        Self(format!("{text:?}: {why} (expected {form})"))
    }
}

impl fmt::Display for ArgError {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.write_str(&self.0)
    }
}

impl std::error::Error for ArgError {}
