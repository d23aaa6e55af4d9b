//! [`BasicIo`] on the chip: the two user outputs, the two user inputs, the front buttons, and
//! with Wi-Fi the flash the settings live in.

use esp_hal::gpio::{AnyPin, Input, InputConfig, Level, Output, OutputConfig, Pull};
use firmware_basic::io::{BasicIo, Buttons, INPUT_PINS, OUTPUT_PINS};
#[cfg(feature = "wifi")]
use firmware_basic::wifi::{FlashWifiStore, WifiStore};

/// The Basic's board IO.
pub struct BoardIo<'d> {
    /// Ordered like [`OUTPUT_PINS`].
    outputs: [Output<'d>; 2],
    /// Ordered like [`INPUT_PINS`].
    inputs: [Input<'d>; 2],
    /// Buttons A, B, C.
    buttons: [Input<'d>; 3],
    /// The Wi-Fi settings' flash (its region, through esp-storage).
    #[cfg(feature = "wifi")]
    wifi: Option<FlashWifiStore<esp_storage::FlashStorage<'d>>>,
}

impl<'d> BoardIo<'d> {
    /// Takes the pins: outputs start low, inputs and buttons float (the board has external
    /// pull-ups on the buttons; GPIO 34..39 of the ESP32 have no internal pulls anyway).
    pub fn new(
        outputs: [AnyPin<'d>; 2],
        inputs: [AnyPin<'d>; 2],
        buttons: [AnyPin<'d>; 3],
    ) -> Self {
        let floating = InputConfig::default().with_pull(Pull::None);
        Self {
            outputs: outputs.map(|pin| Output::new(pin, Level::Low, OutputConfig::default())),
            inputs: inputs.map(|pin| Input::new(pin, floating)),
            buttons: buttons.map(|pin| Input::new(pin, floating)),
            #[cfg(feature = "wifi")]
            wifi: None,
        }
    }

    /// Lends the Basic `region` of `flash` for its Wi-Fi settings, from boot on.
    #[cfg(feature = "wifi")]
    pub fn with_wifi_flash(
        mut self,
        flash: esp_storage::FlashStorage<'d>,
        region: core::ops::Range<u32>,
    ) -> Self {
        self.wifi = Some(FlashWifiStore::new(flash, region));
        self
    }
}

impl BasicIo for BoardIo<'_> {
    fn set_output(&mut self, pin: u8, high: bool) -> bool {
        let index = OUTPUT_PINS.iter().position(|&p| p == pin);
        match index.and_then(|i| self.outputs.get_mut(i)) {
            Some(output) => {
                output.set_level(Level::from(high));
                true
            }
            None => false,
        }
    }

    fn read_input(&mut self, pin: u8) -> Option<bool> {
        let index = INPUT_PINS.iter().position(|&p| p == pin)?;
        self.inputs.get(index).map(Input::is_high)
    }

    fn tof_distance_mm(&mut self) -> Option<u16> {
        // No ToF sensor driver yet: reported to the host as "no sensor".
        None
    }

    fn buttons(&mut self) -> Buttons {
        let [a, b, c] = &self.buttons;
        Buttons {
            a: a.is_low(),
            b: b.is_low(),
            c: c.is_low(),
        }
    }

    #[cfg(feature = "wifi")]
    fn wifi_store(&mut self) -> Option<&mut dyn WifiStore> {
        self.wifi.as_mut().map(|store| store as &mut dyn WifiStore)
    }

    #[cfg(feature = "wifi")]
    fn dialect_store(&mut self) -> Option<&mut dyn firmware_basic::DialectStore> {
        self.wifi
            .as_mut()
            .map(|store| store as &mut dyn firmware_basic::DialectStore)
    }
}
