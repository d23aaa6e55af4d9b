//! The status screen's text: what each character cell shows for a [`BasicStatus`], and which
//! cells changed since they were last drawn. Pure logic, tested on the host
//! (`cargo test -p firmware-basic --test board_logic`).

use core::fmt::{self, Write};

use firmware_basic::{AtomLink, BasicError, BasicStatus, TransponderMode};

/// Text columns: 320 px / 10 px.
pub const COLS: usize = 32;
/// Text rows: 240 px / 20 px.
pub const ROWS: usize = 12;
/// The row with the firmware name and version.
pub const TITLE_ROW: usize = 0;
/// The row with the last error.
pub const ERROR_ROW: usize = 10;

/// A screenful of ASCII characters.
pub type Text = [[u8; COLS]; ROWS];

/// The screen text for `status`.
pub fn render(status: &BasicStatus) -> Text {
    let mut text = [[b' '; COLS]; ROWS];
    for (row, cells) in text.iter_mut().enumerate() {
        let mut line = Line::default();
        // `Line` never fails: what does not fit is cut off.
        let _ = write_row(&mut line, row, status);
        *cells = line.cells;
    }
    text
}

/// Writes the text of screen row `row`.
fn write_row(out: &mut Line, row: usize, s: &BasicStatus) -> fmt::Result {
    match row {
        TITLE_ROW => write!(
            out,
            "open myCobot Basic  v{}.{}",
            s.version_x10 / 10,
            s.version_x10 % 10
        ),
        2 => write!(
            out,
            "mode      {}",
            match s.mode {
                TransponderMode::Framed => "framed",
                TransponderMode::Transparent => "transparent",
            }
        ),
        3 => write!(
            out,
            "atom      {}",
            match s.atom {
                AtomLink::Unknown => "waiting",
                AtomLink::Answering => "answering",
                AtomLink::Silent => "SILENT",
            }
        ),
        4 => write!(out, "power     {}", yes_no(s.atom_powered, "on", "off")),
        5 => write!(out, "bus echo  {}", yes_no(s.echo_heard, "heard", "none")),
        6 => write!(out, "host frames {}", s.host_frames),
        7 => write!(out, "replies     {}", s.replies_forwarded),
        8 => write!(out, "timeouts {}  collisions {}", s.timeouts, s.collisions),
        ERROR_ROW => match s.last_error {
            None => Ok(()),
            Some(BasicError::ReplyTimeout { cmd }) => write!(out, "no reply to 0x{cmd:02X}"),
            Some(BasicError::BusCollisions { cmd }) => write!(out, "bus collisions 0x{cmd:02X}"),
            Some(BasicError::QueueFull { cmd }) => write!(out, "queue full, dropped 0x{cmd:02X}"),
            Some(BasicError::TransparentElsewhere { cmd }) => {
                write!(out, "transparent, dropped 0x{cmd:02X}")
            }
            Some(BasicError::InvalidPin { pin }) => write!(out, "no such pin {pin}"),
            Some(BasicError::HostOverflow) => write!(out, "host link overflow"),
        },
        _ => Ok(()),
    }
}

fn yes_no(value: Option<bool>, yes: &'static str, no: &'static str) -> &'static str {
    match value {
        Some(true) => yes,
        Some(false) => no,
        None => "?",
    }
}

/// One row of text, space padded; what does not fit is cut off, non-ASCII shows as '?'.
struct Line {
    cells: [u8; COLS],
    len: usize,
}

impl Default for Line {
    fn default() -> Self {
        Self {
            cells: [b' '; COLS],
            len: 0,
        }
    }
}

impl Write for Line {
    fn write_str(&mut self, text: &str) -> fmt::Result {
        for ch in text.chars() {
            if let Some(cell) = self.cells.get_mut(self.len) {
                *cell = if ch.is_ascii_graphic() || ch == ' ' {
                    ch as u8
                } else {
                    b'?'
                };
                self.len += 1;
            }
        }
        Ok(())
    }
}

/// A character cell to draw.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct Cell {
    /// Row, 0 at the top.
    pub row: usize,
    /// Column, 0 at the left.
    pub col: usize,
    /// The ASCII character.
    pub byte: u8,
}

/// The text wanted on the screen and the text drawn so far.
pub struct TextGrid {
    wanted: Text,
    shown: Text,
    /// Next cell to compare, `row * COLS + col`; the walk wraps around, so a change made
    /// behind it is reached on the next lap.
    next_cell: usize,
    /// Some cell may differ between `wanted` and `shown`.
    dirty: bool,
}

impl TextGrid {
    /// A grid for a screen that shows only spaces (cleared).
    pub fn new() -> Self {
        Self {
            wanted: [[b' '; COLS]; ROWS],
            shown: [[b' '; COLS]; ROWS],
            next_cell: 0,
            dirty: false,
        }
    }

    /// Sets the text the screen should show.
    pub fn set(&mut self, text: Text) {
        if text != self.wanted {
            self.wanted = text;
            self.dirty = true;
        }
    }

    /// The next cell that differs from what is shown, now taken as drawn; `None` once the
    /// screen shows the wanted text. Costs at most one pass over the grid.
    pub fn next_change(&mut self) -> Option<Cell> {
        if !self.dirty {
            return None;
        }
        for _ in 0..COLS * ROWS {
            let cell = self.next_cell;
            self.next_cell = (cell + 1) % (COLS * ROWS);
            let (row, col) = (cell / COLS, cell % COLS);
            let wanted = self.wanted.get(row).and_then(|r| r.get(col)).copied();
            let shown = self.shown.get_mut(row).and_then(|r| r.get_mut(col));
            if let (Some(byte), Some(shown)) = (wanted, shown)
                && byte != *shown
            {
                *shown = byte;
                return Some(Cell { row, col, byte });
            }
        }
        self.dirty = false;
        None
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn row_text(text: &Text, row: usize) -> &str {
        core::str::from_utf8(&text[row]).unwrap().trim_end()
    }

    fn drain(grid: &mut TextGrid) -> Vec<Cell> {
        core::iter::from_fn(|| grid.next_change()).collect()
    }

    #[test]
    fn shows_what_a_user_needs_to_know() {
        let status = BasicStatus {
            version_x10: 12,
            atom: AtomLink::Silent,
            atom_powered: Some(true),
            last_error: Some(BasicError::ReplyTimeout { cmd: 0x20 }),
            timeouts: 3,
            ..BasicStatus::default()
        };
        let text = render(&status);
        assert_eq!(row_text(&text, TITLE_ROW), "open myCobot Basic  v1.2");
        assert_eq!(row_text(&text, 2), "mode      framed");
        assert_eq!(row_text(&text, 3), "atom      SILENT");
        assert_eq!(row_text(&text, 4), "power     on");
        assert_eq!(row_text(&text, 5), "bus echo  ?");
        assert_eq!(row_text(&text, 8), "timeouts 3  collisions 0");
        assert_eq!(row_text(&text, ERROR_ROW), "no reply to 0x20");
    }

    #[test]
    fn rows_are_cut_at_the_screen_edge_and_stay_ascii() {
        let mut line = Line::default();
        write!(line, "{}", "x".repeat(COLS + 5)).unwrap();
        assert_eq!(line.cells, [b'x'; COLS]);
        let mut line = Line::default();
        line.write_str("µ\t").unwrap();
        assert_eq!(&line.cells[..3], b"?? ");
    }

    #[test]
    fn a_cleared_screen_draws_only_the_non_blank_cells_once() {
        let mut grid = TextGrid::new();
        let text = render(&BasicStatus::default());
        grid.set(text);
        let cells = drain(&mut grid);
        let non_blank = text.iter().flatten().filter(|&&b| b != b' ').count();
        assert_eq!(cells.len(), non_blank);
        for cell in &cells {
            assert_eq!(text[cell.row][cell.col], cell.byte);
        }
        grid.set(text);
        assert_eq!(grid.next_change(), None);
    }

    #[test]
    fn a_change_behind_the_walk_is_still_drawn() {
        let mut grid = TextGrid::new();
        let mut text = [[b' '; COLS]; ROWS];
        text[5][0] = b'a';
        text[6][0] = b'b';
        grid.set(text);
        assert_eq!(
            grid.next_change(),
            Some(Cell {
                row: 5,
                col: 0,
                byte: b'a'
            })
        );
        text[1][3] = b'c';
        grid.set(text);
        assert_eq!(
            grid.next_change(),
            Some(Cell {
                row: 6,
                col: 0,
                byte: b'b'
            })
        );
        assert_eq!(
            grid.next_change(),
            Some(Cell {
                row: 1,
                col: 3,
                byte: b'c'
            })
        );
        assert_eq!(grid.next_change(), None);
    }

    #[test]
    fn a_character_back_to_blank_is_erased() {
        let mut grid = TextGrid::new();
        let mut text = [[b' '; COLS]; ROWS];
        text[0][0] = b'x';
        grid.set(text);
        drain(&mut grid);
        text[0][0] = b' ';
        grid.set(text);
        assert_eq!(
            drain(&mut grid),
            [Cell {
                row: 0,
                col: 0,
                byte: b' '
            }]
        );
    }
}
