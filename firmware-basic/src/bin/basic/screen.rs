//! The LCD status screen: draws the [`screen_text`](crate::screen_text) grid one changed
//! character per call, so the forwarder is never held up by the display for longer than one
//! character (~0.1 ms at 40 MHz SPI, well inside the 1.28 ms the 128-byte UART FIFO buffers at
//! 1 Mbaud).

use crate::screen_text::{
    Cell, ERROR_ROW, NET_ROW, TITLE_ROW, Text as ScreenText, TextGrid, WIFI_ROW,
};
use embedded_graphics::{
    mono_font::{MonoTextStyleBuilder, ascii::FONT_10X20},
    pixelcolor::Rgb565,
    prelude::*,
    text::{Baseline, Text},
};

/// Cell size of `FONT_10X20`, in pixels.
const CELL_WIDTH_PX: i32 = 10;
const CELL_HEIGHT_PX: i32 = 20;
/// The screen text is rebuilt at most this often (counters change with every frame).
const REFORMAT_INTERVAL_US: u64 = 200_000;

/// The status screen on `display`, which must already be cleared to black.
pub struct StatusScreen<D> {
    display: D,
    grid: TextGrid,
    /// When the text was last rebuilt; `None` before the first time.
    formatted_at_us: Option<u64>,
}

impl<D: DrawTarget<Color = Rgb565>> StatusScreen<D> {
    /// A blank screen on `display`.
    pub fn new(display: D) -> Self {
        Self {
            display,
            grid: TextGrid::new(),
            formatted_at_us: None,
        }
    }

    /// Rebuilds the text with `render` at `now_us` if [`REFORMAT_INTERVAL_US`] has passed since
    /// the last time (`render` is called only then); the cells that changed are drawn next.
    pub fn update(&mut self, now_us: u64, render: impl FnOnce() -> ScreenText) {
        if self
            .formatted_at_us
            .is_some_and(|at| now_us.wrapping_sub(at) < REFORMAT_INTERVAL_US)
        {
            return;
        }
        self.formatted_at_us = Some(now_us);
        self.grid.set(render());
    }

    /// Draws the next character whose text changed, if any.
    pub fn draw_next(&mut self) {
        let Some(Cell { row, col, byte }) = self.grid.next_change() else {
            return;
        };
        let color = match row {
            TITLE_ROW => Rgb565::YELLOW,
            ERROR_ROW => Rgb565::RED,
            WIFI_ROW | NET_ROW => Rgb565::CYAN,
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
