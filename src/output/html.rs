//! Text in the HTML pages the study, the effect study and the match write.

/// `t` with `&`, `<`, `>` and `"` escaped, for element text and quoted
/// attribute values.
pub fn escape(t: &str) -> String {
    t.replace('&', "&amp;")
        .replace('<', "&lt;")
        .replace('>', "&gt;")
        .replace('"', "&quot;")
}
