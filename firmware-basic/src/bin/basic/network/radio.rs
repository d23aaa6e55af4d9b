//! The Wi-Fi driver (esp-radio's [`WifiController`]) driven from the super-loop.
//!
//! esp-radio's station API is async (`connect_async`, `disconnect_async`,
//! `wait_for_disconnect_async`). Instead of an executor, the driver's work is one long-lived
//! future, [`run`], that [`Radio::poll`] polls once per loop pass with a no-op waker: each poll
//! only looks at esp-radio's event channel and returns, so it costs microseconds. The radio's
//! own tasks (esp-rtos threads) do the real work and preempt the loop when they have some.
//!
//! The super-loop and the future talk through a [`Mailbox`]: requests in
//! ([`connection::Action::Join`] and [`connection::Action::Leave`] of the library's station
//! machine), [`LinkEvent`]s out. A request that arrives while a join is under way aborts it.

use alloc::boxed::Box;
use core::cell::{Cell, RefCell};
use core::future::{Future, poll_fn};
use core::pin::Pin;
use core::task::{Context, Poll, Waker};

use embassy_futures::select::{Either, select};
use esp_radio::wifi::{
    AuthenticationMethodConfig, Config, ConnectionError, DisconnectReason, WifiController,
    sta::StationConfig,
};
use firmware_basic::wifi::connection;
use firmware_basic::wifi::{Credentials, JoinFailure, LinkEvent};
use heapless::Deque;

/// What the super-loop asks the driver to do.
#[derive(Clone, Debug)]
pub enum Request {
    /// Join this network; report the outcome with `attempt`.
    Join {
        /// The network.
        credentials: Credentials,
        /// The station machine's attempt number.
        attempt: u32,
    },
    /// Leave the network, or abort a join.
    Leave,
}

/// Requests waiting for the driver: the station machine makes at most a leave and a join per
/// input.
const MAX_REQUESTS: usize = 4;
/// Events waiting for the super-loop: a join's outcome and a loss at most, per request.
const MAX_EVENTS: usize = 8;

/// Requests in, events out, between the super-loop and [`run`]. Both run on the super-loop's
/// thread (the future is polled there), so plain cells are enough.
#[derive(Default)]
pub struct Mailbox {
    requests: RefCell<Deque<Request, MAX_REQUESTS>>,
    events: RefCell<Deque<LinkEvent, MAX_EVENTS>>,
    /// Events dropped because the super-loop did not take them (never expected).
    lost_events: Cell<u32>,
}

impl Mailbox {
    /// Queues a request; the oldest is dropped if the queue is full (a newer one supersedes it).
    pub fn request(&self, request: Request) {
        let mut requests = self.requests.borrow_mut();
        if requests.is_full() {
            requests.pop_front();
        }
        let _ = requests.push_back(request);
    }

    /// The next event for the station machine.
    pub fn take_event(&self) -> Option<LinkEvent> {
        self.events.borrow_mut().pop_front()
    }

    fn report(&self, event: LinkEvent) {
        if self.events.borrow_mut().push_back(event).is_err() {
            self.lost_events.set(self.lost_events.get().wrapping_add(1));
        }
    }

    /// Waits for the next request and takes it.
    async fn next_request(&self) -> Request {
        poll_fn(|_| match self.requests.borrow_mut().pop_front() {
            Some(request) => Poll::Ready(request),
            None => Poll::Pending,
        })
        .await
    }

    /// Waits until a request is waiting (without taking it).
    async fn request_waiting(&self) {
        poll_fn(|_| {
            if self.requests.borrow().is_empty() {
                Poll::Pending
            } else {
                Poll::Ready(())
            }
        })
        .await
    }
}

/// The driver task, polled by the super-loop ([`Radio::poll`]).
pub struct Radio {
    task: Pin<Box<dyn Future<Output = ()>>>,
}

impl Radio {
    /// The task driving `controller`, talking through `mailbox`.
    pub fn new(controller: WifiController<'static>, mailbox: &'static Mailbox) -> Self {
        Self {
            task: Box::pin(run(controller, mailbox)),
        }
    }

    /// Lets the driver task look at what happened. Returns at once.
    pub fn poll(&mut self) {
        let mut cx = Context::from_waker(Waker::noop());
        // `run` never ends.
        let _ = self.task.as_mut().poll(&mut cx);
    }
}

/// The station's esp-radio configuration for `credentials`: WPA2 or better with a password
/// (WPA3 networks in transition mode join too), open without.
fn station_config(credentials: &Credentials) -> Option<Config> {
    let ssid = credentials.ssid().try_into().ok()?;
    let authentication = if credentials.is_open() {
        AuthenticationMethodConfig::Open
    } else {
        AuthenticationMethodConfig::Wpa2Personal(credentials.password().try_into().ok()?)
    };
    Some(Config::Station(
        StationConfig::default()
            .with_ssid(ssid)
            .with_authentication(authentication),
    ))
}

/// Sorts esp-radio's reason for a failed join into what the LCD tells the user.
fn join_failure(error: &ConnectionError) -> JoinFailure {
    let ConnectionError::Failed(info) = error else {
        return JoinFailure::Other;
    };
    match info.reason {
        DisconnectReason::NoAccessPointFound
        | DisconnectReason::NoAccessPointFoundWithCompatibleSecurity
        | DisconnectReason::NoAccessPointFoundInAuthmodeThreshold
        | DisconnectReason::NoAccessPointFoundInRssiThreshold => JoinFailure::NotFound,
        DisconnectReason::AuthenticationFailed
        | DisconnectReason::FourWayHandshakeTimeout
        | DisconnectReason::HandshakeTimeout
        | DisconnectReason::MicFailure => JoinFailure::AuthFailed,
        _ => JoinFailure::Other,
    }
}

/// The driver task: takes requests one at a time; a join waits for its outcome and then for
/// the link to be lost, either of which a newer request cuts short.
async fn run(mut controller: WifiController<'static>, mailbox: &'static Mailbox) {
    loop {
        match mailbox.next_request().await {
            Request::Leave => {
                // Not connected (or already leaving): nothing to do.
                let _ = controller.disconnect_async().await;
            }
            Request::Join {
                credentials,
                attempt,
            } => {
                let configured = station_config(&credentials)
                    .is_some_and(|config| controller.set_config(&config).is_ok());
                if !configured {
                    mailbox.report(LinkEvent::JoinFailed {
                        attempt,
                        reason: JoinFailure::Other,
                    });
                    continue;
                }
                match select(controller.connect_async(), mailbox.request_waiting()).await {
                    Either::First(Ok(_)) => {
                        mailbox.report(LinkEvent::Joined { attempt });
                        let lost = select(
                            controller.wait_for_disconnect_async(),
                            mailbox.request_waiting(),
                        )
                        .await;
                        if let Either::First(_) = lost {
                            mailbox.report(LinkEvent::Left { attempt });
                        }
                    }
                    Either::First(Err(error)) => mailbox.report(LinkEvent::JoinFailed {
                        attempt,
                        reason: join_failure(&error),
                    }),
                    // Cut short by a newer request: abort the join, then take that request.
                    Either::Second(()) => {
                        let _ = controller.disconnect_async().await;
                    }
                }
            }
        }
    }
}

/// Turns the station machine's driver actions into requests; the others are the network
/// layer's. Returns the action back if it is not the radio's.
pub fn request_for(action: connection::Action) -> Result<Request, connection::Action> {
    match action {
        connection::Action::Join {
            credentials,
            attempt,
        } => Ok(Request::Join {
            credentials,
            attempt,
        }),
        connection::Action::Leave => Ok(Request::Leave),
        other => Err(other),
    }
}
