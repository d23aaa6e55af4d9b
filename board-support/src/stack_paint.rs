//! ESP32-C3: [`paint_unused_ram`] writes every word of the free stack, and the RAM the
//! bootloader leaves above it, once, first thing in `main`, before the loop's frames exist.
//!
//! Why: the second-stage bootloader runs its loader code from the RAM the application later
//! uses as the top of its stack (ESP-IDF's `iram_loader_seg`, 0x403C_BF10..0x403C_CBA8 in the
//! bootloader espflash writes, which is 0x3FCC_BF10..0x3FCC_CBA8 on the data bus: 6 to 9 KiB
//! below `_stack_start`), and the rest of its code just above the stack (0x3FCC_E710..,
//! on the stack top's page). On a chip that is nothing. QEMU keeps the code it translated from
//! there, and on a page that holds translated code every store takes the slow path that looks
//! for code to invalidate; the bootloader's blocks under the parts of the stack the loop never
//! writes stayed for ever, so the loop's stack stores on those pages paid it: 70 % of the
//! emulated Atom's CPU time, a servo transaction every 4.5 ms (median), each joint's reading
//! older than the 50 ms freshness rule a fifth of the time, and moves refused
//! (docs/boards.md, "Emulated boards"). Writing every word once drops those blocks and the
//! pages are plain data again. On a chip it costs some 100 000 stores (the stack is about
//! 300 KiB, the RAM above it 65 KiB), a millisecond or two at boot.

/// The end of the RAM the second-stage bootloader leaves to the application above the stack
/// (esp-hal's `dram2_seg`, from `_stack_start` to 0x3FCD_E710; above it is the ROM's).
const RECLAIMED_END: usize = 0x3FCD_E710;

/// Writes zero over the free stack, from its end (its lowest address) up to just below the
/// caller's frame, and over the RAM the bootloader left above the stack (its code at
/// 0x3FCC_E710.. shares a page with the top of the stack). Call it first thing in `main`, and
/// keep `main`'s own frame small: the rest of the program must run in a function `main` calls
/// after it (`#[inline(never)]`), so that its frames are all in painted memory. Nothing else
/// runs yet (no interrupt is enabled before `esp_hal::init`, nothing is placed above the
/// stack), so nothing lives in what it writes.
#[inline(never)]
pub fn paint_unused_ram() {
    // SAFETY: both symbols are defined by esp-hal's linker script for this chip; only their
    // addresses are taken, never their values.
    unsafe extern "C" {
        /// The stack's lowest address (esp-hal's linker script).
        static _stack_end: u32;
        /// The stack's highest address, where the bootloader's reclaimed RAM starts.
        static _stack_start: u32;
    }
    let sp: usize;
    // SAFETY: reads the stack pointer into a register; no memory is touched.
    unsafe { core::arch::asm!("mv {}, sp", out(reg) sp, options(nomem, nostack)) };
    // Below this function's frame, with a margin.
    let below_frame = sp.saturating_sub(64);
    zero_words((&raw const _stack_end) as usize, below_frame);
    zero_words((&raw const _stack_start) as usize, RECLAIMED_END);
}

/// Writes zero to every word from `from` up to `to`. Inlined, so that it has no frame of its
/// own below the caller's.
#[inline(always)]
fn zero_words(from: usize, to: usize) {
    let mut at = (from + 3) & !3;
    let end = to & !3;
    while at < end {
        // SAFETY: `at` is word-aligned RAM that no Rust object owns and nothing else touches
        // now ([`paint_unused_ram`]).
        unsafe { core::ptr::write_volatile(at as *mut u32, 0) };
        at += 4;
    }
}
