//! The transponder forwarding host requests to the Atom and replies back, on a simulated wire.
#![allow(clippy::unwrap_used, clippy::indexing_slicing)]

mod common;

use common::{Rig, frame};
use firmware_basic::{AtomLink, BasicError};
use protocol_core::{Frame, timing};

const GET_ANGLES: u8 = 0x20;

fn angles_reply() -> Vec<u8> {
    frame(GET_ANGLES, &[0, 100, 0xFF, 0x9C, 0, 0, 0, 0, 0x12, 0x34, 0xFE, 0xFA])
}

#[test]
fn get_angles_goes_to_the_atom_once_and_its_reply_to_the_host_once() {
    for echo in [true, false] {
        let mut rig = Rig::quiet(echo);
        rig.run_us(100);
        rig.host.send(&frame(GET_ANGLES, &[]));
        rig.run_us(10_000);
        assert_eq!(rig.atom_got.len(), 1, "echo {echo}");
        assert_eq!(rig.atom_got[0].1, Frame::new(GET_ANGLES, &[]).unwrap());
        assert_eq!(rig.host.received(), angles_reply(), "echo {echo}");
        assert_eq!(rig.basic.status().atom, AtomLink::Answering);
        assert_eq!(rig.basic.status().echo_heard, Some(echo));
    }
}
