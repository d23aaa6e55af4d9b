//! Clients that talk to the rig's Basic at the same time, each like pymycobot: one request,
//! wait for its reply or the client's deadline, the next request. Every request carries its
//! client's number and a sequence number, and the scripted Atom echoes them back, so a reply
//! that went to the wrong client (or is the late answer to an earlier request) shows.

use firmware_basic::{LinkId, LinkKind};
use protocol_core::{Frame, FrameDecoder};

use super::{Responder, Rig};

/// The command every client asks: get_encoder, with the client's number and a sequence number
/// as data (the Atom of [`echo_atom`] does not care what it means).
pub const ASK: u8 = 0x3B;

/// An Atom that answers every request with its own data, at once.
pub fn echo_atom() -> Responder {
    Box::new(|f: &Frame| Some(Frame::new(f.cmd(), f.data())?.to_bytes().to_vec()))
}

/// Deterministic pseudo-random numbers (xorshift64).
pub struct Rng(u64);

impl Rng {
    /// A generator from `seed` (any value).
    pub fn new(seed: u64) -> Self {
        Self(seed | 1)
    }

    /// The next number.
    pub fn next(&mut self) -> u64 {
        self.0 ^= self.0 << 13;
        self.0 ^= self.0 >> 7;
        self.0 ^= self.0 << 17;
        self.0
    }

    /// A number below `n`.
    pub fn below(&mut self, n: u64) -> u64 {
        self.next() % n.max(1)
    }
}

/// Garbage as a confused client sends it: noise and, half of the time, the start of a frame
/// that never ends (`FE FE LEN`), which holds back whatever the client sends next until its
/// link's quiet gap has passed. It is made so that it never forms a frame, alone or with the
/// request that follows it (frames carry no checksum: garbage that does is a request): the
/// noise has no `FE` and no `FA`, and the unfinished frame is longer than the request behind
/// it.
pub fn garbage(rng: &mut Rng) -> Vec<u8> {
    let mut bytes: Vec<u8> = (0..rng.below(24)).map(|_| rng.below(0xFA) as u8).collect();
    if rng.below(2) == 0 {
        bytes.extend([0xFE, 0xFE, 9 + rng.below(56) as u8]);
    }
    bytes
}

/// What happened to one client's requests.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct Tally {
    /// Requests sent.
    pub sent: u64,
    /// Requests answered with their own data, in time.
    pub answered: u64,
    /// Replies with other data: another client's, or the late answer to an earlier request.
    pub wrong: u64,
    /// Requests with no reply by the client's deadline.
    pub lost: u64,
    /// Garbage bursts sent.
    pub garbage_bursts: u64,
    /// Virtual time from the start until the client was done (its last answer or deadline),
    /// in ns.
    pub done_ns: u64,
}

impl Tally {
    /// Answers per second of the client's own run.
    pub fn answers_per_s(&self) -> f64 {
        self.answered as f64 * 1e9 / self.done_ns.max(1) as f64
    }
}

/// One simulated client.
struct Client {
    link: LinkId,
    number: u8,
    deadline_ns: u64,
    sends_garbage: bool,
    decoder: FrameDecoder,
    /// How many of the bytes the Basic wrote to this client have been decoded.
    read: usize,
    seq: u16,
    /// The request waiting for its reply: its data, and until when the client waits.
    waiting: Option<([u8; 3], u64)>,
    tally: Tally,
}

impl Client {
    fn request(&self) -> [u8; 3] {
        let [hi, lo] = self.seq.to_be_bytes();
        [self.number, hi, lo]
    }
}

/// Runs clients on `links` (the last one, if `garbage_sender`, also sends garbage before each
/// of its requests) until each has sent `requests` requests and had its answer or given up.
/// Returns each client's tally and the virtual time it took, in ns.
pub fn run_clients(
    rig: &mut Rig,
    links: &[LinkId],
    garbage_sender: bool,
    requests: u64,
    seed: u64,
) -> (Vec<Tally>, u64) {
    let mut rng = Rng::new(seed);
    let last = links.len().saturating_sub(1);
    let mut clients: Vec<Client> = links
        .iter()
        .enumerate()
        .map(|(i, &link)| Client {
            link,
            number: i as u8,
            deadline_ns: if link == LinkId::USB {
                LinkKind::Serial.client_deadline_us()
            } else {
                LinkKind::Network.client_deadline_us()
            } * 1_000,
            sends_garbage: garbage_sender && i == last,
            decoder: FrameDecoder::new(),
            read: 0,
            seq: 0,
            waiting: None,
            tally: Tally::default(),
        })
        .collect();
    let start_ns = rig.now_ns;
    loop {
        let mut busy = false;
        for client in &mut clients {
            let now = rig.now_ns;
            let port = rig.client(client.link);
            let mut frames = Vec::new();
            let fresh: Vec<u8> = port.from_basic[client.read..]
                .iter()
                .filter(|&&(at, _)| at <= now)
                .map(|&(_, b)| b)
                .collect();
            client.read += fresh.len();
            client.decoder.feed(&fresh, |f| frames.push(f));
            for frame in frames {
                match client.waiting {
                    Some((data, _)) if frame.cmd() == ASK && frame.data() == data => {
                        client.tally.answered += 1;
                        client.waiting = None;
                    }
                    _ => client.tally.wrong += 1,
                }
            }
            if let Some((_, until)) = client.waiting
                && now >= until
            {
                client.tally.lost += 1;
                client.waiting = None;
            }
            if client.waiting.is_none() && client.tally.sent < requests {
                if client.sends_garbage {
                    port.send(&garbage(&mut rng));
                    client.tally.garbage_bursts += 1;
                }
                let data = client.request();
                let end = port.send(&Frame::new(ASK, &data).unwrap().to_bytes());
                client.waiting = Some((data, end + client.deadline_ns));
                client.seq = client.seq.wrapping_add(1);
                client.tally.sent += 1;
            }
            if client.waiting.is_some() {
                busy = true;
                client.tally.done_ns = rig.now_ns - start_ns;
            }
        }
        if !busy {
            break;
        }
        rig.step();
    }
    // Anything arriving after the last answer is a reply nobody asked for.
    rig.run_us(20_000);
    for client in &mut clients {
        let port = rig.client(client.link);
        let fresh: Vec<u8> = port.from_basic[client.read..]
            .iter()
            .map(|&(_, b)| b)
            .collect();
        client.decoder.feed(&fresh, |_| client.tally.wrong += 1);
    }
    (
        clients.iter().map(|c| c.tally).collect(),
        rig.now_ns - start_ns,
    )
}
