//! Fixed-point kinematics of the myCobot 280 M5 (`kinematics.md`).
#![cfg_attr(not(test), no_std)]
#![forbid(unsafe_code)]
