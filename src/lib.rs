//! The virtual myCobot 280 M5: the real Basic and Atom firmware libraries on the host, wired by
//! a simulated shared bus to simulated Feetech STS servos.
#![forbid(unsafe_code)]
pub mod host;
pub mod sim;
