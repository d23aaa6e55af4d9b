//! The virtual myCobot 280 M5: the real Basic and Atom firmware libraries on the host, wired by
//! a simulated shared bus to simulated Feetech STS servos, and a live 3D view of it ([`web`]).
#![forbid(unsafe_code)]
pub mod host;
pub mod sim;
pub mod web;
