//! Headless Chromium driven over the DevTools protocol, for the browser tests and benches of
//! the 3D view (included with `#[path]`): open pages, evaluate JavaScript in them, reload
//! them, take screenshots.
//!
//! It runs Debian's `chromium` (`.ci/run` installs it) with a fresh profile, software WebGL
//! (SwiftShader: there is no GPU) and everything that would reach beyond this machine turned
//! off; without those flags it hangs on a closed network. A missing Chromium is an error that
//! says how to install it, never a silent pass.
#![allow(dead_code)]

use std::io::{BufRead, BufReader};
use std::net::TcpStream;
use std::path::PathBuf;
use std::process::{Child, Command, Stdio};
use std::sync::mpsc;
use std::thread;
use std::time::{Duration, Instant};

use serde_json::{Value, json};
use tungstenite::stream::MaybeTlsStream;
use tungstenite::{Message, WebSocket};

/// Longest Chromium may take to start listening for DevTools.
const START_DEADLINE: Duration = Duration::from_secs(30);
/// Longest one DevTools command may take (a screenshot with software GL included).
const COMMAND_DEADLINE: Duration = Duration::from_secs(30);

/// Where Debian puts the browser.
const CHROMIUM: &str = "chromium";

/// The flags every run needs here (see the module doc).
const FLAGS: &[&str] = &[
    "--headless",
    "--no-sandbox",
    "--disable-gpu",
    "--use-angle=swiftshader",
    "--enable-unsafe-swiftshader",
    "--disable-quic",
    "--no-first-run",
    "--disable-background-networking",
    "--disable-component-update",
    "--disable-sync",
    "--remote-debugging-port=0",
];

/// A running headless Chromium and the DevTools connection to it.
pub struct Chromium {
    child: Child,
    profile: PathBuf,
    devtools: WebSocket<MaybeTlsStream<TcpStream>>,
    next_id: u64,
}

/// A page (tab) opened with [`Chromium::open`].
#[derive(Clone, Debug)]
pub struct Page {
    session: String,
    target: String,
}

impl Chromium {
    /// Starts Chromium with a fresh profile in `scratch` (a directory of its own).
    pub fn launch(scratch: PathBuf) -> Result<Self, String> {
        let _ = std::fs::remove_dir_all(&scratch);
        std::fs::create_dir_all(&scratch).map_err(|e| format!("{}: {e}", scratch.display()))?;
        let mut child = Command::new(CHROMIUM)
            .args(FLAGS)
            .arg(format!("--user-data-dir={}", scratch.display()))
            .arg("about:blank")
            .stdout(Stdio::null())
            .stderr(Stdio::piped())
            .spawn()
            .map_err(|e| {
                format!(
                    "cannot start `{CHROMIUM}` ({e}): the browser tests need Debian's Chromium \
                     (`apt-get install chromium`; .ci/run installs it)"
                )
            })?;
        let stderr = child.stderr.take().ok_or("no stderr")?;
        let (lines_tx, lines) = mpsc::channel();
        // Chromium logs a lot on stderr: keep draining it so it never blocks on a full pipe.
        thread::spawn(move || {
            for line in BufReader::new(stderr).lines() {
                let Ok(line) = line else { break };
                let _ = lines_tx.send(line);
            }
        });
        let deadline = Instant::now() + START_DEADLINE;
        let mut said = String::new();
        let url = loop {
            let left = deadline.saturating_duration_since(Instant::now());
            match lines.recv_timeout(left) {
                Ok(line) => {
                    if let Some(url) = line.strip_prefix("DevTools listening on ") {
                        break url.trim().to_string();
                    }
                    said.push_str(&line);
                    said.push('\n');
                }
                Err(_) => {
                    let _ = child.kill();
                    let _ = child.wait();
                    return Err(format!("Chromium did not start DevTools; it said:\n{said}"));
                }
            }
        };
        thread::spawn(move || for _ in lines {});
        let (devtools, _) = tungstenite::connect(&url).map_err(|e| format!("{url}: {e}"))?;
        if let MaybeTlsStream::Plain(stream) = devtools.get_ref() {
            stream
                .set_read_timeout(Some(COMMAND_DEADLINE))
                .map_err(|e| e.to_string())?;
        }
        Ok(Self {
            child,
            profile: scratch,
            devtools,
            next_id: 0,
        })
    }

    /// Sends one DevTools command (to `page`, or to the browser) and waits for its result.
    fn call(&mut self, page: Option<&Page>, method: &str, params: Value) -> Result<Value, String> {
        self.next_id += 1;
        let id = self.next_id;
        let mut command = json!({ "id": id, "method": method, "params": params });
        if let Some(page) = page {
            command["sessionId"] = json!(page.session);
        }
        self.devtools
            .send(Message::text(command.to_string()))
            .map_err(|e| format!("{method}: {e}"))?;
        let deadline = Instant::now() + COMMAND_DEADLINE;
        while Instant::now() < deadline {
            let message = self.devtools.read().map_err(|e| format!("{method}: {e}"))?;
            let Message::Text(text) = message else {
                continue;
            };
            let reply: Value = serde_json::from_str(text.as_str()).map_err(|e| e.to_string())?;
            if reply["id"] != json!(id) {
                continue; // an event
            }
            if let Some(error) = reply.get("error") {
                return Err(format!("{method}: {error}"));
            }
            return Ok(reply["result"].clone());
        }
        Err(format!("{method}: no answer within {COMMAND_DEADLINE:?}"))
    }

    /// Opens `url` in a new page of `width` x `height` CSS pixels and waits until it has
    /// loaded.
    pub fn open(&mut self, url: &str, width: u32, height: u32) -> Result<Page, String> {
        let created = self.call(
            None,
            "Target.createTarget",
            json!({ "url": url, "newWindow": true, "width": width, "height": height }),
        )?;
        let target = created["targetId"]
            .as_str()
            .ok_or("no target id")?
            .to_string();
        let attached = self.call(
            None,
            "Target.attachToTarget",
            json!({ "targetId": target, "flatten": true }),
        )?;
        let session = attached["sessionId"]
            .as_str()
            .ok_or("no session id")?
            .to_string();
        let page = Page { session, target };
        self.call(Some(&page), "Page.enable", json!({}))?;
        self.call(
            Some(&page),
            "Emulation.setDeviceMetricsOverride",
            json!({ "width": width, "height": height, "deviceScaleFactor": 1, "mobile": false }),
        )?;
        let (state, loaded) =
            self.wait_for(&page, "document.readyState", COMMAND_DEADLINE, |v| {
                v == "complete"
            })?;
        if !loaded {
            let resources = self.evaluate(
                &page,
                "performance.getEntriesByType('resource').map(e => [e.name, Math.round(e.responseEnd)])",
            );
            return Err(format!(
                "{url} did not load: {state}; resources loaded: {resources:?}"
            ));
        }
        Ok(page)
    }

    /// The value of JavaScript expression `expression` in `page` (awaited if a promise).
    pub fn evaluate(&mut self, page: &Page, expression: &str) -> Result<Value, String> {
        let result = self.call(
            Some(page),
            "Runtime.evaluate",
            json!({ "expression": expression, "returnByValue": true, "awaitPromise": true }),
        )?;
        if let Some(exception) = result.get("exceptionDetails") {
            return Err(format!("{expression}: {exception}"));
        }
        Ok(result["result"]["value"].clone())
    }

    /// Evaluates `expression` in `page` every 100 ms until `done` holds for its value or
    /// `timeout` passes; returns the last value and whether `done` held.
    pub fn wait_for(
        &mut self,
        page: &Page,
        expression: &str,
        timeout: Duration,
        done: impl Fn(&Value) -> bool,
    ) -> Result<(Value, bool), String> {
        let deadline = Instant::now() + timeout;
        loop {
            let value = self.evaluate(page, expression)?;
            if done(&value) {
                return Ok((value, true));
            }
            if Instant::now() >= deadline {
                return Ok((value, false));
            }
            thread::sleep(Duration::from_millis(100));
        }
    }

    /// Reloads `page`.
    pub fn reload(&mut self, page: &Page) -> Result<(), String> {
        self.call(Some(page), "Page.reload", json!({})).map(|_| ())
    }

    /// Closes `page`.
    pub fn close(&mut self, page: &Page) -> Result<(), String> {
        self.call(
            None,
            "Target.closeTarget",
            json!({ "targetId": page.target }),
        )
        .map(|_| ())
    }

    /// A PNG screenshot of what `page` shows.
    pub fn screenshot(&mut self, page: &Page) -> Result<Vec<u8>, String> {
        let shot = self.call(
            Some(page),
            "Page.captureScreenshot",
            json!({ "format": "png" }),
        )?;
        let data = shot["data"].as_str().ok_or("no screenshot data")?;
        data_encoding::BASE64
            .decode(data.as_bytes())
            .map_err(|e| e.to_string())
    }
}

impl Drop for Chromium {
    fn drop(&mut self) {
        let _ = self.child.kill();
        let _ = self.child.wait();
        let _ = std::fs::remove_dir_all(&self.profile);
    }
}
