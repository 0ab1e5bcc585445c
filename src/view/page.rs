//! The page's files, embedded in the binary (nothing is fetched from
//! elsewhere): `page/index.html` (layout, controls) and `page/view.js` (the
//! WebGL2 renderer, the OBJ reader, the spectra plot and the controls).

/// The page.
pub const INDEX_HTML: &str = include_str!("page/index.html");
/// Its script.
pub const VIEW_JS: &str = include_str!("page/view.js");
