//! The command bodies of the `inksim` binary. `main.rs` holds the clap
//! definitions and the dispatch; each module here takes the parsed flags of
//! its commands, loads the scene or study through the library, runs it and
//! prints what it did.
//!
//! - [`scene`]: `run`, `geometry` and `check` of one scene.
//! - [`paint`]: `run` and `check` of an effect paint.
//! - [`study`]: `run`, `check` and `merge` of a study.
//! - [`effect_study`]: `plan`, `run`, `check` and `merge` of a study of an
//!   effect paint.
//! - [`plan`]: `plan`, the variants with their work and estimated time and
//!   memory.
//! - [`slurm`]: `slurm`, the sbatch job-array script.
//! - [`materials`]: `materials`, the stand-ins and the material library.
//! - [`view`]: `view`, the interactive page.
//! - [`match`](r#match): `match`, from a target colour to a recipe.
//! - [`fit_material`]: `fit-material`, a pigment's constants from drawdowns.
//!
//! Shared here: how an error is printed, a broken pipe ends quietly, which
//! files are studies, the thread count and the shard.

pub mod effect_study;
pub mod export;
pub mod fit_material;
pub mod r#match;
pub mod match_effect;
pub mod materials;
pub mod paint;
pub mod plan;
pub mod scene;
pub mod slurm;
pub mod study;
pub mod view;

use anyhow::Result;
use inksim::study::run::Shard;
use inksim::study::Study;
use std::path::{Path, PathBuf};

/// Output piped into a reader that stops early (`inksim plan … | head`):
/// end quietly, as ripgrep does, instead of a panic message.
pub fn exit_quietly_on_broken_pipe() {
    let default_hook = std::panic::take_hook();
    std::panic::set_hook(Box::new(move |info| {
        let payload = info.payload();
        let msg = payload
            .downcast_ref::<String>()
            .map(String::as_str)
            .or_else(|| payload.downcast_ref::<&str>().copied())
            .unwrap_or("");
        if msg.contains("Broken pipe") {
            std::process::exit(0);
        }
        default_hook(info)
    }));
}

/// Ctrl-C (SIGINT), SIGTERM (a batch system's time limit) and SIGHUP: remove
/// the temporary files being written (every finished result stays: results
/// are written atomically), say what is done and how to resume, exit 130.
pub fn exit_cleanly_on_interrupt() {
    let _ = ctrlc::set_handler(|| {
        if view::SERVING.load(std::sync::atomic::Ordering::SeqCst) {
            eprintln!("\n[inksim] view stopped");
            std::process::exit(0);
        }
        let removed = inksim::output::atomic::remove_unfinished();
        let status = inksim::output::progress::status();
        let status = if status.is_empty() {
            "finished results are kept".to_string()
        } else {
            status
        };
        let removed = match removed {
            0 => String::new(),
            n => format!(" ({n} unfinished temporary file(s) removed)"),
        };
        eprintln!("\n[inksim] interrupted: {status}{removed}");
        std::process::exit(130);
    });
}

/// The error and its causes, `: `-joined; a cause whose text its parent's
/// message already contains (library errors that name their source) is not
/// repeated.
pub fn chain(e: &anyhow::Error) -> String {
    let mut out = String::new();
    for cause in e.chain() {
        let msg = cause.to_string();
        if !out.contains(&msg) {
            if !out.is_empty() {
                out.push_str(": ");
            }
            out.push_str(&msg);
        }
    }
    out
}

/// Largest config file read (a config is a few kB; this refuses `/dev/zero`
/// and other non-configs before they fill the memory).
const MAX_CONFIG_BYTES: u64 = 16 << 20;

/// A config file, read once: standard input, a pipe or a process
/// substitution (`<(…)`) cannot be read a second time.
pub struct ConfigFile {
    pub path: PathBuf,
    pub text: String,
}

impl ConfigFile {
    /// Read `path`; one line naming it when it cannot be read, is a folder,
    /// is too large or is not UTF-8 text.
    pub fn read(path: &Path) -> Result<ConfigFile> {
        use std::io::Read;
        let fail = |what: String| anyhow::anyhow!("{}: cannot read: {what}", path.display());
        let file = std::fs::File::open(path).map_err(|e| fail(e.to_string()))?;
        if file.metadata().is_ok_and(|m| m.is_dir()) {
            return Err(fail("is a folder, not a config file".into()));
        }
        let mut bytes = Vec::new();
        file.take(MAX_CONFIG_BYTES + 1)
            .read_to_end(&mut bytes)
            .map_err(|e| fail(e.to_string()))?;
        if bytes.len() as u64 > MAX_CONFIG_BYTES {
            return Err(fail(format!(
                "larger than {} MiB, not a config file",
                MAX_CONFIG_BYTES >> 20
            )));
        }
        let text = String::from_utf8(bytes).map_err(|e| {
            fail(format!(
                "not UTF-8 text (byte {})",
                e.utf8_error().valid_up_to()
            ))
        })?;
        Ok(ConfigFile {
            path: path.to_path_buf(),
            text,
        })
    }

    pub fn display(&self) -> std::path::Display<'_> {
        self.path.display()
    }

    /// Whether it is a match file (has a [match] table).
    pub fn is_match(&self) -> bool {
        inksim::r#match::config::is_match_text(&self.text)
    }

    /// Whether it is an effect paint's match file (a multi-angle target).
    pub fn is_effect_match(&self) -> bool {
        inksim::r#match::config::is_effect_text(&self.text)
    }

    /// Whether it is a fit file (has a [fit] table).
    pub fn is_fit(&self) -> bool {
        inksim::r#match::fit::config::is_fit_text(&self.text)
    }

    /// Whether it is a study (has a [study] table).
    pub fn is_study(&self) -> bool {
        inksim::study::is_study_text(&self.text)
    }

    /// Whether it is an effect paint (has a [paint] table).
    pub fn is_paint(&self) -> bool {
        inksim::config::is_paint_text(&self.text)
    }

    /// The scene it describes.
    pub fn scene(&self) -> Result<inksim::config::Scene> {
        anyhow::ensure!(
            !self.is_paint(),
            "{}: an effect paint ([paint] table): `inksim run` and `inksim check` take it; this \
             command takes a wave-optics scene",
            self.display()
        );
        Ok(inksim::config::parse_scene(&self.path, &self.text)?)
    }

    /// The study it describes; `output_dir` (from `--output-dir`) replaces
    /// its `study.output_dir`.
    pub fn study(&self, output_dir: Option<PathBuf>) -> Result<Study> {
        // A file that is not TOML at all gets the parser's line and column
        // from `Study::parse`, not "no [study] table".
        anyhow::ensure!(
            self.is_study() || self.text.parse::<toml::Table>().is_err(),
            "{}: not a study (no [study] table); `inksim run` and `inksim check` take a scene",
            self.display()
        );
        let mut study = Study::parse(&self.path, &self.text)?;
        if let Some(d) = output_dir {
            study.output_dir = d;
        }
        Ok(study)
    }
}

/// Most worker threads per core `--threads` is allowed (more only queue).
pub const MAX_THREADS_PER_CORE: usize = 4;

/// `--threads N` checked: at least 1, at most [`MAX_THREADS_PER_CORE`] × the
/// cores (capped there with a message, as results do not depend on it).
pub fn capped_threads(n: usize) -> Result<usize> {
    anyhow::ensure!(n >= 1, "--threads must be at least 1");
    let cores = std::thread::available_parallelism().map_or(1, |c| c.get());
    let most = MAX_THREADS_PER_CORE * cores;
    if n > most {
        eprintln!(
            "[inksim] --threads {n} capped at {most} ({MAX_THREADS_PER_CORE} × the {cores} \
             core(s)); results do not depend on it"
        );
        return Ok(most);
    }
    Ok(n)
}

/// The worker threads: `--threads`, else all cores.
pub fn threads(cli: Option<usize>) -> usize {
    cli.unwrap_or_else(|| std::thread::available_parallelism().map_or(1, |n| n.get()))
}

/// The shard to run: `--shard I/N`, else from the Slurm array variables,
/// else the whole study.
pub fn shard_of(flag: Option<&str>) -> Result<Shard> {
    match flag {
        Some(s) => Shard::parse(s).map_err(anyhow::Error::msg),
        None => Ok(Shard::from_env(|k| std::env::var(k).ok())
            .map_err(anyhow::Error::msg)?
            .unwrap_or(Shard::ALL)),
    }
}

/// The `--only AXIS=LABEL[,LABEL…]` flags, parsed (checked against the
/// study when it is expanded).
pub fn selections(only: &[String]) -> Result<Vec<inksim::study::sweep::Selection>> {
    only.iter()
        .map(|o| inksim::study::sweep::Selection::parse(o).map_err(anyhow::Error::msg))
        .collect()
}
