//! Progress reporting for long runs (a leaf utility used by the pipeline).
//!
//! On a terminal (`stderr` is a TTY) [`Progress`] draws an indicatif bar with
//! elapsed time and ETA. Otherwise (logs, CI, batch jobs) it writes plain lines
//! to stderr,
//! `2026-11-23T21:37:05Z [inksim] label: 3/9 (33%), elapsed 12.3 s, eta 24.6 s — message`
//! (every plain line starts with its UTC time, [`utc_stamp`]),
//! at most one every [`PLAIN_INTERVAL`] plus the line that reaches the total,
//! so log files stay short. All methods take `&self` and the type is `Sync`,
//! so rayon workers can report directly. Output errors are ignored: progress
//! must never fail a run.

use std::io::{IsTerminal, Write};
use std::sync::Mutex;
use std::time::{Duration, Instant, SystemTime, UNIX_EPOCH};

use indicatif::{ProgressBar, ProgressDrawTarget, ProgressStyle};

/// What the current long work has done, one line, for an interrupt message.
static STATUS: Mutex<String> = Mutex::new(String::new());

/// Record what the current work has done so far (e.g. `3 of 6 variants
/// finished`), for the message printed when the run is interrupted.
pub fn set_status(line: impl Into<String>) {
    if let Ok(mut s) = STATUS.lock() {
        *s = line.into();
    }
}

/// The last [`set_status`] line (empty when none).
pub fn status() -> String {
    match STATUS.lock() {
        Ok(s) => s.clone(),
        Err(e) => e.into_inner().clone(),
    }
}

/// Least time between two plain progress lines.
pub const PLAIN_INTERVAL: Duration = Duration::from_secs(2);

const BAR_TEMPLATE: &str =
    "{prefix} [{bar:30}] {pos}/{len} ({percent}%) elapsed {elapsed} eta {eta} {msg}";

/// A progress report over `total` units of work.
pub struct Progress {
    label: String,
    total: u64,
    start: Instant,
    mode: Mode,
}

enum Mode {
    Bar(ProgressBar),
    Plain(Mutex<Plain>),
    Hidden,
}

struct Plain {
    pos: u64,
    last_print: Option<Instant>,
    interval: Duration,
    out: Box<dyn Write + Send>,
}

impl Progress {
    /// A bar on a terminal, plain lines on stderr otherwise.
    pub fn new(total: u64, label: &str) -> Progress {
        if std::io::stderr().is_terminal() {
            let bar = ProgressBar::with_draw_target(Some(total), ProgressDrawTarget::stderr());
            let style = ProgressStyle::with_template(BAR_TEMPLATE)
                .map(|s| s.progress_chars("=> "))
                .unwrap_or_else(|_| ProgressStyle::default_bar());
            bar.set_style(style);
            bar.set_prefix(format!("[inksim] {label}"));
            Self::with_mode(total, label, Mode::Bar(bar))
        } else {
            Self::plain_to(total, label, Box::new(std::io::stderr()), PLAIN_INTERVAL)
        }
    }

    /// Plain lines written to `out`, at most one per `interval` (plus the last).
    pub fn plain_to(
        total: u64,
        label: &str,
        out: Box<dyn Write + Send>,
        interval: Duration,
    ) -> Progress {
        let plain = Plain {
            pos: 0,
            last_print: None,
            interval,
            out,
        };
        Self::with_mode(total, label, Mode::Plain(Mutex::new(plain)))
    }

    /// Reports nothing (quiet runs, tests).
    pub fn hidden(total: u64, label: &str) -> Progress {
        Self::with_mode(total, label, Mode::Hidden)
    }

    fn with_mode(total: u64, label: &str, mode: Mode) -> Progress {
        Progress {
            label: label.to_string(),
            total,
            start: Instant::now(),
            mode,
        }
    }

    /// Count `n` more units done; `message` (if not empty) says what.
    pub fn inc(&self, n: u64, message: &str) {
        match &self.mode {
            Mode::Bar(bar) => {
                if !message.is_empty() {
                    bar.set_message(message.to_string());
                }
                bar.inc(n);
            }
            Mode::Plain(m) => {
                let mut p = lock(m);
                p.pos = p.pos.saturating_add(n);
                let now = Instant::now();
                let due = p
                    .last_print
                    .is_none_or(|t| now.duration_since(t) >= p.interval);
                if due || p.pos >= self.total {
                    p.last_print = Some(now);
                    let line = plain_line(
                        &self.label,
                        p.pos,
                        self.total,
                        self.start.elapsed(),
                        message,
                    );
                    let _ = writeln!(p.out, "{} {line}", utc_stamp(SystemTime::now()));
                    let _ = p.out.flush();
                }
            }
            Mode::Hidden => {}
        }
    }

    /// Print a line (above the bar on a terminal).
    pub fn log(&self, line: &str) {
        match &self.mode {
            Mode::Bar(bar) => bar.println(line),
            Mode::Plain(m) => {
                let mut p = lock(m);
                let _ = writeln!(p.out, "{} {line}", utc_stamp(SystemTime::now()));
                let _ = p.out.flush();
            }
            Mode::Hidden => {}
        }
    }

    /// End the report with a closing message.
    pub fn finish(&self, message: &str) {
        match &self.mode {
            Mode::Bar(bar) => bar.finish_with_message(message.to_string()),
            Mode::Plain(m) => {
                let mut p = lock(m);
                let line = format!(
                    "[inksim] {}: done {}/{} in {:.1} s{}",
                    self.label,
                    p.pos,
                    self.total,
                    self.start.elapsed().as_secs_f64(),
                    suffix(message)
                );
                let _ = writeln!(p.out, "{} {line}", utc_stamp(SystemTime::now()));
                let _ = p.out.flush();
            }
            Mode::Hidden => {}
        }
    }

    /// Units counted so far.
    pub fn position(&self) -> u64 {
        match &self.mode {
            Mode::Bar(bar) => bar.position(),
            Mode::Plain(m) => lock(m).pos,
            Mode::Hidden => 0,
        }
    }
}

/// A poisoned lock only means another thread panicked mid-report; keep going.
fn lock(m: &Mutex<Plain>) -> std::sync::MutexGuard<'_, Plain> {
    m.lock().unwrap_or_else(|e| e.into_inner())
}

fn suffix(message: &str) -> String {
    if message.is_empty() {
        String::new()
    } else {
        format!(" — {message}")
    }
}

/// One plain progress line (see the module docs).
/// `t` as an ISO 8601 UTC time to the second, `2026-11-23T21:37:05Z`.
pub fn utc_stamp(t: SystemTime) -> String {
    let secs = t.duration_since(UNIX_EPOCH).map_or(0, |d| d.as_secs());
    let [y, m, d, hh, mm, ss] = utc_civil(secs);
    format!("{y:04}-{m:02}-{d:02}T{hh:02}:{mm:02}:{ss:02}Z")
}

/// Year, month, day, hour, minute, second (UTC) of a Unix time, by the
/// civil-from-days algorithm (proleptic Gregorian calendar).
pub fn utc_civil(unix_s: u64) -> [i64; 6] {
    let (days, rem) = ((unix_s / 86_400) as i64, (unix_s % 86_400) as i64);
    // Howard Hinnant's days-to-civil.
    let z = days + 719_468;
    let era = z.div_euclid(146_097);
    let doe = z - era * 146_097;
    let yoe = (doe - doe / 1460 + doe / 36_524 - doe / 146_096) / 365;
    let doy = doe - (365 * yoe + yoe / 4 - yoe / 100);
    let mp = (5 * doy + 2) / 153;
    let d = doy - (153 * mp + 2) / 5 + 1;
    let m = if mp < 10 { mp + 3 } else { mp - 9 };
    let y = yoe + era * 400 + i64::from(m <= 2);
    [y, m, d, rem / 3600, rem % 3600 / 60, rem % 60]
}

pub fn plain_line(label: &str, pos: u64, total: u64, elapsed: Duration, message: &str) -> String {
    let secs = elapsed.as_secs_f64();
    let percent = if total == 0 {
        100
    } else {
        (pos.min(total) as u128 * 100 / total as u128) as u64
    };
    let eta = if pos == 0 {
        "?".to_string()
    } else {
        format!(
            "{:.1} s",
            secs * total.saturating_sub(pos) as f64 / pos as f64
        )
    };
    format!(
        "[inksim] {label}: {pos}/{total} ({percent}%), elapsed {secs:.1} s, eta {eta}{}",
        suffix(message)
    )
}

#[cfg(test)]
mod tests {
    use super::*;
    use rayon::prelude::*;
    use std::sync::Arc;

    #[derive(Clone, Default)]
    struct Shared(Arc<Mutex<Vec<u8>>>);

    impl Write for Shared {
        fn write(&mut self, buf: &[u8]) -> std::io::Result<usize> {
            self.0.lock().unwrap().extend_from_slice(buf);
            Ok(buf.len())
        }
        fn flush(&mut self) -> std::io::Result<()> {
            Ok(())
        }
    }

    impl Shared {
        fn lines(&self) -> Vec<String> {
            String::from_utf8(self.0.lock().unwrap().clone())
                .unwrap()
                .lines()
                .map(str::to_owned)
                .collect()
        }
    }

    /// The lines without their UTC stamps, each checked to be one.
    fn unstamped(lines: Vec<String>) -> Vec<String> {
        lines
            .into_iter()
            .map(|l| {
                let (stamp, rest) = l.split_at(20);
                let b = stamp.as_bytes();
                assert!(
                    b[4] == b'-' && b[10] == b'T' && b[19] == b'Z' && rest.starts_with(' '),
                    "{l}"
                );
                rest[1..].to_string()
            })
            .collect()
    }

    #[test]
    fn utc_stamps_are_the_civil_time() {
        let at = |s: u64| utc_stamp(UNIX_EPOCH + Duration::from_secs(s));
        assert_eq!(at(0), "1970-01-01T00:00:00Z");
        assert_eq!(at(951_782_400), "2000-02-29T00:00:00Z");
        assert_eq!(at(1_795_469_825), "2026-11-23T21:37:05Z");
        assert_eq!(at(4_107_542_399), "2100-02-28T23:59:59Z");
    }

    #[test]
    fn plain_line_format() {
        let d = Duration::from_secs_f64(12.3);
        assert_eq!(
            plain_line("solve", 3, 9, d, "λ = 450 nm"),
            "[inksim] solve: 3/9 (33%), elapsed 12.3 s, eta 24.6 s — λ = 450 nm"
        );
        assert_eq!(
            plain_line("x", 0, 4, Duration::ZERO, ""),
            "[inksim] x: 0/4 (0%), elapsed 0.0 s, eta ?"
        );
        assert_eq!(
            plain_line("x", 0, 0, Duration::ZERO, ""),
            "[inksim] x: 0/0 (100%), elapsed 0.0 s, eta ?"
        );
    }

    #[test]
    fn plain_lines_are_throttled_but_the_last_is_kept() {
        let buf = Shared::default();
        let p = Progress::plain_to(5, "run", Box::new(buf.clone()), Duration::from_secs(3600));
        for k in 0..5 {
            p.inc(1, &format!("step {k}"));
        }
        p.log("a note");
        p.finish("all good");
        let lines = unstamped(buf.lines());
        assert_eq!(lines.len(), 4, "{lines:?}");
        assert!(
            lines[0].starts_with("[inksim] run: 1/5 (20%), elapsed "),
            "{}",
            lines[0]
        );
        assert!(lines[0].ends_with(" — step 0"));
        assert!(
            lines[1].starts_with("[inksim] run: 5/5 (100%), "),
            "{}",
            lines[1]
        );
        assert!(lines[1].ends_with("eta 0.0 s — step 4"), "{}", lines[1]);
        assert_eq!(lines[2], "a note");
        assert!(
            lines[3].starts_with("[inksim] run: done 5/5 in ") && lines[3].ends_with(" — all good")
        );
    }

    #[test]
    fn usable_from_rayon_threads() {
        fn shareable<T: Send + Sync>() {}
        shareable::<Progress>();
        let buf = Shared::default();
        let p = Progress::plain_to(200, "par", Box::new(buf.clone()), Duration::ZERO);
        (0..200u64).into_par_iter().for_each(|_| p.inc(1, ""));
        assert_eq!(p.position(), 200);
        let lines = unstamped(buf.lines());
        assert_eq!(lines.len(), 200);
        assert!(lines
            .last()
            .unwrap()
            .starts_with("[inksim] par: 200/200 (100%)"));
        let h = Progress::hidden(3, "quiet");
        h.inc(3, "x");
        h.finish("");
    }
}
