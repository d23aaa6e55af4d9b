//! The view's web server, in threads of its own: the page and its assets, the arm's model
//! (`/model.json`), the state stream (`/state`, a WebSocket that sends every snapshot the
//! simulation publishes as one JSON text message, about 60 a second), and the Basic's buttons
//! (`POST /button/a`, `b` or `c`: one press, queued for the simulation, when the Basic runs a
//! program; answered 204 at once).
//!
//! Requests are parsed by httparse (hyper's HTTP/1.x parser); the WebSocket handshake and
//! framing are tungstenite's. What is left here is routing: each connection carries one
//! request (every response says `Connection: close`), answered with a status line, a few
//! headers and the body. Each connection has a thread; a page's stream thread sleeps on the
//! [`StateBoard`] between snapshots, so a slow or vanished page only ever stalls itself.

use std::io::{self, Read, Write};
use std::net::{Shutdown, SocketAddr, TcpListener, TcpStream};
use std::sync::Arc;
use std::sync::atomic::{AtomicBool, AtomicUsize, Ordering};
use std::thread::{self, JoinHandle};
use std::time::Duration;

use tungstenite::{Bytes, Message, WebSocket};

use super::assets::{self, Asset};
use super::board::StateBoard;
use crate::host::buttons::{Button, PressQueue};

/// Most connections served at once, streams included (each costs a thread); more are closed
/// at once.
pub const MAX_CONNECTIONS: usize = 64;

/// Longest request head accepted (a browser's is well under 2 KiB).
const HEAD_LIMIT: usize = 16 * 1024;
/// Most header lines in a request head.
const MAX_HEADERS: usize = 48;

/// How long a client may take to send its request, or to take a write: then it is dropped.
const IO_TIMEOUT: Duration = Duration::from_secs(5);

/// Longest a stream waits for a snapshot before it pings the page (and so notices a page that
/// went away while the simulation published nothing).
const IDLE_PING: Duration = Duration::from_secs(1);

/// The running web server. Dropping it stops accepting connections and ends the streams.
pub struct WebServer {
    addr: SocketAddr,
    stop: Arc<AtomicBool>,
    acceptor: Option<JoinHandle<()>>,
}

impl WebServer {
    /// Serves the view on `listener`, with the state that `board` receives and the model
    /// `model_json`, until dropped. `presses`: where the view's button presses go when the
    /// Basic runs a program (`None`: no buttons, `POST /button/..` is answered 409).
    pub fn start(
        listener: TcpListener,
        board: Arc<StateBoard>,
        model_json: String,
        presses: Option<PressQueue>,
    ) -> io::Result<Self> {
        let addr = listener.local_addr()?;
        let stop = Arc::new(AtomicBool::new(false));
        let site = Arc::new(Site {
            board,
            model_json,
            presses,
            stop: Arc::clone(&stop),
            connections: AtomicUsize::new(0),
        });
        let acceptor = thread::Builder::new()
            .name("web".into())
            .spawn(move || accept_loop(&listener, &site))?;
        Ok(Self {
            addr,
            stop,
            acceptor: Some(acceptor),
        })
    }

    /// The address the server listens on.
    pub fn local_addr(&self) -> SocketAddr {
        self.addr
    }

    /// The page's address, e.g. `http://127.0.0.1:8280`.
    pub fn url(&self) -> String {
        format!("http://{}", self.addr)
    }
}

impl Drop for WebServer {
    fn drop(&mut self) {
        self.stop.store(true, Ordering::Relaxed);
        // Wake the acceptor blocked in accept().
        let _ = TcpStream::connect_timeout(&self.addr, IO_TIMEOUT);
        if let Some(acceptor) = self.acceptor.take() {
            let _ = acceptor.join();
        }
    }
}

/// What the connection threads share.
struct Site {
    board: Arc<StateBoard>,
    model_json: String,
    presses: Option<PressQueue>,
    stop: Arc<AtomicBool>,
    connections: AtomicUsize,
}

fn accept_loop(listener: &TcpListener, site: &Arc<Site>) {
    for stream in listener.incoming() {
        if site.stop.load(Ordering::Relaxed) {
            return;
        }
        let Ok(stream) = stream else { continue };
        if site.connections.fetch_add(1, Ordering::Relaxed) >= MAX_CONNECTIONS {
            site.connections.fetch_sub(1, Ordering::Relaxed);
            continue; // dropped: closed at once
        }
        let site_for_thread = Arc::clone(site);
        let spawned = thread::Builder::new()
            .name("web-connection".into())
            .spawn(move || {
                let _ = site_for_thread.serve(stream);
                site_for_thread.connections.fetch_sub(1, Ordering::Relaxed);
            });
        if spawned.is_err() {
            site.connections.fetch_sub(1, Ordering::Relaxed);
        }
    }
}

/// What a request asks for.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
enum Route {
    /// A file of the page.
    Asset(&'static Asset),
    /// The DH table.
    Model,
    /// The state stream (a WebSocket upgrade).
    Stream,
    /// `/state` without the upgrade.
    NotAWebSocket,
    /// `POST /button/a` (`b`, `c`): press one of the Basic's buttons.
    Button(Button),
    /// A method the path does not take: the one it takes.
    MethodNotAllowed(&'static str),
    /// No such path.
    NotFound,
}

/// Routes a request by its method, path (a query string does not select anything) and
/// whether it asks for a WebSocket.
fn route(method: &str, target: &str, websocket: bool) -> Route {
    let path = target.split('?').next().unwrap_or_default();
    if let Some(name) = path.strip_prefix("/button/") {
        let mut letters = name.chars();
        let button = match (letters.next(), letters.next()) {
            (Some(letter), None) if letter.is_ascii_lowercase() => Button::from_letter(letter),
            _ => None,
        };
        return match (method, button) {
            (_, None) => Route::NotFound,
            ("POST", Some(button)) => Route::Button(button),
            _ => Route::MethodNotAllowed("POST"),
        };
    }
    match (method, path) {
        ("GET", "/state") if websocket => Route::Stream,
        ("GET", "/state") => Route::NotAWebSocket,
        ("GET", "/model.json") => Route::Model,
        ("GET", path) => assets::find(path).map_or(Route::NotFound, Route::Asset),
        _ => Route::MethodNotAllowed("GET"),
    }
}

impl Site {
    /// Serves the one request of a connection.
    fn serve(&self, stream: TcpStream) -> io::Result<()> {
        stream.set_read_timeout(Some(IO_TIMEOUT))?;
        stream.set_write_timeout(Some(IO_TIMEOUT))?;
        let (head, request) = match read_head(&stream) {
            Ok(read) => read,
            Err(e) if e.kind() == io::ErrorKind::InvalidData => {
                return respond(stream, 400, "text/plain", b"bad request");
            }
            Err(e) => return Err(e),
        };
        match route(&request.method, &request.target, request.websocket) {
            Route::Stream => {
                // tungstenite reads the request again (from `head`) and answers the handshake.
                let replay = Replay {
                    head: io::Cursor::new(head),
                    stream,
                };
                let socket =
                    tungstenite::accept(replay).map_err(|e| io::Error::other(e.to_string()))?;
                self.stream(socket);
                Ok(())
            }
            Route::Model => respond(stream, 200, "application/json", self.model_json.as_bytes()),
            Route::Asset(asset) => respond(stream, 200, asset.content_type, asset.body),
            Route::NotAWebSocket => respond(
                stream,
                400,
                "text/plain",
                b"the state stream is a WebSocket",
            ),
            Route::Button(button) => self.press(stream, button, &request),
            Route::MethodNotAllowed(allowed) => {
                let only = format!("{allowed} only");
                respond(stream, 405, "text/plain", only.as_bytes())
            }
            Route::NotFound => respond(stream, 404, "text/plain", b"not found"),
        }
    }

    /// Queues a press of `button` for the Basic's program, if it runs one. A request a page of
    /// another site sent (its `Origin` is not this server) is refused: only the view presses.
    fn press(&self, stream: TcpStream, button: Button, request: &RequestHead) -> io::Result<()> {
        if !request.same_origin() {
            return respond(
                stream,
                403,
                "text/plain",
                b"only the view's page presses buttons",
            );
        }
        let Some(presses) = &self.presses else {
            return respond(
                stream,
                409,
                "text/plain",
                b"the Basic runs no program (--basic-program)",
            );
        };
        if presses.push(button) {
            respond(stream, 204, "text/plain", b"")
        } else {
            respond(stream, 503, "text/plain", b"too many presses waiting")
        }
    }

    /// Sends each new snapshot until the page goes away or the server stops.
    fn stream<S: Read + Write>(&self, mut socket: WebSocket<S>) {
        let mut seen = 0;
        while !self.stop.load(Ordering::Relaxed) {
            let sent = match self.board.newer_than(seen, IDLE_PING) {
                Some((seq, snapshot)) => {
                    seen = seq;
                    socket.send(Message::text(snapshot.to_json()))
                }
                None => socket.send(Message::Ping(Bytes::new())),
            };
            if sent.is_err() {
                return;
            }
        }
        let _ = socket.close(None);
        let _ = socket.flush();
    }
}

/// The parts of a request head that select the answer.
#[derive(Debug)]
struct RequestHead {
    method: String,
    target: String,
    /// `Upgrade: websocket` is present.
    websocket: bool,
    /// The `Host` header, if any.
    host: Option<String>,
    /// The `Origin` header, if any (a browser sends it with every POST).
    origin: Option<String>,
}

impl RequestHead {
    /// Whether the request comes from this server's own page, or from no page at all (a
    /// client that is not a browser sends no `Origin`): not from another site's page.
    fn same_origin(&self) -> bool {
        match (&self.origin, &self.host) {
            (None, _) => true,
            (Some(origin), Some(host)) => origin
                .strip_prefix("http://")
                .is_some_and(|origin_host| origin_host.eq_ignore_ascii_case(host)),
            (Some(_), None) => false,
        }
    }
}

/// Reads until a complete request head has arrived (at most [`HEAD_LIMIT`] bytes); returns
/// the bytes read and the parsed head. A malformed or oversized head is `InvalidData`.
fn read_head(mut stream: &TcpStream) -> io::Result<(Vec<u8>, RequestHead)> {
    let mut buf = Vec::with_capacity(1024);
    let mut chunk = [0u8; 2048];
    loop {
        let n = stream.read(&mut chunk)?;
        if n == 0 {
            return Err(io::ErrorKind::UnexpectedEof.into());
        }
        buf.extend_from_slice(chunk.get(..n).unwrap_or_default());
        let mut headers = [httparse::EMPTY_HEADER; MAX_HEADERS];
        let mut request = httparse::Request::new(&mut headers);
        match request.parse(&buf) {
            Ok(httparse::Status::Complete(_)) => {
                let websocket = request.headers.iter().any(|h| {
                    h.name.eq_ignore_ascii_case("upgrade")
                        && h.value.eq_ignore_ascii_case(b"websocket")
                });
                let header = |name: &str| {
                    request
                        .headers
                        .iter()
                        .find(|h| h.name.eq_ignore_ascii_case(name))
                        .map(|h| String::from_utf8_lossy(h.value).into_owned())
                };
                let head = RequestHead {
                    method: request.method.unwrap_or_default().to_string(),
                    target: request.path.unwrap_or_default().to_string(),
                    websocket,
                    host: header("host"),
                    origin: header("origin"),
                };
                return Ok((buf, head));
            }
            Ok(httparse::Status::Partial) if buf.len() < HEAD_LIMIT => {}
            Ok(httparse::Status::Partial) => {
                return Err(io::Error::new(io::ErrorKind::InvalidData, "head too long"));
            }
            Err(e) => return Err(io::Error::new(io::ErrorKind::InvalidData, e)),
        }
    }
}

/// Answers with `status` and `body`, then closes the connection.
fn respond(mut stream: TcpStream, status: u16, content_type: &str, body: &[u8]) -> io::Result<()> {
    let reason = match status {
        200 => "OK",
        204 => "No Content",
        400 => "Bad Request",
        403 => "Forbidden",
        404 => "Not Found",
        405 => "Method Not Allowed",
        409 => "Conflict",
        503 => "Service Unavailable",
        _ => "",
    };
    // A 204 has no body, so says nothing about one.
    let content = if status == 204 {
        String::new()
    } else {
        format!(
            "Content-Type: {content_type}\r\nContent-Length: {}\r\n",
            body.len()
        )
    };
    let head = format!(
        "HTTP/1.1 {status} {reason}\r\n{content}Cache-Control: no-cache\r\n\
         Connection: close\r\n\r\n"
    );
    stream.write_all(head.as_bytes())?;
    stream.write_all(body)?;
    stream.flush()?;
    let _ = stream.shutdown(Shutdown::Write);
    // Let the client read the answer and close first, so the close is clean.
    let _ = stream.read(&mut [0u8; 64]);
    Ok(())
}

/// A connection whose request head was already read: reads give the head again, then the
/// connection; writes go to the connection.
struct Replay {
    head: io::Cursor<Vec<u8>>,
    stream: TcpStream,
}

impl Read for Replay {
    fn read(&mut self, buf: &mut [u8]) -> io::Result<usize> {
        match self.head.read(buf)? {
            0 => self.stream.read(buf),
            n => Ok(n),
        }
    }
}

impl Write for Replay {
    fn write(&mut self, buf: &[u8]) -> io::Result<usize> {
        self.stream.write(buf)
    }
    fn flush(&mut self) -> io::Result<()> {
        self.stream.flush()
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::sim::{RobotConfig, VirtualRobot};
    use crate::web::snapshot::Snapshot;

    fn serve() -> (WebServer, Arc<StateBoard>) {
        serve_with(None)
    }

    fn serve_with(presses: Option<PressQueue>) -> (WebServer, Arc<StateBoard>) {
        let board = Arc::new(StateBoard::new());
        let listener = TcpListener::bind("127.0.0.1:0").unwrap();
        let model = "{\"d_mm\":[]}".into();
        let server = WebServer::start(listener, Arc::clone(&board), model, presses).unwrap();
        (server, board)
    }

    fn send(addr: SocketAddr, request: &str) -> String {
        let mut stream = TcpStream::connect(addr).unwrap();
        stream.write_all(request.as_bytes()).unwrap();
        let mut reply = Vec::new();
        stream.read_to_end(&mut reply).unwrap();
        String::from_utf8_lossy(&reply).into_owned()
    }

    fn get(addr: SocketAddr, path: &str) -> String {
        send(addr, &format!("GET {path} HTTP/1.1\r\nHost: x\r\n\r\n"))
    }

    #[test]
    fn routes_by_method_path_and_upgrade() {
        assert!(matches!(route("GET", "/", false), Route::Asset(a) if a.path == "/"));
        assert!(
            matches!(route("GET", "/view.js?v=2", false), Route::Asset(a) if a.path == "/view.js")
        );
        assert_eq!(route("GET", "/model.json", false), Route::Model);
        assert_eq!(route("GET", "/state", true), Route::Stream);
        assert_eq!(route("GET", "/state", false), Route::NotAWebSocket);
        assert_eq!(route("POST", "/", false), Route::MethodNotAllowed("GET"));
        assert_eq!(route("GET", "/../etc/passwd", false), Route::NotFound);
        assert_eq!(route("POST", "/button/a", false), Route::Button(Button::A));
        assert_eq!(
            route("POST", "/button/b?x=1", false),
            Route::Button(Button::B)
        );
        assert_eq!(route("POST", "/button/c", false), Route::Button(Button::C));
        assert_eq!(
            route("GET", "/button/a", false),
            Route::MethodNotAllowed("POST")
        );
        assert_eq!(
            route("PUT", "/button/c", false),
            Route::MethodNotAllowed("POST")
        );
        for other in [
            "/button/d",
            "/button/A",
            "/button/ab",
            "/button/",
            "/button/a/b",
        ] {
            assert_eq!(route("POST", other, false), Route::NotFound, "{other}");
        }
    }

    fn post(addr: SocketAddr, path: &str, origin: Option<&str>) -> String {
        let origin = origin.map_or(String::new(), |o| format!("Origin: {o}\r\n"));
        send(
            addr,
            &format!("POST {path} HTTP/1.1\r\nHost: {addr}\r\n{origin}Content-Length: 0\r\n\r\n"),
        )
    }

    #[test]
    fn a_posted_button_is_queued_for_the_program_and_other_letters_are_not_found() {
        let presses = PressQueue::new();
        let (server, _) = serve_with(Some(presses.clone()));
        let addr = server.local_addr();
        let page = format!("http://{addr}");
        let pressed = post(addr, "/button/a", Some(&page));
        assert!(
            pressed.starts_with("HTTP/1.1 204 No Content\r\n"),
            "{pressed}"
        );
        assert!(!pressed.contains("Content-Length"), "{pressed}");
        assert!(post(addr, "/button/c", None).starts_with("HTTP/1.1 204"));
        assert!(post(addr, "/button/x", Some(&page)).starts_with("HTTP/1.1 404"));
        assert!(get(addr, "/button/b").starts_with("HTTP/1.1 405"));
        let elsewhere = post(addr, "/button/b", Some("http://evil.example"));
        assert!(elsewhere.starts_with("HTTP/1.1 403"), "{elsewhere}");

        let mut presser = crate::host::buttons::Presser::new(presses);
        let mut buttons = firmware_basic::Buttons::default();
        presser.apply(0, &mut buttons);
        assert_eq!(presser.holding(), Some(Button::A));
        presser.apply(1_000_000, &mut buttons);
        presser.apply(2_000_000, &mut buttons);
        assert_eq!(
            presser.holding(),
            Some(Button::C),
            "A, then C; B was refused"
        );
        presser.apply(3_000_000, &mut buttons);
        presser.apply(4_000_000, &mut buttons);
        assert_eq!(presser.holding(), None);
    }

    #[test]
    fn without_a_program_a_button_is_a_conflict() {
        let (server, _) = serve();
        let addr = server.local_addr();
        let refused = post(addr, "/button/a", None);
        assert!(refused.starts_with("HTTP/1.1 409"), "{refused}");
        assert!(refused.ends_with("--basic-program)"), "{refused}");
    }

    #[test]
    fn serves_the_page_the_model_and_clear_errors() {
        let (server, _) = serve();
        let addr = server.local_addr();
        let page = get(addr, "/");
        assert!(page.starts_with("HTTP/1.1 200 OK\r\n"), "{page}");
        assert!(page.contains("Content-Type: text/html") && page.contains("<canvas"));
        assert!(page.contains("Connection: close"));
        let model = get(addr, "/model.json");
        assert!(model.contains("application/json") && model.ends_with("{\"d_mm\":[]}"));
        assert!(get(addr, "/nope").starts_with("HTTP/1.1 404"));
        assert!(get(addr, "/state").starts_with("HTTP/1.1 400"));
        assert!(send(addr, "DELETE / HTTP/1.1\r\n\r\n").starts_with("HTTP/1.1 405"));
        assert!(send(addr, "not http at all\r\n\r\n").starts_with("HTTP/1.1 400"));
        let huge = format!("GET / HTTP/1.1\r\nX: {}\r\n", "a".repeat(HEAD_LIMIT));
        assert!(send(addr, &huge).starts_with("HTTP/1.1 400"));
    }

    #[test]
    fn a_head_that_arrives_in_pieces_is_served() {
        let (server, _) = serve();
        let mut stream = TcpStream::connect(server.local_addr()).unwrap();
        for piece in ["GET /model", ".json HTTP/1.1\r\n", "Host: x\r\n\r\n"] {
            stream.write_all(piece.as_bytes()).unwrap();
            thread::sleep(Duration::from_millis(20));
        }
        let mut reply = String::new();
        stream.read_to_string(&mut reply).unwrap();
        assert!(reply.starts_with("HTTP/1.1 200"), "{reply}");
    }

    #[test]
    fn every_open_page_gets_the_snapshots_as_json() {
        let (server, board) = serve();
        let url = format!("ws://{}/state", server.local_addr());
        let mut pages: Vec<_> = (0..3)
            .map(|_| tungstenite::connect(&url).unwrap().0)
            .collect();
        let mut robot = VirtualRobot::new(RobotConfig::default());
        for page in &mut pages {
            // Publish until this page has one (it may have connected after the last one).
            let text = loop {
                robot.run_for(16_000);
                board.publish(Snapshot::of(&robot));
                match page.read().unwrap() {
                    Message::Text(text) => break text,
                    Message::Ping(_) => continue,
                    other => panic!("unexpected {other:?}"),
                }
            };
            let value: serde_json::Value = serde_json::from_str(text.as_str()).unwrap();
            let angles: Vec<f64> = value["angles_deg"]
                .as_array()
                .unwrap()
                .iter()
                .filter_map(serde_json::Value::as_f64)
                .collect();
            assert_eq!(angles, [0.0; 6]);
            assert!(value["t_s"].as_f64().unwrap() > 0.0);
        }
        // A page that closes does not disturb the others.
        let mut closed = pages.pop().unwrap();
        closed.close(None).unwrap();
        drop(closed);
        robot.run_for(16_000);
        board.publish(Snapshot::of(&robot));
        for page in &mut pages {
            assert!(matches!(page.read().unwrap(), Message::Text(_)));
        }
    }

    #[test]
    fn an_idle_stream_pings_and_dropping_the_server_ends_it() {
        let (server, _board) = serve();
        let url = format!("ws://{}/state", server.local_addr());
        let (mut page, _) = tungstenite::connect(&url).unwrap();
        assert!(matches!(page.read().unwrap(), Message::Ping(_)));
        drop(server);
        let ended =
            (0..10).any(|_| !matches!(page.read(), Ok(Message::Ping(_) | Message::Pong(_))));
        assert!(ended, "the stream ends after the server is dropped");
    }
}
