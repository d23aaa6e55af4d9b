//! The teach-and-play image's screen text (`render_teach`): the program's status, what the
//! buttons do, and the transponder's rows about the Atom. Pure logic, tested on the host
//! (`cargo test -p firmware-basic --test board_logic`).

use core::fmt::{self, Write};

use firmware_basic::BasicStatus;
use firmware_basic::teach::{Activity, SAMPLE_PERIOD_US, TeachStatus};

use crate::screen_text::{
    BoardStatus, COLS, ERROR_ROW, LOOP_ROW, Line, ROWS, TITLE_ROW, Text, write_row,
};

/// The screen text of the teach-and-play image (`basic-teach`): the program's `teach` status,
/// the buttons' meaning, and the transponder's rows about the Atom.
pub fn render_teach(teach: &TeachStatus, status: &BasicStatus, board: &BoardStatus) -> Text {
    let mut text = [[b' '; COLS]; ROWS];
    for (row, cells) in text.iter_mut().enumerate() {
        let mut line = Line::default();
        let _ = match row {
            TITLE_ROW => write!(
                line,
                "open myCobot teach  v{}.{}",
                status.version_x10 / 10,
                status.version_x10 % 10
            ),
            LOOP_ROW => write!(line, "loop max  {} us", board.loop_max_us),
            2 => write!(line, "A record  B play  C stop"),
            4 => write_activity(&mut line, teach),
            5 => write!(
                line,
                "record    {} points, {}.{} s",
                teach.points,
                u64::from(teach.points) * SAMPLE_PERIOD_US / 1_000_000,
                u64::from(teach.points) * SAMPLE_PERIOD_US / 100_000 % 10
            ),
            6 => write!(line, "played    {} times", teach.plays),
            7 | 8 => write_row(&mut line, row - 4, status),
            9 => write!(line, "protocol  {}", status.dialect.name()),
            ERROR_ROW => match teach.error {
                Some(error) => write!(line, "{error}"),
                None => write_row(&mut line, ERROR_ROW, status),
            },
            _ => Ok(()),
        };
        *cells = line.cells;
    }
    text
}

/// What the teach program is doing, in words.
fn write_activity(out: &mut Line, teach: &TeachStatus) -> fmt::Result {
    match teach.activity {
        Activity::Idle if teach.points == 0 => write!(out, "now       move by hand after A"),
        Activity::Idle => write!(out, "now       ready"),
        Activity::Recording => write!(out, "now       RECORDING"),
        Activity::Approaching => write!(out, "now       to the first point"),
        Activity::Playing => write!(out, "now       PLAYING {}/{}", teach.played, teach.points),
        Activity::Settling => write!(out, "now       to the last point"),
        Activity::Stopping => write!(out, "now       stopping"),
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn row_text(text: &Text, row: usize) -> &str {
        core::str::from_utf8(&text[row]).unwrap().trim_end()
    }

    #[test]
    fn the_teach_screen_says_what_the_program_does_and_what_the_buttons_do() {
        let teach = TeachStatus {
            activity: Activity::Playing,
            points: 81,
            played: 12,
            plays: 2,
            error: None,
        };
        let text = render_teach(&teach, &BasicStatus::default(), &BoardStatus::default());
        assert_eq!(row_text(&text, 2), "A record  B play  C stop");
        assert_eq!(row_text(&text, 4), "now       PLAYING 12/81");
        assert_eq!(row_text(&text, 5), "record    81 points, 4.0 s");
        assert_eq!(row_text(&text, 6), "played    2 times");
        let failed = TeachStatus {
            activity: Activity::Idle,
            error: Some(mycobot_api::Error::Timeout { cmd: 0x20 }),
            ..teach
        };
        let text = render_teach(&failed, &BasicStatus::default(), &BoardStatus::default());
        assert_eq!(row_text(&text, 4), "now       ready");
        assert_eq!(
            row_text(&text, ERROR_ROW),
            "no reply to command 0x20 in time"
        );
    }
}
