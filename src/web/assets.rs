//! The page and everything it loads, compiled into the binary so the view works offline. The
//! files live in `src/web/assets/` (three.js is vendored there; see its README.md).

/// A file the server hands out as it is.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct Asset {
    /// The URL path it is served at.
    pub path: &'static str,
    /// Its `Content-Type`.
    pub content_type: &'static str,
    /// Its bytes.
    pub body: &'static [u8],
}

const HTML: &str = "text/html; charset=utf-8";
const JS: &str = "text/javascript; charset=utf-8";
const CSS: &str = "text/css; charset=utf-8";
const TEXT: &str = "text/plain; charset=utf-8";

/// An [`Asset`] at `path` from `file` (relative to this source file).
macro_rules! asset {
    ($path:literal, $content_type:expr, $file:literal) => {
        Asset {
            path: $path,
            content_type: $content_type,
            body: include_bytes!($file),
        }
    };
}

/// Every static file of the view.
pub const ASSETS: &[Asset] = &[
    asset!("/", HTML, "assets/index.html"),
    asset!("/view.css", CSS, "assets/view.css"),
    asset!("/view.js", JS, "assets/view.js"),
    asset!("/arm.js", JS, "assets/arm.js"),
    asset!("/plot.js", JS, "assets/plot.js"),
    asset!("/three/three.module.js", JS, "assets/three/three.module.js"),
    asset!("/three/three.core.js", JS, "assets/three/three.core.js"),
    asset!(
        "/three/OrbitControls.js",
        JS,
        "assets/three/OrbitControls.js"
    ),
    asset!("/three/LICENSE", TEXT, "assets/three/LICENSE"),
];

/// The asset served at `path` (`/index.html` is `/`).
pub fn find(path: &str) -> Option<&'static Asset> {
    let path = if path == "/index.html" { "/" } else { path };
    ASSETS.iter().find(|a| a.path == path)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn every_module_the_page_imports_is_served() {
        let page = std::str::from_utf8(find("/").expect("the page").body).expect("UTF-8");
        for asset in ASSETS.iter().filter(|a| a.content_type == JS) {
            let text = std::str::from_utf8(asset.body).expect("UTF-8");
            for import in text
                .lines()
                .map(str::trim)
                .filter(|l| l.starts_with("import ") || l.starts_with("} from "))
                .filter_map(|l| l.split(['\'', '"']).nth(1))
            {
                let resolved = match import {
                    "three" => "/three/three.module.js".to_string(),
                    absolute if absolute.starts_with('/') => absolute.to_string(),
                    relative => {
                        let dir = asset.path.rsplit_once('/').map_or("", |(d, _)| d);
                        format!("{dir}/{}", relative.trim_start_matches("./"))
                    }
                };
                assert!(
                    find(&resolved).is_some(),
                    "{} imports {import} ({resolved}), which is not served",
                    asset.path
                );
            }
        }
        assert!(page.contains("/three/three.module.js"), "the import map");
        assert!(page.contains("/view.js"));
    }

    #[test]
    fn the_three_js_licence_ships_with_it() {
        let licence = find("/three/LICENSE").expect("licence");
        assert!(
            std::str::from_utf8(licence.body)
                .expect("UTF-8")
                .contains("three.js authors")
        );
    }
}
