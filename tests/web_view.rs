//! The 3D view as a user meets it: the robot binary serves the page, headless Chromium opens
//! it, pymycobot moves the arm, and the same page, without reloading, shows the arm move.
//!
//! "Drawn" and "moved" are read off screenshots: the arm's links are the only orange in the
//! scene (`LINK_COLOUR` in arm.js), so the test counts orange pixels left of the readout panel.
//! Drawn: at least [`DRAWN_FRACTION`] of the scene is orange (a blank page has none). Moved:
//! the orange outline after the move differs from the one before in at least
//! [`MOVED_FRACTION`] of its pixels and its centre moved by [`MOVED_PX`] or more. The readout
//! must show the angles pymycobot reads back, and the flange the page drew must be where
//! kinematics-core puts it. Reloading the page and a second page must work too.
//!
//! Needs Debian's `chromium` (`.ci/run` installs it) and the pymycobot venv (created on first
//! run); either missing fails the test with the reason.
#![allow(clippy::unwrap_used, clippy::expect_used, clippy::indexing_slicing)] // a test harness: a panic is a failed check

use std::path::{Path, PathBuf};
use std::process::Command;

use serde_json::Value;

#[path = "e2e/chromium.rs"]
mod chromium;
#[path = "e2e/launcher.rs"]
mod launcher;
#[path = "e2e/venv.rs"]
mod venv;
#[path = "e2e/view_page.rs"]
mod view_page;

use chromium::Chromium;
use launcher::launch;
use view_page::{PAGE_DEADLINE, READOUT_ANGLES, numbers, wait_until_drawn};

/// The page's size in CSS pixels; the readout panel takes the right [`PANEL_PX`].
const WIDTH: u32 = 1000;
const HEIGHT: u32 = 640;
const PANEL_PX: u32 = 320;
/// Share of the scene the arm's links cover at least, drawn (about 2 % in the poses used).
const DRAWN_FRACTION: f64 = 0.005;
/// Share of the arm's pixels that must change with the move.
const MOVED_FRACTION: f64 = 0.3;
/// How far the middle of the arm's pixels must move, in pixels.
const MOVED_PX: f64 = 20.0;

/// A page with the view's background and nothing on it.
const BLANK_PAGE: &str = "data:text/html,<body style='margin:0;background:%231d2127'>";

/// The move: J1 turns the arm aside, J2 and J3 fold it down.
const TARGET_DEG: [f64; 6] = [60.0, -45.0, -45.0, 20.0, 30.0, 40.0];

fn scratch(name: &str) -> PathBuf {
    PathBuf::from(env!("CARGO_TARGET_TMPDIR")).join(format!("web-view-{name}"))
}

/// The arm's pixels in a screenshot: orange, left of the panel.
struct ArmPixels {
    /// Whether each scene pixel is the arm's, row by row, `width` per row.
    mask: Vec<bool>,
    width: usize,
}

impl ArmPixels {
    fn of(png_bytes: &[u8]) -> ArmPixels {
        let mut decoder = png::Decoder::new(std::io::Cursor::new(png_bytes));
        decoder.set_transformations(png::Transformations::normalize_to_color8());
        let mut reader = decoder.read_info().expect("a PNG");
        let mut buf = vec![0; reader.output_buffer_size().expect("size")];
        let info = reader.next_frame(&mut buf).expect("PNG pixels");
        let channels = info.color_type.samples();
        let width = info.width as usize;
        let scene_width = width.saturating_sub(PANEL_PX as usize);
        let mut mask = Vec::with_capacity(scene_width * info.height as usize);
        for row in buf.chunks(info.line_size).take(info.height as usize) {
            for px in row.chunks(channels).take(scene_width) {
                mask.push(is_link_orange(px[0], px[1], px[2]));
            }
        }
        ArmPixels {
            mask,
            width: scene_width,
        }
    }

    fn count(&self) -> usize {
        self.mask.iter().filter(|&&m| m).count()
    }

    fn fraction(&self) -> f64 {
        self.count() as f64 / self.mask.len().max(1) as f64
    }

    /// The middle of the arm's pixels.
    fn centre(&self) -> (f64, f64) {
        let (mut x, mut y, mut n) = (0.0, 0.0, 0.0_f64);
        for (i, _) in self.mask.iter().enumerate().filter(|(_, m)| **m) {
            x += (i % self.width) as f64;
            y += (i / self.width) as f64;
            n += 1.0;
        }
        (x / n.max(1.0), y / n.max(1.0))
    }

    /// Share of the pixels that are the arm's in one picture but not in the other.
    fn changed_fraction(&self, other: &ArmPixels) -> f64 {
        let (mut either, mut one) = (0usize, 0usize);
        for (&a, &b) in self.mask.iter().zip(&other.mask) {
            either += usize::from(a || b);
            one += usize::from(a != b);
        }
        one as f64 / either.max(1) as f64
    }
}

/// The links' orange (0xf28c28, hue 30 degrees) in any light: hue 15..45 degrees, saturated,
/// not dark. Nothing else in the scene has that hue.
fn is_link_orange(r: u8, g: u8, b: u8) -> bool {
    let (r, g, b) = (f64::from(r), f64::from(g), f64::from(b));
    let max = r.max(g).max(b);
    let min = r.min(g).min(b);
    if max < 60.0 || max - min < 0.45 * max || max != r {
        return false;
    }
    let hue = 60.0 * (g - b) / (max - min);
    (15.0..=45.0).contains(&hue)
}

fn save(name: &str, png_bytes: &[u8]) -> PathBuf {
    let path = scratch(name).with_extension("png");
    std::fs::write(&path, png_bytes).expect("save the screenshot");
    path
}

/// Runs the Python lines `script` with `mc`, a pymycobot MyCobot280 on `link`; returns what
/// they printed.
fn run_pymycobot(link: &Path, script: &str) -> String {
    let script = format!(
        "import json, os, time, warnings\n\
         warnings.filterwarnings('ignore')\n\
         from pymycobot import MyCobot280\n\
         mc = MyCobot280(os.environ['MYCOBOT_PORT'])\n\
         {script}"
    );
    venv::run_checked(
        Command::new(venv::python())
            .arg("-c")
            .arg(script)
            .env("MYCOBOT_PORT", link),
    )
}

/// Moves the arm with pymycobot; returns the angles it reads back.
fn move_with_pymycobot(link: &Path) -> Vec<f64> {
    let out = run_pymycobot(
        link,
        &format!(
            "mc.set_color(0, 200, 255)\n\
             mc.set_gripper_value(60, 80)\n\
             mc.sync_send_angles({TARGET_DEG:?}, 80, timeout=15)\n\
             print(json.dumps(mc.get_angles()))\n"
        ),
    );
    let angles: Value = serde_json::from_str(out.trim())
        .unwrap_or_else(|e| panic!("pymycobot printed {out:?}: {e}"));
    numbers(&angles)
}

#[test]
fn the_page_draws_the_arm_and_shows_it_move() {
    let link = scratch("link");
    let _ = std::fs::remove_file(&link);
    let link_arg = link.to_str().expect("UTF-8 path");
    let robot = launch(&["--pty-link", link_arg, "--web", "127.0.0.1:0"]);
    let url = robot
        .banner_value("view on ")
        .unwrap_or_else(|| panic!("no view address in the banner:\n{}", robot.banner))
        .to_string();
    assert!(url.starts_with("http://127.0.0.1:"), "{url}");

    let mut browser = Chromium::launch(scratch("profile")).unwrap_or_else(|e| panic!("{e}"));
    let blank = browser
        .open(BLANK_PAGE, WIDTH, HEIGHT)
        .expect("a blank page");
    let blank_shot = browser.screenshot(&blank).expect("screenshot");
    assert_eq!(
        ArmPixels::of(&blank_shot).count(),
        0,
        "the detector sees an arm on a blank page"
    );

    let page = browser.open(&url, WIDTH, HEIGHT).expect("open the view");
    wait_until_drawn(&mut browser, &page);
    let before_png = browser.screenshot(&page).expect("screenshot");
    let before = ArmPixels::of(&before_png);
    let before_path = save("before", &before_png);
    assert!(
        before.fraction() >= DRAWN_FRACTION,
        "no arm drawn: {:.2} % of the scene is the arm's orange (see {})",
        100.0 * before.fraction(),
        before_path.display()
    );

    let read_back = move_with_pymycobot(&link);
    for (got, want) in read_back.iter().zip(TARGET_DEG) {
        assert!((got - want).abs() < 0.5, "pymycobot read {read_back:?}");
    }

    // The same page, not reloaded, follows: its readout shows the angles read back...
    let (shown, ok) = browser
        .wait_for(&page, READOUT_ANGLES, PAGE_DEADLINE, |v| {
            let shown = numbers(v);
            shown.len() == 6
                && shown
                    .iter()
                    .zip(&read_back)
                    .all(|(s, r)| (s - r).abs() <= 0.2)
        })
        .expect("evaluate");
    assert!(
        ok,
        "the readout shows {shown}, pymycobot read {read_back:?}"
    );
    let led = browser
        .evaluate(&page, "document.getElementById('led').textContent")
        .expect("evaluate");
    assert_eq!(led, "#00c8ff", "the LED colour set with set_color");
    let status = browser
        .evaluate(&page, "document.getElementById('status').textContent")
        .expect("evaluate");
    assert!(
        status
            .as_str()
            .is_some_and(|s| s.contains("pymycobot protocol")),
        "the status line names the Basic's dialect: {status}"
    );

    // ...and it drew the flange where kinematics-core puts it for the angles it shows.
    let (shown, drawn) = {
        let both = browser
            .evaluate(
                &page,
                &format!("[{READOUT_ANGLES}, window.viewStats.flangeMm]"),
            )
            .expect("evaluate");
        (numbers(&both[0]), numbers(&both[1]))
    };
    let q = kinematics_core::JointAngles(std::array::from_fn(|j| {
        (shown.get(j).copied().unwrap_or(0.0) * 100.0).round() as i32
    }));
    let pose = kinematics_core::Kinematics::new().forward(&q);
    let expected = [pose.x, pose.y, pose.z].map(|tenths| f64::from(tenths) / 10.0);
    assert_eq!(drawn.len(), 3, "flange {drawn:?}");
    for (d, e) in drawn.iter().zip(expected) {
        assert!(
            (d - e).abs() <= 0.2,
            "drawn flange {drawn:?} mm, kinematics-core {expected:?} mm at {shown:?} deg"
        );
    }

    let after_png = browser.screenshot(&page).expect("screenshot");
    let after = ArmPixels::of(&after_png);
    let after_path = save("after", &after_png);
    let (x0, y0) = before.centre();
    let (x1, y1) = after.centre();
    let shift = (x1 - x0).hypot(y1 - y0);
    let changed = before.changed_fraction(&after);
    let pictures = format!("{} and {}", before_path.display(), after_path.display());
    println!(
        "arm: {:.1} % of the scene before the move, {:.1} % after; {:.0} % of its pixels \
         changed; its centre moved {shift:.0} px ({pictures})",
        100.0 * before.fraction(),
        100.0 * after.fraction(),
        100.0 * changed
    );
    assert!(
        after.fraction() >= DRAWN_FRACTION,
        "no arm drawn after the move ({pictures})"
    );
    assert!(
        changed >= MOVED_FRACTION && shift >= MOVED_PX,
        "the arm did not move on the page: {:.0} % of its pixels changed, its centre moved \
         {shift:.0} px ({pictures})",
        100.0 * changed
    );

    // A second page shows the same arm; the first, reloaded, comes back.
    let second = browser.open(&url, WIDTH, HEIGHT).expect("a second page");
    // Marked, so that waiting for the reloaded page cannot be satisfied by the old document.
    browser
        .evaluate(&page, "window.testMark = 1")
        .expect("mark the document");
    browser.reload(&page).expect("reload");
    for p in [&second, &page] {
        wait_until_drawn(&mut browser, p);
        let (shown, ok) = browser
            .wait_for(p, READOUT_ANGLES, PAGE_DEADLINE, |v| {
                numbers(v)
                    .iter()
                    .zip(&read_back)
                    .all(|(s, r)| (s - r).abs() <= 0.2)
            })
            .expect("evaluate");
        assert!(ok, "a reloaded or second page shows {shown}");
    }
}

/// Makes the README's picture, docs/view.png: a tool frame set, the LED lit, and a few moves so
/// the plot has something to show. By hand:
/// `cargo test --release --test web_view -- --ignored readme_screenshot`.
#[test]
#[ignore = "writes docs/view.png; run by hand"]
fn readme_screenshot() {
    let link = scratch("readme-link");
    let _ = std::fs::remove_file(&link);
    let robot = launch(&[
        "--pty-link",
        link.to_str().expect("UTF-8"),
        "--web",
        "127.0.0.1:0",
    ]);
    let url = robot
        .banner_value("view on ")
        .expect("view address")
        .to_string();
    let mut browser = Chromium::launch(scratch("readme-profile")).unwrap_or_else(|e| panic!("{e}"));
    let page = browser.open(&url, WIDTH, HEIGHT).expect("open the view");
    wait_until_drawn(&mut browser, &page);
    run_pymycobot(
        &link,
        "mc.set_color(60, 220, 120)\n\
         mc.set_tool_reference([0, 0, 90, 0, 0, 0])\n\
         mc.set_end_type(1)\n\
         mc.set_gripper_value(70, 80)\n\
         mc.sync_send_angles([35, -25, -45, 10, 40, 20], 70, timeout=15)\n\
         mc.sync_send_angles([-25, -55, -25, 25, 60, -30], 70, timeout=15)\n\
         mc.sync_send_angles([40, -35, -55, 5, 35, 30], 70, timeout=15)\n\
         time.sleep(0.5)\n",
    );
    let png = browser.screenshot(&page).expect("screenshot");
    let path = venv::workspace().join("docs/view.png");
    std::fs::write(&path, &png).expect("write docs/view.png");
    println!("wrote {} ({} bytes)", path.display(), png.len());
}
