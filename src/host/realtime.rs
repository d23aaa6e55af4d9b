//! Runs the virtual robot in real time and connects it to the host's clients.
//!
//! One loop, no threads: wait for a client's bytes (`ppoll`, so input wakes it at once) or the
//! next tick, advance the robot's virtual time to the wall clock, hand it the input, and pass
//! what the robot sent back to its clients. The pseudo-terminal is the robot's serial line;
//! each TCP client is a network client of the Basic with a host link of its own, so every
//! client gets its own answers (the Basic's router serves them in turn and refuses clients
//! beyond its limit: their connection is closed at once). With
//! [`RealtimeDriver::follow_server_port`] the TCP server moves to the port the Basic's Wi-Fi
//! settings name, as the board's sockets do. While clients are talking the tick
//! is [`ACTIVE_TICK`], and while a reply is on the simulated 115200 baud wire the loop wakes
//! when each of its bytes arrives ([`RealtimeRobot::next_output_us`], with a timer slack of
//! [`TIMER_SLACK_NS`]), so a reply byte reaches the client as soon as the wire has carried it
//! (the wire itself takes 87 us per byte, 1.5 ms for a `get_angles` reply); when the line has
//! been quiet for [`ACTIVE_SPELL`] the loop ticks at [`IDLE_TICK`] and costs almost no CPU.

use std::io;
use std::net::{IpAddr, SocketAddr};
use std::os::fd::BorrowedFd;
use std::sync::Arc;
use std::sync::atomic::{AtomicBool, Ordering};
use std::time::{Duration, Instant};

use nix::poll::{PollFd, PollFlags, ppoll};
use nix::sys::time::TimeSpec;

use protocol_core::timing::HOST_BAUD;

use crate::sim::{HostLink, VirtualRobot};

use super::tcp::ClientId;

use super::pacer::{LinePacer, WINDOW_BYTES};
use super::pty::PseudoTerminal;
use super::tcp::TcpServer;

/// The longest the loop sleeps between two advances of virtual time while clients talk.
pub const ACTIVE_TICK: Duration = Duration::from_micros(50);

/// The timer slack of the loop's thread: how late the kernel may end its sleeps, in ns (its
/// default is 50 us, which would hold back every reply byte by up to that much).
pub const TIMER_SLACK_NS: std::ffi::c_ulong = 1_000;

/// The longest the loop sleeps when the line is quiet (input still wakes it at once).
pub const IDLE_TICK: Duration = Duration::from_millis(5);

/// How long after the last byte in either direction the loop keeps the short tick: longer
/// than any reply takes to start (the firmware answers within a few milliseconds).
pub const ACTIVE_SPELL: Duration = Duration::from_millis(50);

/// If the simulation falls this far behind the wall clock (a slow or overloaded machine, a
/// stopped process), the debt is forgiven instead of fast-forwarding the arm in one jump: the
/// robot runs late, as a real arm looks to a client whose bytes and answers are held up, and
/// never makes up the time by moving faster than it can. What was forgiven is counted
/// ([`Lateness`]).
pub const MAX_CATCH_UP: Duration = Duration::from_millis(50);

/// How often at most the loop says on stderr that it ran late.
pub const LATE_REPORT_PERIOD: Duration = Duration::from_secs(1);

/// How late the robot ran behind the wall clock because the machine could not keep up: the
/// time forgiven beyond [`MAX_CATCH_UP`], counted since the start.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct Lateness {
    /// Wall time the robot's virtual time fell behind in all, microseconds.
    pub total_us: u64,
    /// How many times it fell behind.
    pub stalls: u32,
    /// The most it fell behind at once, microseconds.
    pub worst_us: u64,
}

impl Lateness {
    /// Notes that `behind_us` of wall time was not run.
    fn fell_behind(&mut self, behind_us: u64) {
        self.total_us = self.total_us.saturating_add(behind_us);
        self.stalls = self.stalls.saturating_add(1);
        self.worst_us = self.worst_us.max(behind_us);
    }
}

impl std::fmt::Display for Lateness {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        write!(
            f,
            "{:.1} ms in {} stalls, the worst {:.1} ms",
            self.total_us as f64 / 1e3,
            self.stalls,
            self.worst_us as f64 / 1e3
        )
    }
}

/// The robot as the front end sees it: the host end of one serial line, network clients with
/// a link each, and time.
pub trait RealtimeRobot {
    /// Virtual time, microseconds since the robot started.
    fn now_us(&self) -> u64;
    /// Bytes from the host into the robot (they travel the simulated 115200 baud line).
    fn host_write(&mut self, bytes: &[u8]);
    /// Appends what the robot sent to the host so far.
    fn host_read(&mut self, out: &mut Vec<u8>);
    /// Advances virtual time to `t_us`.
    fn run_until(&mut self, t_us: u64);
    /// A network client connects (a TCP client, like one of the Basic's Wi-Fi server): the
    /// link it gets, or `None` to turn it away. The default serves no network clients.
    fn connect(&mut self) -> Option<HostLink> {
        None
    }
    /// The network client on `link` has gone.
    fn disconnect(&mut self, _link: HostLink) {}
    /// How many bytes the network client on `link` may send now.
    fn link_room(&self, _link: HostLink) -> usize {
        0
    }
    /// Bytes from the network client on `link` into the robot.
    fn link_write(&mut self, _link: HostLink, _bytes: &[u8]) {}
    /// Appends what the robot sent to the network client on `link` so far.
    fn link_read(&mut self, _link: HostLink, _out: &mut Vec<u8>) {}
    /// The TCP port the robot's Basic serves its network clients on (its Wi-Fi settings, which
    /// 0xB2 `set_server_port` changes); `None` without one.
    fn server_port(&self) -> Option<u16> {
        None
    }
    /// Descriptors besides the clients' whose input must wake the loop at once (the sockets of
    /// emulated boards). The default has none.
    fn wake_fds(&self) -> Vec<BorrowedFd<'_>> {
        Vec::new()
    }
    /// Whether something is under way inside the robot that needs the short tick even while no
    /// client talks (bytes on an emulated board's bus). The default: never.
    fn busy(&self) -> bool {
        false
    }
    /// When (virtual time, us) the next byte on its way to the serial client arrives, if one is
    /// on the wire: the loop wakes then to pass it on, instead of a tick later. The default:
    /// never known.
    fn next_output_us(&self) -> Option<u64> {
        None
    }
}

/// The virtual robot served on one of its USB ports.
pub struct ServedRobot {
    /// The robot.
    pub robot: VirtualRobot,
    /// Which board's USB serial the clients talk to.
    pub link: HostLink,
}

impl RealtimeRobot for ServedRobot {
    fn now_us(&self) -> u64 {
        self.robot.now_us()
    }
    fn host_write(&mut self, bytes: &[u8]) {
        self.robot.link_write(self.link, bytes);
    }
    fn host_read(&mut self, out: &mut Vec<u8>) {
        self.robot.link_read(self.link, out);
    }
    fn run_until(&mut self, t_us: u64) {
        self.robot.run_until(t_us);
    }
    fn connect(&mut self) -> Option<HostLink> {
        self.robot.connect()
    }
    fn disconnect(&mut self, link: HostLink) {
        self.robot.disconnect(link);
    }
    fn link_room(&self, link: HostLink) -> usize {
        self.robot.link_room(link)
    }
    fn link_write(&mut self, link: HostLink, bytes: &[u8]) {
        self.robot.link_write(link, bytes);
    }
    fn link_read(&mut self, link: HostLink, out: &mut Vec<u8>) {
        self.robot.link_read(link, out);
    }
    fn server_port(&self) -> Option<u16> {
        Some(self.robot.basic()?.wifi()?.settings().port())
    }
    fn next_output_us(&self) -> Option<u64> {
        self.robot
            .link_next_arrival_ns(self.link)
            .map(|ns| ns.div_ceil(1_000))
    }
}

/// Something that looks at the robot now and then from inside the loop (the web view takes its
/// snapshot). It runs on the loop's thread, so it must be quick and must never wait.
struct Observer<R> {
    period: Duration,
    next: Instant,
    look: Look<R>,
}

/// What an [`Observer`] does when it looks: sees the robot and how late it has run.
type Look<R> = Box<dyn FnMut(&R, &Lateness) + Send>;

/// What runs on every pass of the loop with the robot in hand ([`RealtimeDriver::each_pass`]).
type Pass<R> = Box<dyn FnMut(&mut R) + Send>;

impl<R> Observer<R> {
    /// Looks if it is time; keeps a steady rate, but never makes up for missed turns.
    fn look_if_due(&mut self, robot: &R, late: &Lateness) {
        let now = Instant::now();
        if now >= self.next {
            (self.look)(robot, late);
            self.next = (self.next + self.period).max(now);
        }
    }
}

/// Where the TCP server listens when it follows the Basic's server port, and who is told when
/// it moves.
struct FollowPort {
    ip: IpAddr,
    /// The port last tried and not had (not tried again until the Basic's port changes).
    refused: Option<u16>,
    moved: Box<dyn FnMut(io::Result<SocketAddr>) + Send>,
}

/// The real-time loop: a robot, its pseudo-terminal and optionally a TCP server.
pub struct RealtimeDriver<R> {
    robot: R,
    pty: PseudoTerminal,
    tcp: Option<TcpServer>,
    follow: Option<FollowPort>,
    /// The robot's link for each TCP client.
    tcp_links: Vec<(ClientId, HostLink)>,
    pacer: LinePacer,
    observer: Option<Observer<R>>,
    each_pass: Option<Pass<R>>,
    late: Lateness,
    /// Told how late the robot ran, at most every [`LATE_REPORT_PERIOD`] while it runs late.
    report_late: Box<dyn FnMut(&Lateness) + Send>,
}

impl<R: RealtimeRobot> RealtimeDriver<R> {
    /// Connects `robot` to `pty` and, if given, `tcp`.
    pub fn new(robot: R, pty: PseudoTerminal, tcp: Option<TcpServer>) -> Self {
        Self {
            robot,
            pty,
            tcp,
            follow: None,
            tcp_links: Vec::new(),
            pacer: LinePacer::new(HOST_BAUD, WINDOW_BYTES),
            observer: None,
            each_pass: None,
            late: Lateness::default(),
            report_late: Box::new(|late| {
                eprintln!("open-mycobot: the machine is too busy, the robot ran late: {late}");
            }),
        }
    }

    /// How late the robot has run so far (see [`Lateness`]).
    pub fn lateness(&self) -> Lateness {
        self.late
    }

    /// Replaces what the loop does when the robot ran late (by default a line on stderr, at
    /// most every [`LATE_REPORT_PERIOD`]).
    pub fn on_late(mut self, report: impl FnMut(&Lateness) + Send + 'static) -> Self {
        self.report_late = Box::new(report);
        self
    }

    /// Calls `look` with the robot and how late it has run about every `period` of wall time
    /// (not more often; later if the loop is busy), after virtual time has caught up. `look`
    /// runs on the loop's thread: it must be quick and never wait, or the robot's answers are
    /// late.
    pub fn observe_every(
        mut self,
        period: Duration,
        look: impl FnMut(&R, &Lateness) + Send + 'static,
    ) -> Self {
        self.observer = Some(Observer {
            period,
            next: Instant::now(),
            look: Box::new(look),
        });
        self
    }

    /// Calls `pass` with the robot on every pass of the loop, right after virtual time has
    /// caught up with the wall clock and before the clients' bytes are handed over: to act on
    /// the robot from outside at the virtual time it has reached (the Basic's buttons pressed
    /// from the keyboard or the view). A pass comes at least every [`IDLE_TICK`]; `pass` runs
    /// on the loop's thread, so it must be quick and never wait.
    pub fn each_pass(mut self, pass: impl FnMut(&mut R) + Send + 'static) -> Self {
        self.each_pass = Some(Box::new(pass));
        self
    }

    /// Makes the TCP server listen on `ip` at the Basic's server port
    /// ([`RealtimeRobot::server_port`]) and move when a client changes it (0xB2), like the
    /// board: new connections go to the new port, the clients connected stay. `moved` is told
    /// the new address, or why the port could not be had (the server then stays where it is).
    pub fn follow_server_port(
        mut self,
        ip: IpAddr,
        moved: impl FnMut(io::Result<SocketAddr>) + Send + 'static,
    ) -> Self {
        self.follow = Some(FollowPort {
            ip,
            refused: None,
            moved: Box::new(moved),
        });
        self
    }

    /// The pseudo-terminal clients open.
    pub fn pty(&self) -> &PseudoTerminal {
        &self.pty
    }

    /// Runs until `stop` is set (by a signal handler), then returns the robot.
    pub fn run(mut self, stop: &AtomicBool) -> io::Result<R> {
        // Virtual time = virtual_at_sync + wall time since wall_sync.
        let mut wall_sync = Instant::now();
        let mut virtual_at_sync = self.robot.now_us();
        let mut last_traffic: Option<Instant> = None;
        let mut reported = Lateness::default();
        let mut next_report = Instant::now();
        let mut input = [0u8; 4096];
        let mut output = Vec::with_capacity(256);
        // Sleeps end when asked, not up to the kernel's default 50 us later: a reply byte is
        // passed on when it arrives (Linux; elsewhere the kernel's own slack applies).
        #[cfg(any(target_os = "linux", target_os = "android"))]
        let _ = nix::sys::prctl::set_timerslack(TIMER_SLACK_NS);
        while !stop.load(Ordering::Relaxed) {
            let active =
                self.robot.busy() || last_traffic.is_some_and(|t| t.elapsed() < ACTIVE_SPELL);
            let line_full = self.pacer.room(self.robot.now_us().saturating_mul(1_000)) == 0;
            let mut tick = if active { ACTIVE_TICK } else { IDLE_TICK };
            if let Some(arrival_us) = self.robot.next_output_us() {
                // Wake when the next reply byte arrives (virtual time runs with the wall clock
                // from the last sync).
                let due =
                    wall_sync + Duration::from_micros(arrival_us.saturating_sub(virtual_at_sync));
                tick = tick.min(due.saturating_duration_since(Instant::now()));
            }
            self.wait_for_input(tick, !line_full)?;

            let mut target_us = virtual_at_sync.saturating_add(micros(wall_sync.elapsed()));
            let furthest_us = self.robot.now_us() + micros(MAX_CATCH_UP);
            if target_us > furthest_us {
                self.late.fell_behind(target_us - furthest_us);
                target_us = furthest_us;
                wall_sync = Instant::now();
                virtual_at_sync = target_us;
            }
            self.robot.run_until(target_us);
            if let Some(pass) = self.each_pass.as_mut() {
                pass(&mut self.robot);
            }
            if let Some(observer) = self.observer.as_mut() {
                observer.look_if_due(&self.robot, &self.late);
            }
            if self.late != reported && Instant::now() >= next_report {
                (self.report_late)(&self.late);
                reported = self.late;
                next_report = Instant::now() + LATE_REPORT_PERIOD;
            }

            let had_input = self.forward_client_input(&mut input)?;
            let had_output = self.deliver(&mut output)?;
            self.follow_port();
            if had_input || had_output {
                last_traffic = Some(Instant::now());
            }
        }
        Ok(self.robot)
    }

    /// Moves the TCP server to the Basic's server port if it follows it and the port changed.
    fn follow_port(&mut self) {
        let (Some(follow), Some(tcp), Some(port)) = (
            self.follow.as_mut(),
            self.tcp.as_mut(),
            self.robot.server_port(),
        ) else {
            return;
        };
        let now = tcp.local_addr().map(|a| a.port()).ok();
        if now == Some(port) || follow.refused == Some(port) {
            return;
        }
        let addr = SocketAddr::new(follow.ip, port);
        match tcp.listen_on(addr) {
            Ok(()) => {
                follow.refused = None;
                (follow.moved)(Ok(addr));
            }
            Err(e) => {
                follow.refused = Some(port);
                (follow.moved)(Err(e));
            }
        }
    }

    /// Sleeps until a client sends something or `tick` passes. A client whose link cannot take
    /// bytes now is not watched (its pending bytes would wake us at once): the pty client while
    /// its line is full (`watch_pty`), a TCP client while its link has no room.
    fn wait_for_input(&self, tick: Duration, watch_pty: bool) -> io::Result<()> {
        let pty_fd: BorrowedFd<'_> = std::os::fd::AsFd::as_fd(&self.pty);
        let has_room = |id: ClientId| {
            self.tcp_links
                .iter()
                .find(|(client, _)| *client == id)
                .is_some_and(|(_, link)| self.robot.link_room(*link) > 0)
        };
        let mut fds: Vec<PollFd<'_>> = std::iter::once(pty_fd)
            .filter(|_| watch_pty)
            .chain(self.tcp.iter().flat_map(|tcp| tcp.poll_fds(has_room)))
            .chain(self.robot.wake_fds())
            .map(|fd| PollFd::new(fd, PollFlags::POLLIN))
            .collect();
        match ppoll(&mut fds, Some(TimeSpec::from_duration(tick)), None) {
            Ok(_) | Err(nix::errno::Errno::EINTR) => Ok(()),
            Err(e) => Err(e.into()),
        }
    }

    /// Hands what clients sent to the robot, as much as the line can carry now (see
    /// [`LinePacer`]); tells whether there was anything.
    fn forward_client_input(&mut self, buf: &mut [u8]) -> io::Result<bool> {
        let now_ns = self.robot.now_us().saturating_mul(1_000);
        let mut budget = self.pacer.room(now_ns);
        let mut any = false;
        while let Some(window) = buf
            .get_mut(..budget.min(buf.len()))
            .filter(|w| !w.is_empty())
        {
            let n = self.pty.read_available(window)?;
            let Some(bytes) = window.get(..n).filter(|b| !b.is_empty()) else {
                break;
            };
            self.robot.host_write(bytes);
            self.pacer.consumed(n, now_ns);
            budget -= n;
            any = true;
        }
        if let Some(tcp) = self.tcp.as_mut() {
            let (robot, links) = (&mut self.robot, &mut self.tcp_links);
            tcp.accept_pending(|id| robot.connect().map(|link| links.push((id, link))).is_some());
            let rooms: Vec<(ClientId, HostLink, usize)> = links
                .iter()
                .map(|&(id, link)| (id, link, robot.link_room(link)))
                .collect();
            let find = |id: ClientId| rooms.iter().find(|(client, _, _)| *client == id);
            let mut gone = Vec::new();
            tcp.receive(
                |id| find(id).map_or(0, |&(_, _, room)| room),
                |id, bytes| {
                    if let Some(&(_, link, _)) = find(id) {
                        robot.link_write(link, bytes);
                        any = true;
                    }
                },
                |id| gone.push(id),
            );
            for id in gone {
                if let Some(&(_, link, _)) = find(id) {
                    robot.disconnect(link);
                }
                links.retain(|(client, _)| *client != id);
            }
        }
        Ok(any)
    }

    /// Passes what the robot sent to its clients: the serial line's bytes to the pty, each
    /// network link's to its TCP client (each reply whole, in one write). Tells whether there
    /// was anything.
    fn deliver(&mut self, buf: &mut Vec<u8>) -> io::Result<bool> {
        buf.clear();
        self.robot.host_read(buf);
        let mut any = !buf.is_empty();
        if any {
            self.pty.write_or_drop(buf)?;
        }
        if let Some(tcp) = self.tcp.as_mut() {
            let robot = &mut self.robot;
            self.tcp_links.retain(|&(id, link)| {
                buf.clear();
                robot.link_read(link, buf);
                any |= !buf.is_empty();
                let connected = buf.is_empty() || tcp.send(id, buf);
                if !connected {
                    robot.disconnect(link);
                }
                connected
            });
        }
        Ok(any)
    }
}

fn micros(d: Duration) -> u64 {
    u64::try_from(d.as_micros()).unwrap_or(u64::MAX)
}

/// A flag set by SIGINT, SIGTERM or SIGHUP, for [`RealtimeDriver::run`].
pub fn stop_on_signals() -> io::Result<Arc<AtomicBool>> {
    let stop = Arc::new(AtomicBool::new(false));
    for signal in [
        signal_hook::consts::SIGINT,
        signal_hook::consts::SIGTERM,
        signal_hook::consts::SIGHUP,
    ] {
        signal_hook::flag::register(signal, Arc::clone(&stop))?;
    }
    Ok(stop)
}

#[cfg(test)]
mod tests {
    use super::*;
    use std::fs::OpenOptions;
    use std::io::{Read, Write};

    /// Answers each request byte-timed like the real Basic: 87 us per byte after a 1 ms think.
    struct AckingRobot {
        now_us: u64,
        inbox: Vec<u8>,
        outbox: Vec<(u64, u8)>,
    }

    impl RealtimeRobot for AckingRobot {
        fn now_us(&self) -> u64 {
            self.now_us
        }
        fn host_write(&mut self, bytes: &[u8]) {
            self.inbox.extend_from_slice(bytes);
            if let [0xFE, 0xFE, _, cmd, .., 0xFA] = self.inbox[..] {
                for (i, byte) in [0xFE, 0xFE, 0x03, cmd, 0x01, 0xFA].into_iter().enumerate() {
                    self.outbox
                        .push((self.now_us + 1_000 + 87 * i as u64, byte));
                }
                self.inbox.clear();
            }
        }
        fn host_read(&mut self, out: &mut Vec<u8>) {
            let now = self.now_us;
            out.extend(
                self.outbox
                    .iter()
                    .filter(|(t, _)| *t <= now)
                    .map(|(_, b)| b),
            );
            self.outbox.retain(|(t, _)| *t > now);
        }
        fn run_until(&mut self, t_us: u64) {
            assert!(t_us >= self.now_us, "time went backwards");
            self.now_us = t_us;
        }
    }

    #[test]
    fn a_client_on_the_pty_gets_its_reply_and_the_loop_stops_on_request() {
        let robot = AckingRobot {
            now_us: 5,
            inbox: Vec::new(),
            outbox: Vec::new(),
        };
        let driver = RealtimeDriver::new(robot, PseudoTerminal::open().unwrap(), None);
        let path = driver.pty().slave_path().to_path_buf();
        let stop = Arc::new(AtomicBool::new(false));
        let loop_stop = Arc::clone(&stop);
        let handle = std::thread::spawn(move || driver.run(&loop_stop).map(|r| r.now_us));

        let mut client = OpenOptions::new()
            .read(true)
            .write(true)
            .open(&path)
            .unwrap();
        client.write_all(&[0xFE, 0xFE, 0x02, 0x12, 0xFA]).unwrap();
        let mut reply = [0u8; 6];
        client.read_exact(&mut reply).unwrap();
        assert_eq!(reply, [0xFE, 0xFE, 0x03, 0x12, 0x01, 0xFA]);

        stop.store(true, Ordering::Relaxed);
        let virtual_end_us = handle.join().unwrap().unwrap();
        assert!(
            virtual_end_us > 1_000,
            "virtual time followed the wall clock"
        );
    }

    /// Reads one frame from `stream` (two seconds at most); nothing if the server closed the
    /// connection (a reset, if the client had written before being turned away).
    fn read_frame(stream: &mut std::net::TcpStream) -> Vec<u8> {
        stream
            .set_read_timeout(Some(Duration::from_secs(2)))
            .unwrap();
        let mut buf = [0u8; 64];
        match stream.read(&mut buf) {
            Ok(n) => buf[..n].to_vec(),
            Err(e) if e.kind() == std::io::ErrorKind::ConnectionReset => Vec::new(),
            Err(e) => panic!("reading a reply: {e}"),
        }
    }

    #[test]
    fn every_client_gets_its_own_replies_and_one_too_many_is_turned_away() {
        let served = ServedRobot {
            robot: VirtualRobot::new(crate::sim::RobotConfig::default()),
            link: HostLink::Basic,
        };
        let tcp = TcpServer::bind("127.0.0.1:0".parse().unwrap()).unwrap();
        let addr = tcp.local_addr().unwrap();
        let driver = RealtimeDriver::new(served, PseudoTerminal::open().unwrap(), Some(tcp));
        let mut pty_client = OpenOptions::new()
            .read(true)
            .write(true)
            .open(driver.pty().slave_path())
            .unwrap();
        let stop = Arc::new(AtomicBool::new(false));
        let loop_stop = Arc::clone(&stop);
        let handle = std::thread::spawn(move || driver.run(&loop_stop).map(|_| ()));

        // The USB link and seven network clients: the Basic's limit. The next is turned away.
        let mut clients: Vec<std::net::TcpStream> = (1..firmware_basic::MAX_HOST_LINKS)
            .map(|_| std::net::TcpStream::connect(addr).unwrap())
            .collect();
        let mut refused = std::net::TcpStream::connect(addr).unwrap();
        assert!(read_frame(&mut refused).is_empty(), "closed at once");

        // Everyone asks something different at the same time; each gets its own answer.
        let requests: [u8; 7] = [0xC1, 0xC3, 0xC0, 0x12, 0x20, 0x2B, 0x29];
        for (client, cmd) in clients.iter_mut().zip(requests) {
            client.write_all(&[0xFE, 0xFE, 0x02, cmd, 0xFA]).unwrap();
        }
        pty_client
            .write_all(&[0xFE, 0xFE, 0x02, 0x1A, 0xFA])
            .unwrap();
        for (client, cmd) in clients.iter_mut().zip(requests) {
            let reply = read_frame(client);
            assert_eq!(reply.get(3), Some(&cmd), "{reply:02x?}");
        }
        let mut reply = [0u8; 5];
        pty_client.read_exact(&mut reply[..4]).unwrap();
        assert_eq!(reply[3], 0x1A);

        // One leaves: a newcomer takes its place.
        drop(clients.pop());
        let deadline = Instant::now() + Duration::from_secs(2);
        let mut newcomer = loop {
            let mut stream = std::net::TcpStream::connect(addr).unwrap();
            stream.write_all(&[0xFE, 0xFE, 0x02, 0xC1, 0xFA]).unwrap();
            let reply = read_frame(&mut stream);
            if !reply.is_empty() || Instant::now() > deadline {
                assert_eq!(reply.get(3), Some(&0xC1));
                break stream;
            }
        };
        newcomer.write_all(&[0xFE, 0xFE, 0x02, 0xC3, 0xFA]).unwrap();
        assert_eq!(
            read_frame(&mut newcomer),
            [0xFE, 0xFE, 0x03, 0xC3, 0x00, 0xFA]
        );

        stop.store(true, Ordering::Relaxed);
        handle.join().unwrap().unwrap();
    }

    /// Stalls 150 ms (a machine under load) on its second advance; records every advance.
    struct StallingRobot {
        now_us: u64,
        advances_us: Vec<u64>,
        stop: Arc<AtomicBool>,
    }

    impl StallingRobot {
        /// A robot at time 0 that stops the loop (`stop`) after 50 advances.
        fn new(stop: &Arc<AtomicBool>) -> Self {
            Self {
                now_us: 0,
                advances_us: Vec::new(),
                stop: Arc::clone(stop),
            }
        }
    }

    impl RealtimeRobot for StallingRobot {
        fn now_us(&self) -> u64 {
            self.now_us
        }
        fn host_write(&mut self, _: &[u8]) {}
        fn host_read(&mut self, _: &mut Vec<u8>) {}
        fn run_until(&mut self, t_us: u64) {
            assert!(t_us >= self.now_us, "time went backwards");
            self.advances_us.push(t_us - self.now_us);
            self.now_us = t_us;
            if self.advances_us.len() == 2 {
                std::thread::sleep(Duration::from_millis(150));
            }
            if self.advances_us.len() == 50 {
                self.stop.store(true, Ordering::Relaxed);
            }
        }
    }

    #[test]
    fn after_a_stall_the_arm_does_not_jump_ahead_by_more_than_the_catch_up_limit() {
        let stop = Arc::new(AtomicBool::new(false));
        let robot = StallingRobot::new(&stop);
        let driver = RealtimeDriver::new(robot, PseudoTerminal::open().unwrap(), None);
        let robot = driver.run(&stop).unwrap();
        let largest = robot.advances_us.iter().max().copied().unwrap();
        assert!(
            largest <= micros(MAX_CATCH_UP),
            "advanced {largest} us at once"
        );
        assert_eq!(robot.advances_us.len(), 50);
    }

    #[test]
    fn a_stall_is_counted_as_running_late_and_reported() {
        let stop = Arc::new(AtomicBool::new(false));
        let robot = StallingRobot::new(&stop);
        let reports = Arc::new(std::sync::Mutex::new(Vec::new()));
        let seen = Arc::new(std::sync::Mutex::new(Lateness::default()));
        let driver = RealtimeDriver::new(robot, PseudoTerminal::open().unwrap(), None)
            .on_late({
                let reports = Arc::clone(&reports);
                move |late: &Lateness| reports.lock().unwrap().push(*late)
            })
            .observe_every(Duration::ZERO, {
                let seen = Arc::clone(&seen);
                move |_: &StallingRobot, late: &Lateness| *seen.lock().unwrap() = *late
            });
        let start = Instant::now();
        let robot = driver.run(&stop).unwrap();
        let wall_us = micros(start.elapsed());
        // A stall of 150 ms (or more, and others, on a busy machine): at most 50 ms of it was
        // run, the rest is counted as late and said on the report.
        let late = *seen.lock().unwrap();
        assert!(late.stalls >= 1, "{late:?}");
        assert!(late.total_us >= 100_000, "late by {late}");
        assert!(
            !reports.lock().unwrap().is_empty(),
            "the stall was not reported"
        );
        // Virtual time plus what was counted as late is the wall time that passed.
        assert!(
            robot.now_us + late.total_us <= wall_us,
            "{} us run + {late} > {wall_us} us of wall time",
            robot.now_us
        );
    }

    /// Stands still; lets virtual time follow the wall clock.
    struct IdleRobot {
        now_us: u64,
    }

    impl RealtimeRobot for IdleRobot {
        fn now_us(&self) -> u64 {
            self.now_us
        }
        fn host_write(&mut self, _: &[u8]) {}
        fn host_read(&mut self, _: &mut Vec<u8>) {}
        fn run_until(&mut self, t_us: u64) {
            self.now_us = t_us;
        }
    }

    #[test]
    fn an_observer_is_called_from_the_loop_and_no_more_often_than_its_period() {
        let period = Duration::from_millis(20);
        let looks = Arc::new(std::sync::Mutex::new(Vec::new()));
        let stop = Arc::new(AtomicBool::new(false));
        let robot = IdleRobot { now_us: 0 };
        let start = Instant::now();
        let driver = RealtimeDriver::new(robot, PseudoTerminal::open().unwrap(), None)
            .observe_every(period, {
                let looks = Arc::clone(&looks);
                let stop = Arc::clone(&stop);
                move |_: &IdleRobot, _: &Lateness| {
                    let mut looks = looks.lock().unwrap();
                    looks.push(Instant::now());
                    if looks.len() == 10 {
                        stop.store(true, Ordering::Relaxed);
                    }
                }
            });
        driver.run(&stop).unwrap();
        let looks = looks.lock().unwrap();
        assert_eq!(looks.len(), 10);
        // The k-th look is due k periods after the start, never earlier.
        assert!(looks[9] - start >= 9 * period, "{:?}", looks[9] - start);
    }

    #[test]
    fn each_pass_gets_the_robot_after_virtual_time_advanced() {
        let stop = Arc::new(AtomicBool::new(false));
        let seen = Arc::new(std::sync::Mutex::new(Vec::new()));
        let robot = IdleRobot { now_us: 0 };
        let driver = RealtimeDriver::new(robot, PseudoTerminal::open().unwrap(), None).each_pass({
            let seen = Arc::clone(&seen);
            let stop = Arc::clone(&stop);
            move |robot: &mut IdleRobot| {
                let mut seen = seen.lock().unwrap();
                seen.push(robot.now_us);
                // It may act on the robot: here it moves its clock on a little.
                robot.now_us += 1;
                if seen.len() == 20 {
                    stop.store(true, Ordering::Relaxed);
                }
            }
        });
        let robot = driver.run(&stop).unwrap();
        let seen = seen.lock().unwrap();
        assert_eq!(seen.len(), 20, "one call per pass until the stop");
        assert!(seen.windows(2).all(|w| w[1] > w[0]), "{seen:?}");
        assert_eq!(robot.now_us, seen[19] + 1);
    }

    /// Checks on every write that no more arrived than the 115200 line could carry.
    struct CountingRobot {
        now_us: u64,
        received: usize,
        expected: usize,
        stop: Arc<AtomicBool>,
    }

    impl RealtimeRobot for CountingRobot {
        fn now_us(&self) -> u64 {
            self.now_us
        }
        fn host_write(&mut self, bytes: &[u8]) {
            self.received += bytes.len();
            let byte_ns = protocol_core::timing::wire_time_ns(1, HOST_BAUD);
            let carried = WINDOW_BYTES as u64 + self.now_us * 1_000 / byte_ns + 1;
            assert!(
                self.received as u64 <= carried,
                "{} bytes handed over by {} us: faster than 115200 baud",
                self.received,
                self.now_us
            );
            if self.received >= self.expected {
                self.stop.store(true, Ordering::Relaxed);
            }
        }
        fn host_read(&mut self, _: &mut Vec<u8>) {}
        fn run_until(&mut self, t_us: u64) {
            self.now_us = t_us;
        }
    }

    #[test]
    fn a_flooding_client_is_paced_to_the_line_speed_and_nothing_is_lost() {
        let stop = Arc::new(AtomicBool::new(false));
        let flood = vec![0x55u8; 2_000];
        let robot = CountingRobot {
            now_us: 0,
            received: 0,
            expected: flood.len(),
            stop: Arc::clone(&stop),
        };
        let driver = RealtimeDriver::new(robot, PseudoTerminal::open().unwrap(), None);
        let mut client = OpenOptions::new()
            .read(true)
            .write(true)
            .open(driver.pty().slave_path())
            .unwrap();
        client.write_all(&flood).unwrap();
        let robot = driver.run(&stop).unwrap();
        assert_eq!(robot.received, flood.len());
    }
}
