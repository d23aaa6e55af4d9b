//! The host protocol over TCP, like the Basic's Wi-Fi server: raw `FE FE .. FA` frames both
//! ways, no extra framing. pymycobot's `MyCobot280Socket` talks to it unchanged.
//!
//! Each connection is one client with a link of its own on the robot (see
//! [`super::realtime`]): the server only moves bytes. Who is let in, the client limit, each
//! client's buffers and what a leaving client closes are the simulated Basic's, through the
//! firmware library's `firmware_basic::NetworkClients`, the code the board's sockets use. The
//! server asks whether to admit each new connection; one turned away is closed at once, so the
//! client reads end-of-file (`MyCobot280Socket` raises `BrokenPipeError` on its first command).
//! A client that disconnects or fails is dropped without disturbing the robot or the others.

use std::io::{self, Read, Write};
use std::net::{SocketAddr, TcpListener, TcpStream};
use std::os::fd::{AsFd, BorrowedFd};

/// Most bytes taken from one client per read.
const READ_CHUNK: usize = 1024;

/// Identifies one TCP connection for the lifetime of the server (ids are never reused).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct ClientId(u64);

struct TcpClient {
    id: ClientId,
    stream: TcpStream,
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

    /// Listens on `addr` from now on instead (the Basic's port was changed): connections not yet
    /// accepted on the old address are refused, the clients already connected stay. On error
    /// the old address is kept.
    pub fn listen_on(&mut self, addr: SocketAddr) -> io::Result<()> {
        let listener = TcpListener::bind(addr)?;
        listener.set_nonblocking(true)?;
        self.listener = listener;
        Ok(())
    }

    /// The address actually listened on.
    pub fn local_addr(&self) -> io::Result<SocketAddr> {
        self.listener.local_addr()
    }

    /// Descriptors to wait on: the listener, then every connected client for which `watch`
    /// holds (a client whose bytes cannot be taken now is not watched: they would wake the
    /// loop at once).
    pub fn poll_fds(
        &self,
        watch: impl Fn(ClientId) -> bool,
    ) -> impl Iterator<Item = BorrowedFd<'_>> {
        std::iter::once(self.listener.as_fd()).chain(
            self.clients
                .iter()
                .filter(move |c| watch(c.id))
                .map(|c| c.stream.as_fd()),
        )
    }

    /// How many clients are connected.
    pub fn client_count(&self) -> usize {
        self.clients.len()
    }

    /// Accepts every pending connection that `admit` lets in; the others are closed at once.
    pub fn accept_pending(&mut self, mut admit: impl FnMut(ClientId) -> bool) {
        loop {
            match self.listener.accept() {
                Ok((stream, _peer)) => {
                    let id = ClientId(self.next_id);
                    self.next_id += 1;
                    if stream.set_nonblocking(true).is_err() || !admit(id) {
                        continue; // dropping the stream closes it
                    }
                    // Replies are tiny and latency is the point.
                    let _ = stream.set_nodelay(true);
                    self.clients.push(TcpClient { id, stream });
                }
                Err(e) if e.kind() == io::ErrorKind::Interrupted => {}
                // WouldBlock: none left. Anything else (e.g. EMFILE) is retried next round.
                Err(_) => return,
            }
        }
    }

    /// Reads what clients sent, at most `room(id)` bytes from each (the rest waits in the
    /// kernel: TCP flow control slows the client), handing them to `on_bytes`. Clients that
    /// closed their connection or failed are dropped and given to `on_gone`.
    pub fn receive(
        &mut self,
        room: impl Fn(ClientId) -> usize,
        mut on_bytes: impl FnMut(ClientId, &[u8]),
        mut on_gone: impl FnMut(ClientId),
    ) {
        let mut buf = [0u8; READ_CHUNK];
        self.clients.retain_mut(|client| {
            let mut budget = room(client.id);
            while let Some(window) = buf
                .get_mut(..budget.min(READ_CHUNK))
                .filter(|w| !w.is_empty())
            {
                match client.stream.read(window) {
                    Ok(0) => {
                        on_gone(client.id);
                        return false;
                    }
                    Ok(n) => {
                        budget -= n;
                        on_bytes(client.id, window.get(..n).unwrap_or_default());
                    }
                    Err(e) if e.kind() == io::ErrorKind::Interrupted => {}
                    Err(e) if e.kind() == io::ErrorKind::WouldBlock => return true,
                    Err(_) => {
                        on_gone(client.id);
                        return false;
                    }
                }
            }
            true
        });
    }

    /// Sends `bytes` to client `to` in one write (the robot hands over each reply whole, and
    /// `MyCobot280Socket` takes what one `recv` returns as the reply). Dropped for a client
    /// that is gone; a client that does not read its replies loses them rather than stalling
    /// the robot. Returns false if the connection broke (the client is then closed; the next
    /// [`Self::receive`] does not report it again).
    pub fn send(&mut self, to: ClientId, bytes: &[u8]) -> bool {
        let Some(index) = self.clients.iter().position(|c| c.id == to) else {
            return true;
        };
        let Some(client) = self.clients.get_mut(index) else {
            return true;
        };
        match client.stream.write_all(bytes) {
            Err(e) if e.kind() != io::ErrorKind::WouldBlock => {
                self.clients.swap_remove(index);
                false
            }
            _ => true,
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

    /// Accepts everyone and reads until `want` bytes arrived from some client (or two seconds
    /// passed), at most `room` bytes per client per round.
    fn pump(server: &mut TcpServer, want: usize, room: usize) -> Vec<(ClientId, Vec<u8>)> {
        let deadline = Instant::now() + Duration::from_secs(2);
        let mut got: Vec<(ClientId, Vec<u8>)> = Vec::new();
        while got.iter().map(|(_, b)| b.len()).sum::<usize>() < want && Instant::now() < deadline {
            server.accept_pending(|_| true);
            server.receive(|_| room, |id, bytes| got.push((id, bytes.to_vec())), |_| {});
            std::thread::sleep(Duration::from_millis(1));
        }
        got
    }

    #[test]
    fn a_reply_reaches_the_client_in_one_read() {
        let mut server = localhost_server();
        let mut client = TcpStream::connect(server.local_addr().unwrap()).unwrap();
        client.write_all(&[0xFE, 0xFE, 0x02, 0x20, 0xFA]).unwrap();
        let got = pump(&mut server, 5, usize::MAX);
        let (id, bytes) = got.first().unwrap();
        assert_eq!(bytes, &[0xFE, 0xFE, 0x02, 0x20, 0xFA]);

        let reply = [0xFE, 0xFE, 0x04, 0x20, 0xFE, 0xFA, 0xFA];
        assert!(server.send(*id, &reply));
        client
            .set_read_timeout(Some(Duration::from_secs(2)))
            .unwrap();
        let mut buf = [0u8; 64];
        let n = client.read(&mut buf).unwrap();
        assert_eq!(&buf[..n], &reply);
    }

    #[test]
    fn a_client_takes_no_more_than_its_room() {
        let mut server = localhost_server();
        let mut client = TcpStream::connect(server.local_addr().unwrap()).unwrap();
        client.write_all(&[7; 100]).unwrap();
        let got = pump(&mut server, 10, 10);
        assert!(got.iter().all(|(_, b)| b.len() <= 10), "{got:?}");
        let rest = pump(&mut server, 90, 30);
        let total: usize = got.iter().chain(&rest).map(|(_, b)| b.len()).sum();
        assert_eq!(total, 100, "nothing lost: the rest waited in the kernel");
    }

    #[test]
    fn a_client_turned_away_reads_end_of_file() {
        let mut server = localhost_server();
        let mut refused = TcpStream::connect(server.local_addr().unwrap()).unwrap();
        let deadline = Instant::now() + Duration::from_secs(2);
        let mut asked = 0;
        while asked == 0 && Instant::now() < deadline {
            server.accept_pending(|_| {
                asked += 1;
                false
            });
        }
        assert_eq!((asked, server.client_count()), (1, 0));
        refused
            .set_read_timeout(Some(Duration::from_secs(2)))
            .unwrap();
        let mut buf = [0u8; 8];
        assert_eq!(refused.read(&mut buf).unwrap(), 0, "closed at once");
    }

    #[test]
    fn clients_come_and_go_without_disturbing_each_other() {
        let mut server = localhost_server();
        let addr = server.local_addr().unwrap();
        let mut first = TcpStream::connect(addr).unwrap();
        let mut second = TcpStream::connect(addr).unwrap();
        first.write_all(&[1]).unwrap();
        second.write_all(&[2]).unwrap();
        let got = pump(&mut server, 2, usize::MAX);
        assert_eq!(server.client_count(), 2);
        let first_id = got.iter().find(|(_, b)| b == &[1]).unwrap().0;
        let second_id = got.iter().find(|(_, b)| b == &[2]).unwrap().0;

        drop(first);
        let deadline = Instant::now() + Duration::from_secs(2);
        let mut gone = Vec::new();
        while server.client_count() == 2 && Instant::now() < deadline {
            server.receive(|_| usize::MAX, |_, _| {}, |id| gone.push(id));
        }
        assert_eq!(server.client_count(), 1);
        assert_eq!(gone, [first_id]);

        assert!(server.send(second_id, &[0xFE, 0xFE, 0x03, 0x10, 0x01, 0xFA]));
        second
            .set_read_timeout(Some(Duration::from_secs(2)))
            .unwrap();
        let mut buf = [0u8; 16];
        let n = second.read(&mut buf).unwrap();
        assert_eq!(&buf[..n], &[0xFE, 0xFE, 0x03, 0x10, 0x01, 0xFA]);
    }

    #[test]
    fn moving_to_another_port_keeps_the_clients_connected() {
        let mut server = localhost_server();
        let mut first = TcpStream::connect(server.local_addr().unwrap()).unwrap();
        first.write_all(&[1]).unwrap();
        let got = pump(&mut server, 1, usize::MAX);
        let first_id = got[0].0;
        let old = server.local_addr().unwrap();
        server.listen_on("127.0.0.1:0".parse().unwrap()).unwrap();
        let new = server.local_addr().unwrap();
        assert_ne!(old.port(), new.port());
        let mut second = TcpStream::connect(new).unwrap();
        second.write_all(&[2]).unwrap();
        let got = pump(&mut server, 1, usize::MAX);
        assert_eq!(got[0].1, [2]);
        assert_eq!(server.client_count(), 2);
        assert!(server.send(first_id, &[9]));
        first
            .set_read_timeout(Some(Duration::from_secs(2)))
            .unwrap();
        let mut buf = [0u8; 1];
        first.read_exact(&mut buf).unwrap();
        assert_eq!(buf, [9]);
        // A port that cannot be had: the server stays where it is.
        let taken = TcpListener::bind("127.0.0.1:0").unwrap();
        assert!(server.listen_on(taken.local_addr().unwrap()).is_err());
        assert_eq!(server.local_addr().unwrap(), new);
    }
}
