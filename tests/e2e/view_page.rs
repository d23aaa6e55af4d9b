//! What the browser tests and benches read off the 3D view's page (included with `#[path]`
//! after `chromium.rs`): the page counts its progress in `window.viewStats` (`received`:
//! state messages, `drawn`: renders, `flangeMm`: where it drew the flange, [x, y, z]).
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
pub const RECEIVED: &str = "window.viewStats ? window.viewStats.received : 0";

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
            "(() => { const s = window.viewStats || {}; \
             return [s.received || 0, s.drawn || 0, s.flangeMm || null, \
             window.testMark === undefined]; })()",
            PAGE_DEADLINE,
            |v| {
                v[0].as_f64() >= Some(5.0)
                    && v[1].as_f64() >= Some(1.0)
                    && v[2].is_array()
                    && v[3] == true
            },
        )
        .unwrap_or_else(|e| panic!("{e}"));
    assert!(
        ok,
        "the page did not receive state and draw within {PAGE_DEADLINE:?}: {value}"
    );
}
