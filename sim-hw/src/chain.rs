//! Servos daisy-chained on one [`Bus`]: every servo hears the same bytes, so one decoder (the
//! bus [tap](Bus::take_heard)) serves them all, and each servo transmits through its own station.

use crate::servo::{PacketListener, SimServo};
use crate::wire::{Bus, HeardByte, StationId};

/// Simulated servos sharing one bus. Feed it every byte the bus delivered
/// ([`ServoChain::hear`]), then let the servos answer ([`ServoChain::transmit_due`]) before the
/// bus starts its transmissions for the instant.
#[derive(Clone, Debug, Default)]
pub struct ServoChain {
    servos: Vec<(StationId, SimServo)>,
    listener: PacketListener,
}

impl ServoChain {
    /// A chain without servos.
    pub fn new() -> Self {
        Self::default()
    }

    /// Connects `servo` to `bus` as a transmitter (turn the bus tap on to feed
    /// [`ServoChain::hear`]); returns its station.
    pub fn attach(&mut self, bus: &mut Bus, servo: SimServo) -> StationId {
        let station = bus.attach_transmitter();
        self.servos.push((station, servo));
        station
    }

    /// One byte the bus delivered: a packet it completes is obeyed by every servo but its
    /// sender (a servo does not hear its own answers).
    pub fn hear(&mut self, heard: &HeardByte) {
        let servos = &mut self.servos;
        self.listener.hear(heard.byte, heard.end_ns, |packet| {
            for (_, servo) in servos.iter_mut().filter(|(st, _)| *st != heard.from) {
                servo.receive(&packet, heard.end_ns);
            }
        });
    }

    /// Moves every shaft up to `now_ns` and queues on the bus the answers due by then.
    pub fn transmit_due(&mut self, now_ns: u64, bus: &mut Bus) {
        for (station, servo) in &mut self.servos {
            if let Some(mut port) = bus.port(*station) {
                servo.transmit_due(now_ns, &mut port);
            }
        }
    }

    /// The next instant a servo has an answer to start, in ns.
    pub fn next_event_ns(&self) -> Option<u64> {
        self.servos
            .iter()
            .filter_map(|(_, s)| s.next_event_ns())
            .min()
    }

    /// The servo whose id (register 5) is `id` now.
    pub fn get(&self, id: u8) -> Option<&SimServo> {
        self.iter().find(|s| s.id() == id)
    }

    /// The servo whose id is `id` now, to inject faults or move it by hand.
    pub fn get_mut(&mut self, id: u8) -> Option<&mut SimServo> {
        self.servos
            .iter_mut()
            .map(|(_, s)| s)
            .find(|s| s.id() == id)
    }

    /// The bus station of the servo whose id is `id` now.
    pub fn station(&self, id: u8) -> Option<StationId> {
        self.servos
            .iter()
            .find(|(_, s)| s.id() == id)
            .map(|(st, _)| *st)
    }

    /// Every servo, in attach order.
    pub fn iter(&self) -> impl Iterator<Item = &SimServo> {
        self.servos.iter().map(|(_, s)| s)
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use protocol_core::BytePort;
    use protocol_core::servo::{Instruction, PacketDecoder, reg};

    #[test]
    fn the_addressed_servo_answers_and_the_others_stay_silent() {
        let mut bus = Bus::mycobot(1);
        bus.set_tap(true);
        let controller = bus.attach(false);
        let mut chain = ServoChain::new();
        for id in 1..=3 {
            chain.attach(&mut bus, SimServo::new(id, 2048));
        }
        let read = Instruction::Read {
            addr: reg::PRESENT_POSITION,
            count: 2,
        };
        bus.port(controller)
            .unwrap()
            .write(&read.to_packet(2).unwrap().to_bytes());
        let mut heard = Vec::new();
        let mut now = 0;
        bus.start_transmissions(now);
        while now < 1_000_000 {
            now = [bus.next_event_ns(), chain.next_event_ns()]
                .into_iter()
                .flatten()
                .min()
                .unwrap_or(1_000_000)
                .max(now + 1);
            bus.deliver(now);
            bus.take_heard(&mut heard);
            for h in heard.drain(..) {
                chain.hear(&h);
            }
            chain.transmit_due(now, &mut bus);
            bus.start_transmissions(now);
        }
        let mut answers = Vec::new();
        let mut port = bus.port(controller).unwrap();
        let mut decoder = PacketDecoder::new();
        while let Some(b) = port.read_byte() {
            decoder.feed(&[b], |p| answers.push(p));
        }
        assert_eq!(answers.len(), 1, "one answer");
        assert_eq!(answers[0].id(), 2);
        assert_eq!(answers[0].params(), [0x00, 0x08]);
        assert_eq!(chain.get(2).map(|s| s.stats().replies), Some(1));
        assert_eq!(chain.get(1).map(|s| s.stats().replies), Some(0));
        assert_eq!(chain.station(4), None);
    }
}
