//! What the Basic's board gives the transponder: two user outputs, two user inputs, an optional
//! ToF distance sensor and the three front buttons (`docs/boards.md`).

use protocol_core::command::{BasicInputPin, BasicOutputPin};

use crate::dialect::DialectStore;
use crate::wifi::WifiStore;

/// User output pins a client may drive with 0xA0 (GPIO5 drives the suction-pump valve).
pub const OUTPUT_PINS: [u8; 2] = BasicOutputPin::ALLOWED;
/// User input pins a client may read with 0xA1 (input-only GPIOs).
pub const INPUT_PINS: [u8; 2] = BasicInputPin::ALLOWED;

/// The state of the Basic's three front buttons (true = pressed).
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct Buttons {
    /// Left button (GPIO39).
    pub a: bool,
    /// Middle button (GPIO38).
    pub b: bool,
    /// Right button (GPIO37).
    pub c: bool,
}

/// The Basic's pins and sensors, implemented by the board layer and by the virtual robot.
///
/// The transponder only calls these with pins it has checked against [`OUTPUT_PINS`] and
/// [`INPUT_PINS`]; an implementation still refuses any other pin. None of these may block.
pub trait BasicIo {
    /// Drives output `pin` high or low; false if this board cannot drive `pin`.
    fn set_output(&mut self, pin: u8, high: bool) -> bool;

    /// Level of input `pin` (true = high); `None` if this board cannot read `pin`.
    fn read_input(&mut self, pin: u8) -> Option<bool>;

    /// Latest distance measured by the ToF sensor, in millimetres; `None` if no sensor answers.
    fn tof_distance_mm(&mut self) -> Option<u16>;

    /// Which front buttons are pressed now.
    fn buttons(&mut self) -> Buttons;

    /// Where the Wi-Fi settings are kept (the board's flash; a file in the virtual robot).
    /// `None` (the default): the board has no Wi-Fi, and 0xB0..0xB2 answer as such. Asked at
    /// boot (the settings are loaded then) and for every Wi-Fi command; a board with Wi-Fi
    /// always lends the same store.
    fn wifi_store(&mut self) -> Option<&mut dyn WifiStore> {
        None
    }

    /// Where the dialect is kept (the board's flash, beside the Wi-Fi settings; a file in the
    /// virtual robot). `None` (the default): a change lasts until power-off.
    fn dialect_store(&mut self) -> Option<&mut dyn DialectStore> {
        None
    }
}

/// A board with nothing attached: outputs refuse, inputs and the sensor read nothing, no button
/// is ever pressed. For tests and for hosts that do not model the Basic's pins.
#[derive(Clone, Copy, Debug, Default)]
pub struct NullIo;

impl BasicIo for NullIo {
    fn set_output(&mut self, _pin: u8, _high: bool) -> bool {
        false
    }

    fn read_input(&mut self, _pin: u8) -> Option<bool> {
        None
    }

    fn tof_distance_mm(&mut self) -> Option<u16> {
        None
    }

    fn buttons(&mut self) -> Buttons {
        Buttons::default()
    }
}
