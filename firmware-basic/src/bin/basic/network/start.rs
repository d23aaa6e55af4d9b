//! Starts the Wi-Fi driver on an esp-rtos thread of its own, so that the super-loop serves
//! USB from boot whatever the radio does.
//!
//! `WifiController::new` (`esp_wifi_init` in Espressif's blobs) blocks its caller until the
//! radio's own tasks and interrupts have done their part. On a chip that is a fraction of a
//! second; on an emulator that does not model them, or a radio that is broken, it is forever,
//! and the task that called it idles (`waiti`) with nothing else to run. So the loop never calls
//! it: [`spawn`] hands the `WIFI` peripheral to a thread that does, and that thread leaves the
//! outcome for the loop to take ([`take_outcome`]) on its next pass. The loop gives up at the
//! deadline ([`crate::radio_start`]).
//!
//! The thread runs at the loop's priority, 0: the scheduler shares the CPU between them in
//! time slices (esp-rtos's tick, 10 ms), so a start-up that computes, or spins, cannot starve the
//! loop; while it waits, the loop has the CPU to itself. Past the deadline the loop raises its
//! own priority above it ([`give_up`]), so a start-up that never ends costs nothing after that.

use core::cell::RefCell;
use core::ffi::c_void;

use critical_section::Mutex;
use esp_hal::peripherals::WIFI;
use esp_radio::wifi::{ControllerConfig, WifiController, WifiError};

/// Stack of the start-up thread, in bytes (from the heap, given back when the thread ends):
/// esp-radio's initialisation and the blobs' `esp_wifi_init`, which ESP-IDF runs on its 3.5 KiB
/// main task (the radio's own tasks have their own stacks).
const START_STACK_BYTES: usize = 6 * 1024;
/// The start-up thread's priority: the loop's.
const START_PRIORITY: u32 = 0;
/// The loop's priority once it has given up on the radio: above the start-up thread's.
const LOOP_PRIORITY_WITHOUT_RADIO: usize = 1;

/// What the start-up thread reports: the driver, or why not.
type Outcome = Result<WifiController<'static>, WifiError>;

/// The peripheral, from the loop to the thread.
static DEVICE: Mutex<RefCell<Option<WIFI<'static>>>> = Mutex::new(RefCell::new(None));
/// The outcome, from the thread to the loop.
static OUTCOME: Mutex<RefCell<Option<Outcome>>> = Mutex::new(RefCell::new(None));

/// Starts the driver on its own thread (the esp-rtos scheduler must be running). Returns at
/// once.
pub fn spawn(wifi: WIFI<'static>) {
    critical_section::with(|cs| DEVICE.borrow_ref_mut(cs).replace(wifi));
    // SAFETY: `task_create` requires `param` to be valid for the task's lifetime and `Send`:
    // it is null and `start` never reads it (the peripheral goes through `DEVICE`). The task's
    // stack comes from the heap, which is set up before this is called, and the scheduler is
    // running (esp_rtos::start). The handle is not kept: the thread ends by returning, which
    // esp-rtos turns into deleting it.
    #[allow(unsafe_code)]
    let _thread = unsafe {
        esp_radio_rtos_driver::task_create(
            "radio start",
            start,
            core::ptr::null_mut(),
            START_PRIORITY,
            None,
            START_STACK_BYTES,
        )
    };
}

/// The start-up thread: takes the peripheral, starts the driver (however long that takes) and
/// leaves the outcome.
extern "C" fn start(_unused: *mut c_void) {
    let Some(device) = critical_section::with(|cs| DEVICE.borrow_ref_mut(cs).take()) else {
        return;
    };
    let outcome = WifiController::new(device, ControllerConfig::default());
    critical_section::with(|cs| OUTCOME.borrow_ref_mut(cs).replace(outcome));
}

/// What the start-up thread reported, once.
pub fn take_outcome() -> Option<Outcome> {
    critical_section::with(|cs| OUTCOME.borrow_ref_mut(cs).take())
}

/// The loop gives up on the radio: it no longer shares the CPU with a start-up that has not
/// ended (the radio's tasks, if any run, still preempt it).
pub fn give_up() {
    esp_rtos::CurrentThreadHandle::get().set_priority(LOOP_PRIORITY_WITHOUT_RADIO);
}
