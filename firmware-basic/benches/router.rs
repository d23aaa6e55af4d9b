//! Several clients at once, in virtual time: crossed and lost replies, and throughput.
//!
//! Four clients talk to the Basic at the same time, each like pymycobot (one request, then
//! wait for its reply or its deadline: 0.5 s on the USB serial, 0.3 s on a network link), and
//! one of them sends garbage (noise, unfinished frames) before each of its requests. Each
//! request carries its client's number and a sequence number, and the scripted Atom echoes
//! them back after 100 us, so a reply given to the wrong client, or the late answer to an
//! earlier request taken for the current one, shows as "wrong". The Basic is polled every
//! 5 us; the bus echoes.
//!
//! Run: `cargo bench -p firmware-basic --bench router`.
#![allow(clippy::unwrap_used, clippy::indexing_slicing, missing_docs)]

#[path = "../tests/common/mod.rs"]
mod common;

use std::time::Instant;

use common::Rig;
use common::clients::{Tally, echo_atom, run_clients};
use firmware_basic::LinkId;

const REQUESTS: u64 = 10_000;

fn scenario(name: &str, with_usb: bool, garbage: bool) {
    let mut rig = Rig::quiet(true);
    rig.atom = echo_atom();
    rig.atom_delay_ns = 100_000;
    rig.step_ns = 5_000;
    let network = if with_usb { 3 } else { 4 };
    let mut links: Vec<LinkId> = Vec::new();
    if with_usb {
        links.push(LinkId::USB);
    }
    links.extend((0..network).map(|_| rig.connect().unwrap()));
    let wall = Instant::now();
    let (tallies, virtual_ns) = run_clients(&mut rig, &links, garbage, REQUESTS, 0x5EED);
    println!(
        "{name}: {REQUESTS} requests per client, {:.1} s of virtual time ({:.1} s wall)",
        virtual_ns as f64 / 1e9,
        wall.elapsed().as_secs_f64()
    );
    for (link, t) in links.iter().zip(&tallies) {
        let kind = if *link == LinkId::USB {
            "USB serial"
        } else {
            "network"
        };
        let garbage = if t.garbage_bursts > 0 {
            format!(", after {} garbage bursts", t.garbage_bursts)
        } else {
            String::new()
        };
        println!(
            "  client {} ({kind:10}): answered {:5}, wrong {}, lost {}; {:5.0} replies/s{garbage}",
            link.index(),
            t.answered,
            t.wrong,
            t.lost,
            t.answers_per_s(),
        );
    }
    let sum = |f: fn(&Tally) -> u64| tallies.iter().map(f).sum::<u64>();
    println!(
        "  all: {} requests, wrong (crossed or stale) {}, lost {}; {:.0} replies/s together",
        sum(|t| t.sent),
        sum(|t| t.wrong),
        sum(|t| t.lost),
        tallies.iter().map(Tally::answers_per_s).sum::<f64>()
    );
}

fn main() {
    println!("Basic router: four clients at once (virtual time, pymycobot-like clients)");
    scenario(
        "USB + 3 network clients, the last sending garbage",
        true,
        true,
    );
    scenario("4 network clients, no garbage", false, false);
}
