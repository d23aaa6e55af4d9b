//! The status screen's text: what each character cell shows for a [`BasicStatus`], and which
//! cells changed since they were last drawn. Pure logic, tested on the host
//! (`cargo test -p firmware-basic --test board_logic`).

use core::fmt::{self, Write};

use firmware_basic::wifi::{Failure, JoinFailure, StationState, WifiError, WifiStatus};
use firmware_basic::{AtomLink, BasicError, BasicStatus, TransponderMode};

use crate::radio_start::{RADIO_START_DEADLINE_US, RadioStart};

/// Text columns: 320 px / 10 px.
pub const COLS: usize = 32;
/// Text rows: 240 px / 20 px.
pub const ROWS: usize = 12;
/// The row with the firmware name and version.
pub const TITLE_ROW: usize = 0;
/// The row with the last error.
pub const ERROR_ROW: usize = 10;
/// The row with the loop's longest pass gap lately.
pub const LOOP_ROW: usize = 1;
/// The row with the Wi-Fi network and the station's state (Wi-Fi builds).
pub const WIFI_ROW: usize = 9;
/// The row with the address and port clients connect to, and how many are connected (or why
/// the station is not online).
pub const NET_ROW: usize = 11;

/// A screenful of ASCII characters.
pub type Text = [[u8; COLS]; ROWS];

/// What the board shows besides the transponder's status.
#[derive(Clone, Debug, Default, PartialEq, Eq)]
pub struct BoardStatus {
    /// The longest gap between two passes of the loop lately, microseconds
    /// ([`crate::loop_time`]).
    pub loop_max_us: u32,
    /// Wi-Fi, in a Wi-Fi build.
    pub wifi: Option<WifiStatus>,
    /// The radio's start-up, in a Wi-Fi build.
    pub radio: Option<RadioStart>,
}

/// The screen text for the transponder's `status` and the `board`'s.
pub fn render(status: &BasicStatus, board: &BoardStatus) -> Text {
    let mut text = [[b' '; COLS]; ROWS];
    for (row, cells) in text.iter_mut().enumerate() {
        let mut line = Line::default();
        // `Line` never fails: what does not fit is cut off.
        let _ = match (row, &board.wifi) {
            (LOOP_ROW, _) => write!(line, "loop max  {} us", board.loop_max_us),
            (WIFI_ROW | NET_ROW, Some(wifi)) => match board.radio {
                Some(RadioStart::Up) | None => write_wifi_row(&mut line, row, wifi),
                Some(radio) => write_radio_row(&mut line, row, radio, wifi),
            },
            _ => write_row(&mut line, row, status),
        };
        *cells = line.cells;
    }
    text
}

/// Writes Wi-Fi row `row` (`WIFI_ROW` or `NET_ROW`) while the radio is not up: starting, or
/// given up on (the Basic is a USB transponder then).
fn write_radio_row(
    out: &mut Line,
    row: usize,
    radio: RadioStart,
    wifi: &WifiStatus,
) -> fmt::Result {
    match (row, radio) {
        (WIFI_ROW, RadioStart::Starting { .. }) => write!(out, "wifi  radio starting"),
        (WIFI_ROW, _) => write!(out, "wifi  FAILED, USB only"),
        (_, RadioStart::Refused) => write!(out, "radio refused to start"),
        (_, RadioStart::TimedOut) => write!(
            out,
            "radio not up in {} s",
            RADIO_START_DEADLINE_US / 1_000_000
        ),
        _ => write!(out, "port {}", wifi.port),
    }
}

/// Writes Wi-Fi row `row` (`WIFI_ROW` or `NET_ROW`).
fn write_wifi_row(out: &mut Line, row: usize, wifi: &WifiStatus) -> fmt::Result {
    let Some(ssid) = &wifi.ssid else {
        return match row {
            WIFI_ROW if wifi.settings_unreadable => write!(out, "wifi  off (settings lost)"),
            WIFI_ROW => write!(out, "wifi  off"),
            _ => write!(out, "port {}", wifi.port),
        };
    };
    if row == WIFI_ROW {
        let state = match wifi.state {
            StationState::Off => "off",
            StationState::Joining { .. } => "joining",
            StationState::GettingAddress { .. } => "DHCP",
            StationState::Online { .. } => "on",
            StationState::Waiting { .. } => "retry",
        };
        return write!(out, "wifi  {state:<8}{ssid}");
    }
    match (wifi.state, wifi.last_failure) {
        (StationState::Online { address }, _) => {
            let plural = if wifi.clients == 1 { "" } else { "s" };
            write!(
                out,
                "{address}:{}  {} client{plural}",
                wifi.port, wifi.clients
            )
        }
        (_, Some(failure)) => write!(
            out,
            "{}",
            match failure {
                Failure::Join(JoinFailure::NotFound) => "network not found",
                Failure::Join(JoinFailure::AuthFailed) => "wrong password?",
                Failure::Join(JoinFailure::Other) => "join failed",
                Failure::JoinTimeout => "join timed out",
                Failure::NoAddress => "no DHCP address",
                Failure::LinkLost => "link lost",
            }
        ),
        _ => write!(out, "port {}", wifi.port),
    }
}

/// Writes the text of screen row `row`.
pub fn write_row(out: &mut Line, row: usize, s: &BasicStatus) -> fmt::Result {
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
        6 => write!(
            out,
            "frames {}  replies {}",
            s.host_frames, s.replies_forwarded
        ),
        7 => write!(out, "protocol  {} (hold C 2s)", s.dialect.name()),
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
            Some(BasicError::SettingNotSaved) => write!(out, "protocol not saved to flash"),
            Some(BasicError::Wifi(WifiError::Refused(why))) => write!(out, "wifi: {why}"),
            Some(BasicError::Wifi(WifiError::Flash(_))) => write!(out, "wifi: flash write failed"),
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
pub struct Line {
    /// The row's characters.
    pub cells: [u8; COLS],
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
        let text = render(&status, &BoardStatus::default());
        assert_eq!(row_text(&text, TITLE_ROW), "open myCobot Basic  v1.2");
        assert_eq!(row_text(&text, 2), "mode      framed");
        assert_eq!(row_text(&text, 3), "atom      SILENT");
        assert_eq!(row_text(&text, 4), "power     on");
        assert_eq!(row_text(&text, 5), "bus echo  ?");
        assert_eq!(row_text(&text, 7), "protocol  pymycobot (hold C 2s)");
        assert_eq!(row_text(&text, 8), "timeouts 3  collisions 0");
        assert_eq!(row_text(&text, ERROR_ROW), "no reply to 0x20");
    }

    #[test]
    fn wifi_rows_show_network_address_port_and_clients() {
        let basic = BasicStatus::default();
        let mut wifi = WifiStatus {
            ssid: Some("robots".try_into().unwrap()),
            state: StationState::Online {
                address: core::net::Ipv4Addr::new(192, 168, 100, 200),
            },
            port: 65535,
            clients: 7,
            last_failure: None,
            settings_unreadable: false,
        };
        let board = |wifi: &WifiStatus| BoardStatus {
            loop_max_us: 412,
            wifi: Some(wifi.clone()),
            radio: Some(RadioStart::Up),
        };
        let text = render(&basic, &board(&wifi));
        assert_eq!(row_text(&text, LOOP_ROW), "loop max  412 us");
        assert_eq!(row_text(&text, WIFI_ROW), "wifi  on      robots");
        assert_eq!(row_text(&text, NET_ROW), "192.168.100.200:65535  7 clients");
        wifi.state = StationState::Waiting { retry_at_us: 0 };
        wifi.last_failure = Some(Failure::Join(JoinFailure::AuthFailed));
        let text = render(&basic, &board(&wifi));
        assert_eq!(row_text(&text, WIFI_ROW), "wifi  retry   robots");
        assert_eq!(row_text(&text, NET_ROW), "wrong password?");
        wifi.ssid = None;
        wifi.state = StationState::Off;
        let text = render(&basic, &board(&wifi));
        assert_eq!(row_text(&text, WIFI_ROW), "wifi  off");
        assert_eq!(row_text(&text, NET_ROW), "port 65535");
        // Without Wi-Fi the rows stay blank.
        let text = render(&basic, &BoardStatus::default());
        assert_eq!(row_text(&text, WIFI_ROW), "");
        assert_eq!(row_text(&text, NET_ROW), "");
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
        let text = render(&BasicStatus::default(), &BoardStatus::default());
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

    #[test]
    fn a_radio_that_did_not_start_is_shown_with_usb_still_served() {
        let wifi = WifiStatus {
            ssid: Some("robots".try_into().unwrap()),
            state: StationState::Off,
            port: 9000,
            clients: 0,
            last_failure: None,
            settings_unreadable: false,
        };
        let board = |radio| BoardStatus {
            loop_max_us: 50,
            wifi: Some(wifi.clone()),
            radio: Some(radio),
        };
        let text = render(&BasicStatus::default(), &board(RadioStart::begin(0)));
        assert_eq!(row_text(&text, WIFI_ROW), "wifi  radio starting");
        assert_eq!(row_text(&text, NET_ROW), "port 9000");
        let text = render(&BasicStatus::default(), &board(RadioStart::TimedOut));
        assert_eq!(row_text(&text, WIFI_ROW), "wifi  FAILED, USB only");
        assert_eq!(row_text(&text, NET_ROW), "radio not up in 5 s");
        let text = render(&BasicStatus::default(), &board(RadioStart::Refused));
        assert_eq!(row_text(&text, NET_ROW), "radio refused to start");
    }
}
