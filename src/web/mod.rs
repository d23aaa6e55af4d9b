//! The live 3D view of the virtual robot in a browser (`view on http://127.0.0.1:8280`).
//!
//! The simulation loop hands a small [`Snapshot`] of the arm to a [`StateBoard`] every
//! [`PUBLISH_PERIOD`] without ever waiting; the [`WebServer`], in threads of its own, serves
//! the page and streams each snapshot to every open page over a WebSocket. The page draws the
//! arm with three.js from kinematics-core's DH table (served as `/model.json`), so what is
//! drawn is the model the firmware computes with.
//!
//! * [`snapshot`]: what the view shows and its JSON;
//! * [`board`]: the hand-over between the simulation and the web threads;
//! * [`server`]: HTTP, the assets and the WebSocket stream;
//! * [`assets`]: the page and the vendored three.js, compiled into the binary.

pub mod assets;
pub mod board;
pub mod server;
pub mod snapshot;

use std::io;
use std::net::{SocketAddr, TcpListener};
use std::time::Duration;

pub use board::StateBoard;
pub use server::WebServer;
pub use snapshot::{CollisionMark, Snapshot};

/// Where the view is served unless `--web` says otherwise.
pub const DEFAULT_ADDR: SocketAddr =
    SocketAddr::new(std::net::IpAddr::V4(std::net::Ipv4Addr::LOCALHOST), 8280);

/// How often the simulation publishes a snapshot: 16 ms, about 60 a second, one per frame of
/// a 60 Hz display.
pub const PUBLISH_PERIOD: Duration = Duration::from_millis(16);

/// Where the view is listening, and whether that is not where it was asked to.
#[derive(Debug)]
pub struct Listening {
    /// The bound socket.
    pub listener: TcpListener,
    /// Set when the default address was taken and a free port was used instead: the address
    /// that was in use.
    pub default_taken: Option<SocketAddr>,
}

/// Binds the view's address. An address the user chose (`--web`) must be free: a busy one is
/// an error, as with `--tcp`. The default one may be taken (most likely by another virtual
/// robot); then the view moves to a free port on the same interface rather than stopping a
/// robot from starting over its view, and [`Listening::default_taken`] says so.
pub fn listen(chosen: Option<SocketAddr>) -> io::Result<Listening> {
    match chosen {
        Some(addr) => Ok(Listening {
            listener: TcpListener::bind(addr)?,
            default_taken: None,
        }),
        None => match TcpListener::bind(DEFAULT_ADDR) {
            Ok(listener) => Ok(Listening {
                listener,
                default_taken: None,
            }),
            Err(e) if e.kind() == io::ErrorKind::AddrInUse => Ok(Listening {
                listener: TcpListener::bind(SocketAddr::new(DEFAULT_ADDR.ip(), 0))?,
                default_taken: Some(DEFAULT_ADDR),
            }),
            Err(e) => Err(e),
        },
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_chosen_busy_address_is_an_error_and_port_zero_picks_one() {
        let taken = TcpListener::bind("127.0.0.1:0").unwrap();
        let addr = taken.local_addr().unwrap();
        let err = listen(Some(addr)).unwrap_err();
        assert_eq!(err.kind(), io::ErrorKind::AddrInUse);
        let any = listen(Some("127.0.0.1:0".parse().unwrap())).unwrap();
        assert_ne!(any.listener.local_addr().unwrap().port(), 0);
        assert!(any.default_taken.is_none());
    }
}
