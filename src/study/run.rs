//! Running the variants of a study: resumable, sharded, in parallel.
//!
//! Each variant writes `<study dir>/variants/<name>.h5` and `<name>.png`
//! through [`pipeline::run_with`] (quietly: the study reports per variant),
//! which writes both atomically (temporary file,
//! sync, rename): an interrupted run (Ctrl-C, a killed job) leaves either no
//! file or a complete one under the final names, at most a stale `*.tmp`
//! that the next run of that variant removes first.
//!
//! A variant is computed under its result's lock ([`lock::OutputLock`]), so
//! several processes may run one study in one folder at once (two shells, an
//! array job whose shards overlap): each variant is computed once. A process
//! that finds a variant locked takes the next one, and when its queue is
//! empty waits for each locked variant, skips it when the other run finished
//! it and computes it when that run failed or was killed.
//!
//! Before running, each variant's [`State`] is read from its files: it is
//! skipped only when its result file reads back ([`h5::read_summary`]), its
//! stored `input_hash` equals the hash of the variant's exact scene text,
//! it holds the planned number of solves and its tile exists; otherwise it
//! is (re)done and the reason is logged.
//!
//! Variants are split over shards round-robin by expansion index (variant
//! `i` belongs to shard `i mod N`), so every shard gets a similar mix. Within
//! a process, `jobs` worker threads take variants from a shared queue; each
//! variant's solves use the rayon pool. Results never depend on either:
//! a variant's seed is a function of its name.

use super::sweep::Variant;
use crate::config::Scene;
use crate::output::atomic::stale_temporaries;
use crate::output::h5;
use crate::output::lock::{self, OutputLock};
use crate::output::progress::{self, Progress};
use crate::pipeline;
use crate::pipeline::memory::{LimitSource, MemoryLimit};
use std::path::PathBuf;
use std::sync::atomic::{AtomicUsize, Ordering};
use std::sync::Mutex;
use std::time::Instant;

/// Which part of the study a process runs: shard `index` of `count` (0-based).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct Shard {
    pub index: usize,
    pub count: usize,
}

impl Shard {
    /// The whole study.
    pub const ALL: Shard = Shard { index: 0, count: 1 };

    /// Parse `I/N` (0 ≤ I < N).
    pub fn parse(s: &str) -> Result<Shard, String> {
        let (i, n) = s
            .split_once('/')
            .ok_or_else(|| format!("--shard must be I/N (e.g. 0/4), got `{s}`"))?;
        let index: usize = i
            .trim()
            .parse()
            .map_err(|_| format!("--shard: `{i}` is not a shard index"))?;
        let count: usize = n
            .trim()
            .parse()
            .map_err(|_| format!("--shard: `{n}` is not a shard count"))?;
        if count == 0 || index >= count {
            return Err(format!(
                "--shard {s}: need 0 <= I < N (shards are numbered from 0)"
            ));
        }
        Ok(Shard { index, count })
    }

    /// From Slurm's job-array variables, when set: `SLURM_ARRAY_TASK_ID`
    /// minus `SLURM_ARRAY_TASK_MIN` (default 0) of `SLURM_ARRAY_TASK_COUNT`.
    pub fn from_env(get: impl Fn(&str) -> Option<String>) -> Result<Option<Shard>, String> {
        let (Some(id), Some(count)) = (get("SLURM_ARRAY_TASK_ID"), get("SLURM_ARRAY_TASK_COUNT"))
        else {
            return Ok(None);
        };
        let num = |k: &str, v: &str| {
            v.trim()
                .parse::<usize>()
                .map_err(|_| format!("{k}=`{v}` is not a number"))
        };
        let id = num("SLURM_ARRAY_TASK_ID", &id)?;
        let count = num("SLURM_ARRAY_TASK_COUNT", &count)?;
        let min = match get("SLURM_ARRAY_TASK_MIN") {
            Some(m) => num("SLURM_ARRAY_TASK_MIN", &m)?,
            None => 0,
        };
        let index = id
            .checked_sub(min)
            .ok_or("SLURM_ARRAY_TASK_ID < SLURM_ARRAY_TASK_MIN")?;
        Shard::parse(&format!("{index}/{count}")).map(Some)
    }

    /// Whether variant number `index` belongs to this shard.
    pub fn contains(&self, index: usize) -> bool {
        index % self.count == self.index
    }
}

/// What the files of a variant say about it.
#[derive(Debug, Clone, PartialEq)]
pub enum State {
    /// Complete, with the variant's input hash: skipped.
    Done,
    Missing,
    /// The result file does not read back (truncated, corrupt).
    Unreadable(String),
    /// Written from a different scene text (the study or profile changed).
    Mismatch {
        stored: String,
    },
    /// Fewer or more solves than planned.
    Incomplete {
        found: usize,
        planned: usize,
    },
    /// The result is there, its tile (or another picture) is not.
    NoTile,
}

impl State {
    /// Why the variant has to be (re)done, for the log.
    pub fn reason(&self) -> String {
        match self {
            State::Done => "finished".into(),
            State::Missing => "no result yet".into(),
            State::Unreadable(e) => format!("result file unreadable (truncated or corrupt): {e}"),
            State::Mismatch { stored } => format!(
                "result was computed from a different configuration (stored input hash {}…)",
                &stored[..stored.len().min(12)]
            ),
            State::Incomplete { found, planned } => {
                format!("result holds {found} solves, {planned} planned")
            }
            State::NoTile => "tile picture missing".into(),
        }
    }
}

/// A variant's scene as the runner sees it: where its result goes, whether
/// it is finished and how to compute it. Implemented by the wave-optics
/// [`Scene`] here and by the effect paint's scene in
/// [`effect`](crate::study::effect).
pub trait RunScene: Sync {
    /// The result file: its lock is the variant's.
    fn result_path(&self) -> PathBuf;
    /// Every file a run writes (a killed run's temporaries of them are
    /// removed before it is redone).
    fn files(&self) -> Vec<PathBuf>;
    /// What its files say about it.
    fn state(&self) -> State;
    /// Compute it and write its files, quietly, held to `memory`.
    fn run(&self, memory: Option<MemoryLimit>) -> Result<(), String>;
}

impl RunScene for Scene {
    fn result_path(&self) -> PathBuf {
        pipeline::result_paths(self).0
    }
    fn files(&self) -> Vec<PathBuf> {
        let (h5, png) = pipeline::result_paths(self);
        vec![h5, png]
    }
    fn state(&self) -> State {
        let (h5, png) = pipeline::result_paths(self);
        if !h5.exists() {
            return State::Missing;
        }
        match h5::read_summary(&h5) {
            Err(e) => State::Unreadable(e.to_string()),
            Ok(s) if s.input_hash != self.provenance.input_hash => State::Mismatch {
                stored: s.input_hash,
            },
            Ok(s) if !complete(self, s.entries.len()) => State::Incomplete {
                found: s.entries.len(),
                planned: pipeline::planned_solves(self),
            },
            // A stack solved layer by layer draws no tile (pipeline::output_files).
            Ok(_) if !png.is_file() && pipeline::output_files(self).contains(&png) => State::NoTile,
            Ok(_) => State::Done,
        }
    }
    fn run(&self, memory: Option<MemoryLimit>) -> Result<(), String> {
        pipeline::run_with(self, true, memory)
            .map(|_| ())
            .map_err(|e| e.to_string())
    }
}

/// Result and tile paths of a variant.
pub fn paths(v: &Variant) -> (PathBuf, PathBuf) {
    pipeline::result_paths(&v.scene)
}

/// Read the state of a variant from its files.
pub fn state<S: RunScene>(v: &Variant<S>) -> State {
    v.scene.state()
}

/// Whether a result with `entries` solves is a whole run of `scene`: every
/// planned solve, or with a realisation target whole realisations between
/// the target's minimum and the most allowed (the run stops when the
/// colour is certain enough).
fn complete(scene: &crate::config::Scene, entries: usize) -> bool {
    let plan = pipeline::RunPlan::of(scene);
    let planned = plan.solves(scene);
    match scene.realisation_target {
        // A layer the same in every realisation (homogeneous, explicit)
        // runs one whatever the target: all of its solves.
        Some(t) if plan.realisations > 1 => {
            let per = planned / plan.realisations;
            per > 0
                && entries.is_multiple_of(per)
                && (t.min.min(plan.realisations)..=plan.realisations).contains(&(entries / per))
        }
        _ => entries == planned,
    }
}

/// How a run goes.
#[derive(Debug, Clone, Copy)]
pub struct RunOptions {
    /// Variants run at the same time (≥ 1).
    pub jobs: usize,
    pub shard: Shard,
    /// No progress output (tests).
    pub quiet: bool,
    /// The memory each variant is held to ([`pipeline::memory::preflight`]).
    pub memory: Option<MemoryLimit>,
}

/// What happened to one variant.
#[derive(Debug, Clone)]
pub struct Outcome {
    pub name: String,
    /// State found before the run.
    pub before: State,
    /// `None`: skipped (already done); `Some(Ok(seconds))`; `Some(Err(message))`.
    pub result: Option<Result<f64, String>>,
}

/// The report of a run.
#[derive(Debug, Clone)]
pub struct RunReport {
    /// One per variant of the shard, in expansion order.
    pub outcomes: Vec<Outcome>,
    pub wall_s: f64,
    pub jobs: usize,
}

impl RunReport {
    pub fn failed(&self) -> impl Iterator<Item = (&str, &str)> {
        self.outcomes.iter().filter_map(|o| match &o.result {
            Some(Err(e)) => Some((o.name.as_str(), e.as_str())),
            _ => None,
        })
    }
    pub fn ran(&self) -> impl Iterator<Item = (&str, f64)> {
        self.outcomes.iter().filter_map(|o| match &o.result {
            Some(Ok(s)) => Some((o.name.as_str(), *s)),
            _ => None,
        })
    }
    pub fn skipped(&self) -> usize {
        self.outcomes.iter().filter(|o| o.result.is_none()).count()
    }

    /// The final report: counts, timings, failures (one line each).
    pub fn text(&self) -> String {
        let ran: Vec<(&str, f64)> = self.ran().collect();
        let failed: Vec<(&str, &str)> = self.failed().collect();
        let mut out = format!(
            "study run: {} variants in this shard: {} ran, {} skipped (already finished), {} \
             failed; wall {:.1} s with {} job(s)\n",
            self.outcomes.len(),
            ran.len(),
            self.skipped(),
            failed.len(),
            self.wall_s,
            self.jobs
        );
        if !ran.is_empty() {
            let total: f64 = ran.iter().map(|r| r.1).sum();
            let (slow, s) = ran
                .iter()
                .fold(("", 0.0), |a, r| if r.1 > a.1 { *r } else { a });
            out += &format!(
                "variant time: total {total:.1} s, mean {:.1} s, slowest {slow} {s:.1} s\n",
                total / ran.len() as f64
            );
        }
        for (n, e) in &failed {
            out += &format!("FAILED {n}: {e}\n");
        }
        out
    }
}

/// Run the variants of `opts.shard` that are not finished.
pub fn run_variants<S: RunScene>(variants: &[Variant<S>], opts: &RunOptions) -> RunReport {
    let start = Instant::now();
    let mine: Vec<&Variant<S>> = variants
        .iter()
        .filter(|v| opts.shard.contains(v.index))
        .collect();
    let states: Vec<State> = mine.iter().map(|v| state(v)).collect();
    let todo: Vec<usize> = (0..mine.len())
        .filter(|&i| states[i] != State::Done)
        .collect();
    let progress = if opts.quiet {
        Progress::hidden(todo.len() as u64, "study")
    } else {
        Progress::new(todo.len() as u64, "study")
    };
    let jobs = opts.jobs.max(1).min(todo.len().max(1));
    progress.log(&format!(
        "[inksim] study: {} variants in shard {}/{}: {} finished, {} to run, {} job(s)",
        mine.len(),
        opts.shard.index,
        opts.shard.count,
        mine.len() - todo.len(),
        todo.len(),
        jobs
    ));
    let results: Mutex<Vec<Option<Result<f64, String>>>> = Mutex::new(vec![None; mine.len()]);
    // Variants another process holds the lock of: taken up after the queue.
    let deferred: Mutex<Vec<usize>> = Mutex::new(Vec::new());
    let next = AtomicUsize::new(0);
    let finished = AtomicUsize::new(mine.len() - todo.len());
    let status = |finished: usize| {
        progress::set_status(format!(
            "{finished} of {} variants of this shard finished ({} before this run); run the \
             same command again to resume: finished variants are not redone",
            mine.len(),
            mine.len() - todo.len()
        ))
    };
    status(mine.len() - todo.len());
    let finish = |i: usize, r: Option<Result<f64, String>>| {
        if !matches!(r, Some(Err(_))) {
            status(finished.fetch_add(1, Ordering::SeqCst) + 1);
        }
        let name = &mine[i].name;
        let msg = match &r {
            None => format!("{name} finished by another run"),
            Some(Ok(t)) => format!("{name} done in {t:.1} s"),
            Some(Err(e)) => format!("{name} FAILED: {e}"),
        };
        if !matches!(r, Some(Ok(_))) {
            progress.log(&format!("[inksim] {msg}"));
        }
        progress.inc(1, &msg);
        if let Ok(mut g) = results.lock() {
            g[i] = r;
        }
    };
    // Run variant `i` while holding its lock, unless a run that held it
    // before us finished it (its state is read again under the lock).
    let run_locked = |i: usize, lock: OutputLock| {
        let v = mine[i];
        let now = state(v);
        if now == State::Done {
            finish(i, None);
            return;
        }
        progress.log(&format!("[inksim] start {}: {}", v.name, now.reason()));
        let r = run_one(v, opts.memory);
        drop(lock);
        finish(i, Some(r));
    };
    std::thread::scope(|s| {
        for _ in 0..jobs {
            s.spawn(|| {
                loop {
                    let k = next.fetch_add(1, Ordering::SeqCst);
                    let Some(&i) = todo.get(k) else { break };
                    let h5_path = mine[i].scene.result_path();
                    match OutputLock::try_acquire(&h5_path) {
                        Ok(Some(lock)) => run_locked(i, lock),
                        Ok(None) => {
                            progress.log(&format!(
                                "[inksim] {} is being computed by another run ({}); coming \
                                 back to it after the other variants",
                                mine[i].name,
                                lock::holder(&h5_path)
                            ));
                            if let Ok(mut d) = deferred.lock() {
                                d.push(i);
                            }
                        }
                        Err(e) => finish(i, Some(Err(e.to_string()))),
                    }
                }
                // Then wait for each variant another run holds: it is
                // skipped when that run finishes it, redone when it failed.
                // (The guard is released inside `pop`, not held over the wait.)
                let pop = || deferred.lock().ok().and_then(|mut d| d.pop());
                while let Some(i) = pop() {
                    let h5_path = mine[i].scene.result_path();
                    progress.log(&format!(
                        "[inksim] waiting for {} ({})",
                        mine[i].name,
                        lock::holder(&h5_path)
                    ));
                    match OutputLock::acquire(&h5_path) {
                        Ok(lock) => run_locked(i, lock),
                        Err(e) => finish(i, Some(Err(e.to_string()))),
                    }
                }
            });
        }
    });
    progress.finish("study shard done");
    let results = results.into_inner().unwrap_or_else(|e| e.into_inner());
    let outcomes = mine
        .iter()
        .zip(states)
        .zip(results)
        .map(|((v, before), result)| Outcome {
            name: v.name.clone(),
            before,
            result,
        })
        .collect();
    RunReport {
        outcomes,
        wall_s: start.elapsed().as_secs_f64(),
        jobs,
    }
}

/// Run one variant; a panic inside is caught so the others go on.
fn run_one<S: RunScene>(v: &Variant<S>, memory: Option<MemoryLimit>) -> Result<f64, String> {
    let t = Instant::now();
    // The caller holds the variant's lock: temporaries of its files are
    // left by a killed run.
    for p in v.scene.files() {
        for tmp in stale_temporaries(&p) {
            let _ = std::fs::remove_file(tmp);
        }
    }
    guarded(|| v.scene.run(memory).map(|()| t.elapsed().as_secs_f64()))
}

/// `f`'s result, with a panic inside it (on this thread or a rayon worker
/// it waits on) turned into an error naming the panic's message.
fn guarded<T>(f: impl FnOnce() -> Result<T, String>) -> Result<T, String> {
    match std::panic::catch_unwind(std::panic::AssertUnwindSafe(f)) {
        Ok(r) => r,
        Err(p) => Err(format!(
            "internal error (panic): {}",
            p.downcast_ref::<String>()
                .map(String::as_str)
                .or_else(|| p.downcast_ref::<&str>().copied())
                .unwrap_or("?")
        )),
    }
}

/// Default number of parallel variants: the smallest of the cores, what the
/// memory limit holds (all of `--max-memory`, 80 % of the machine's
/// available memory, over the largest per-variant estimate), and the
/// variants to run; at least 1.
pub fn default_jobs(
    threads: usize,
    peak_bytes: f64,
    to_run: usize,
    memory: Option<MemoryLimit>,
) -> usize {
    threads
        .min(jobs_memory_holds(peak_bytes, memory))
        .min(to_run)
        .max(1)
}

/// How many variants of `peak_bytes` each the memory limit holds at once.
pub fn jobs_memory_holds(peak_bytes: f64, memory: Option<MemoryLimit>) -> usize {
    memory
        .map(|m| {
            let usable = match m.source {
                LimitSource::Flag => m.bytes,
                LimitSource::Available => 0.8 * m.bytes,
            };
            (usable / peak_bytes.max(1.0)).floor() as usize
        })
        .unwrap_or(usize::MAX)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_panic_inside_a_variant_becomes_its_error_and_the_next_one_runs() {
        use rayon::prelude::*;
        // A panic in a rayon worker (where the solvers' loops run) reaches
        // the variant's thread and is caught there; the same thread then
        // runs the next variant as usual.
        let r: Result<f64, String> = guarded(|| {
            let s: usize = (0..64usize)
                .into_par_iter()
                .map(|i| {
                    if i == 37 {
                        panic!("index {i} out of range");
                    }
                    i
                })
                .sum();
            Ok(s as f64)
        });
        assert_eq!(
            r,
            Err("internal error (panic): index 37 out of range".into())
        );
        assert_eq!(
            guarded(|| -> Result<(), String> { std::panic::panic_any(7u8) }),
            Err("internal error (panic): ?".into())
        );
        assert_eq!(guarded(|| Ok::<_, String>(2.0)), Ok(2.0));
        assert_eq!(
            guarded(|| Err::<f64, _>("bad".to_string())),
            Err("bad".into())
        );
    }

    #[test]
    fn shards_parse_and_partition() {
        assert_eq!(Shard::parse("1/3"), Ok(Shard { index: 1, count: 3 }));
        assert!(Shard::parse("3/3").is_err());
        assert!(Shard::parse("0/0").is_err());
        assert!(Shard::parse("x").is_err());
        let s: Vec<usize> = (0..7)
            .filter(|&i| Shard::parse("1/3").unwrap().contains(i))
            .collect();
        assert_eq!(s, [1, 4]);
        let env = |k: &str| match k {
            "SLURM_ARRAY_TASK_ID" => Some("5".to_string()),
            "SLURM_ARRAY_TASK_COUNT" => Some("4".to_string()),
            "SLURM_ARRAY_TASK_MIN" => Some("3".to_string()),
            _ => None,
        };
        assert_eq!(Shard::from_env(env), Ok(Some(Shard { index: 2, count: 4 })));
        assert_eq!(Shard::from_env(|_| None), Ok(None));
    }
}
