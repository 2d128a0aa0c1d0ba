//! The page, embedded in the binary (no build step, no CDN, nothing read from disk).

pub const INDEX: &str = include_str!("page/index.html");
pub const APP_JS: &str = include_str!("page/app.js");
pub const STYLE_CSS: &str = include_str!("page/style.css");
