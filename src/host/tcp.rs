//! The host protocol over TCP, like the Basic's Wi-Fi server: raw `FE FE .. FA` frames both
//! ways, no extra framing. pymycobot's `MyCobot280Socket` talks to it unchanged.
//!
//! `MyCobot280Socket` reads each answer with a single `recv(1024)` and takes whatever arrives
//! first as the whole reply, so replies are sent as complete frames in one write: the bytes
//! the Basic emits at 115200 baud are collected until a frame is complete, then sent. Several
//! clients may be connected at once (they take turns on the one robot); a client that
//! disconnects or misbehaves is dropped without disturbing the robot or the others.

use std::io::{self, Read, Write};
use std::net::{SocketAddr, TcpListener, TcpStream};
use std::os::fd::{AsFd, BorrowedFd};

use protocol_core::FrameDecoder;

/// How many clients may be connected at once; more are turned away, so a misbehaving script
/// that opens connections in a loop cannot exhaust file descriptors.
pub const MAX_TCP_CLIENTS: usize = 8;

/// Identifies one TCP connection for the lifetime of the server (ids are never reused).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct ClientId(u64);

struct TcpClient {
    id: ClientId,
    stream: TcpStream,
    /// Reassembles the robot's byte-timed reply into whole frames for this client.
    reply_framer: FrameDecoder,
}

/// A non-blocking TCP server for the host protocol.
pub struct TcpServer {
    listener: TcpListener,
    clients: Vec<TcpClient>,
    next_id: u64,
}

impl TcpServer {
    /// Listens on `addr` (port 0 picks a free port: see [`TcpServer::local_addr`]).
    pub fn bind(addr: SocketAddr) -> io::Result<Self> {
        let listener = TcpListener::bind(addr)?;
        listener.set_nonblocking(true)?;
        Ok(Self {
            listener,
            clients: Vec::new(),
            next_id: 0,
        })
    }

    /// The address actually listened on.
    pub fn local_addr(&self) -> io::Result<SocketAddr> {
        self.listener.local_addr()
    }

    /// Descriptors to wait on: the listener, then every connected client.
    pub fn poll_fds(&self) -> impl Iterator<Item = BorrowedFd<'_>> {
        std::iter::once(self.listener.as_fd()).chain(self.clients.iter().map(|c| c.stream.as_fd()))
    }

    /// How many clients are connected.
    pub fn client_count(&self) -> usize {
        self.clients.len()
    }

    /// Accepts every pending connection (turning away those above [`MAX_TCP_CLIENTS`]).
    pub fn accept_pending(&mut self) {
        loop {
            match self.listener.accept() {
                Ok((stream, _peer)) => {
                    if self.clients.len() >= MAX_TCP_CLIENTS {
                        continue; // dropping the stream closes it
                    }
                    if stream.set_nonblocking(true).is_err() {
                        continue;
                    }
                    // Replies are tiny and latency is the point.
                    let _ = stream.set_nodelay(true);
                    self.clients.push(TcpClient {
                        id: ClientId(self.next_id),
                        stream,
                        reply_framer: FrameDecoder::new(),
                    });
                    self.next_id += 1;
                }
                Err(e) if e.kind() == io::ErrorKind::Interrupted => {}
                // WouldBlock: none left. Anything else (e.g. EMFILE) is retried next round.
                Err(_) => return,
            }
        }
    }

    /// Reads up to `budget` bytes of what clients sent, handing them to `on_bytes`; the rest
    /// waits in the kernel (TCP flow control slows the client). Drops clients that closed
    /// their connection or failed.
    pub fn receive(&mut self, mut budget: usize, mut on_bytes: impl FnMut(ClientId, &[u8])) {
        let mut buf = [0u8; 1024];
        self.clients.retain_mut(|client| {
            while let Some(window) = buf.get_mut(..budget.min(1024)).filter(|w| !w.is_empty()) {
                match client.stream.read(window) {
                    Ok(0) => return false,
                    Ok(n) => {
                        budget -= n;
                        on_bytes(client.id, window.get(..n).unwrap_or_default());
                    }
                    Err(e) if e.kind() == io::ErrorKind::Interrupted => {}
                    Err(e) if e.kind() == io::ErrorKind::WouldBlock => return true,
                    Err(_) => return false,
                }
            }
            true
        });
    }

    /// Passes the robot's reply bytes to client `to`, sending each frame once it is complete.
    /// Bytes outside frames are dropped; so is everything for a client that is gone.
    pub fn send_reply_bytes(&mut self, to: ClientId, bytes: &[u8]) {
        let Some(index) = self.clients.iter().position(|c| c.id == to) else {
            return;
        };
        let Some(client) = self.clients.get_mut(index) else {
            return;
        };
        let mut healthy = true;
        let TcpClient {
            stream,
            reply_framer,
            ..
        } = client;
        reply_framer.feed(bytes, |frame| {
            // A client that does not read its replies loses them (WouldBlock) rather than
            // stalling the robot; a broken connection is closed.
            if healthy
                && let Err(e) = stream.write_all(&frame.to_bytes())
                && e.kind() != io::ErrorKind::WouldBlock
            {
                healthy = false;
            }
        });
        if !healthy {
            self.clients.swap_remove(index);
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use std::time::{Duration, Instant};

    fn localhost_server() -> TcpServer {
        TcpServer::bind("127.0.0.1:0".parse().unwrap()).unwrap()
    }

    /// Accepts and reads until `want` bytes arrived from some client (or two seconds passed).
    fn pump(server: &mut TcpServer, want: usize) -> Vec<(ClientId, Vec<u8>)> {
        let deadline = Instant::now() + Duration::from_secs(2);
        let mut got: Vec<(ClientId, Vec<u8>)> = Vec::new();
        while got.iter().map(|(_, b)| b.len()).sum::<usize>() < want && Instant::now() < deadline {
            server.accept_pending();
            server.receive(usize::MAX, |id, bytes| got.push((id, bytes.to_vec())));
            std::thread::sleep(Duration::from_millis(1));
        }
        got
    }

    #[test]
    fn a_reply_trickling_in_byte_by_byte_reaches_the_client_as_one_frame() {
        let mut server = localhost_server();
        let mut client = TcpStream::connect(server.local_addr().unwrap()).unwrap();
        client.write_all(&[0xFE, 0xFE, 0x02, 0x20, 0xFA]).unwrap();
        let got = pump(&mut server, 5);
        let (id, bytes) = got.first().unwrap();
        assert_eq!(bytes, &[0xFE, 0xFE, 0x02, 0x20, 0xFA]);

        let reply = [0xFE, 0xFE, 0x04, 0x20, 0xFE, 0xFA, 0xFA];
        server.send_reply_bytes(*id, &[0x00, 0x55]); // line noise before the frame
        for byte in reply {
            server.send_reply_bytes(*id, &[byte]);
        }
        client
            .set_read_timeout(Some(Duration::from_secs(2)))
            .unwrap();
        let mut buf = [0u8; 64];
        let n = client.read(&mut buf).unwrap();
        assert_eq!(&buf[..n], &reply);
    }

    #[test]
    fn clients_come_and_go_without_disturbing_each_other() {
        let mut server = localhost_server();
        let addr = server.local_addr().unwrap();
        let mut first = TcpStream::connect(addr).unwrap();
        let mut second = TcpStream::connect(addr).unwrap();
        first.write_all(&[1]).unwrap();
        second.write_all(&[2]).unwrap();
        let got = pump(&mut server, 2);
        assert_eq!(server.client_count(), 2);
        let second_id = got.iter().find(|(_, b)| b == &[2]).unwrap().0;

        drop(first);
        let deadline = Instant::now() + Duration::from_secs(2);
        while server.client_count() == 2 && Instant::now() < deadline {
            server.receive(usize::MAX, |_, _| {});
        }
        assert_eq!(server.client_count(), 1);

        server.send_reply_bytes(second_id, &[0xFE, 0xFE, 0x03, 0x10, 0x01, 0xFA]);
        second
            .set_read_timeout(Some(Duration::from_secs(2)))
            .unwrap();
        let mut buf = [0u8; 16];
        let n = second.read(&mut buf).unwrap();
        assert_eq!(&buf[..n], &[0xFE, 0xFE, 0x03, 0x10, 0x01, 0xFA]);
    }
}
