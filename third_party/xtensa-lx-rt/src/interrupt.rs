//! Interrupts

include!(concat!(env!("OUT_DIR"), "/interrupt_level_masks.rs"));
