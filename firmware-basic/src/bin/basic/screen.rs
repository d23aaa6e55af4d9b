//! The LCD status screen: a grid of text cells redrawn one changed cell per call, so the
//! forwarder is never held up by the display for longer than one character (~0.1 ms at 40 MHz
//! SPI, well inside the 1.28 ms the 128-byte UART FIFO buffers at 1 Mbaud).

use core::fmt::{self, Write};

use embedded_graphics::{
    mono_font::{MonoTextStyleBuilder, ascii::FONT_10X20},
    pixelcolor::Rgb565,
    prelude::*,
    text::{Baseline, Text},
};
use firmware_basic::{AtomLink, BasicError, BasicStatus, TransponderMode};

/// Text columns: 320 px / 10 px.
const COLS: usize = 32;
/// Text rows: 240 px / 20 px.
const ROWS: usize = 12;
/// Cell size of `FONT_10X20`, in pixels.
const CELL_WIDTH_PX: i32 = 10;
const CELL_HEIGHT_PX: i32 = 20;
/// The screen text is rebuilt at most this often (counters change with every frame).
const REFORMAT_INTERVAL_US: u64 = 200_000;

/// Rows with their own colour.
const TITLE_ROW: usize = 0;
const ERROR_ROW: usize = 10;

/// The status screen on `display`, which must already be cleared to black.
pub struct StatusScreen<D> {
    display: D,
    wanted: [[u8; COLS]; ROWS],
    shown: [[u8; COLS]; ROWS],
    /// Next cell to compare, row * COLS + column.
    next_cell: usize,
    /// Cells may differ between `wanted` and `shown`.
    dirty: bool,
    last_status: Option<BasicStatus>,
    formatted_at_us: u64,
}

impl<D: DrawTarget<Color = Rgb565>> StatusScreen<D> {
    /// A blank screen on `display`.
    pub fn new(display: D) -> Self {
        Self {
            display,
            wanted: [[b' '; COLS]; ROWS],
            shown: [[b' '; COLS]; ROWS],
            next_cell: 0,
            dirty: false,
            last_status: None,
            formatted_at_us: 0,
        }
    }

    /// Notes the transponder's `status` at `now_us`; the text follows within
    /// [`REFORMAT_INTERVAL_US`] when it changed.
    pub fn update(&mut self, now_us: u64, status: BasicStatus) {
        let due = now_us.wrapping_sub(self.formatted_at_us) >= REFORMAT_INTERVAL_US;
        if self.last_status == Some(status) || (self.last_status.is_some() && !due) {
            return;
        }
        self.last_status = Some(status);
        self.formatted_at_us = now_us;
        for (row, text) in self.wanted.iter_mut().enumerate() {
            let mut line = Line::default();
            // `Line` never fails: what does not fit is cut off.
            let _ = write_row(&mut line, row, &status);
            *text = line.cells;
        }
        self.dirty = true;
    }

    /// Draws the next cell whose text changed, if any.
    pub fn draw_next(&mut self) {
        if !self.dirty {
            return;
        }
        for _ in 0..COLS * ROWS {
            let cell = self.next_cell;
            self.next_cell = (cell + 1) % (COLS * ROWS);
            let (row, col) = (cell / COLS, cell % COLS);
            let wanted = self.wanted.get(row).and_then(|r| r.get(col)).copied();
            let shown = self.shown.get_mut(row).and_then(|r| r.get_mut(col));
            if let (Some(wanted), Some(shown)) = (wanted, shown)
                && wanted != *shown
            {
                *shown = wanted;
                self.draw_cell(row, col, wanted);
                return;
            }
        }
        self.dirty = false;
    }

    fn draw_cell(&mut self, row: usize, col: usize, byte: u8) {
        let color = match row {
            TITLE_ROW => Rgb565::YELLOW,
            ERROR_ROW => Rgb565::RED,
            _ => Rgb565::WHITE,
        };
        // An opaque background makes each character overwrite its whole cell.
        let style = MonoTextStyleBuilder::new()
            .font(&FONT_10X20)
            .text_color(color)
            .background_color(Rgb565::BLACK)
            .build();
        let byte = [byte];
        let text = core::str::from_utf8(&byte).unwrap_or("?");
        let origin = Point::new(
            i32::try_from(col).unwrap_or(0) * CELL_WIDTH_PX,
            i32::try_from(row).unwrap_or(0) * CELL_HEIGHT_PX,
        );
        // A failed SPI write leaves one stale character until that cell changes again.
        let _ = Text::with_baseline(text, origin, style, Baseline::Top).draw(&mut self.display);
    }
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
        8 => write!(out, "timeouts {} collisions {}", s.timeouts, s.collisions),
        ERROR_ROW => match s.last_error {
            None => Ok(()),
            Some(BasicError::ReplyTimeout { cmd }) => write!(out, "no reply to 0x{cmd:02X}"),
            Some(BasicError::BusCollisions { cmd }) => write!(out, "bus collisions 0x{cmd:02X}"),
            Some(BasicError::QueueFull { cmd }) => write!(out, "queue full, dropped 0x{cmd:02X}"),
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
