//! What the browser tests and benches read off the 3D view's page (included with `#[path]`
//! after `chromium.rs`): the page marks its progress on `<body>` (`data-received`: state
//! messages, `data-drawn`: renders, `data-flange-mm`: where it drew the flange).
#![allow(dead_code)]

use std::time::Duration;

use serde_json::Value;

use super::chromium::{Chromium, Page};

/// Longest the page may take to show what the robot does.
pub const PAGE_DEADLINE: Duration = Duration::from_secs(20);

/// The joint angles the page's readout shows.
pub const READOUT_ANGLES: &str =
    "[...document.querySelectorAll('#joints td')].map(td => Number(td.textContent))";

/// How many state messages the page has received.
pub const RECEIVED: &str = "Number(document.body ? document.body.dataset.received || 0 : 0)";

/// The numbers in a JSON array (empty if it is none).
pub fn numbers(value: &Value) -> Vec<f64> {
    value
        .as_array()
        .map(|a| a.iter().filter_map(Value::as_f64).collect())
        .unwrap_or_default()
}

/// Waits until `page` (a document the test did not mark with `window.testMark`) has received
/// state and drawn the arm; panics if it does not within [`PAGE_DEADLINE`].
pub fn wait_until_drawn(browser: &mut Chromium, page: &Page) {
    let (value, ok) = browser
        .wait_for(
            page,
            "(() => { const d = document.body ? document.body.dataset : {}; \
             return [Number(d.received || 0), Number(d.drawn || 0), d.flangeMm || '', \
             window.testMark === undefined]; })()",
            PAGE_DEADLINE,
            |v| {
                v[0].as_f64() >= Some(5.0)
                    && v[1].as_f64() >= Some(1.0)
                    && v[2] != ""
                    && v[3] == true
            },
        )
        .unwrap_or_else(|e| panic!("{e}"));
    assert!(
        ok,
        "the page did not receive state and draw within {PAGE_DEADLINE:?}: {value}"
    );
}
