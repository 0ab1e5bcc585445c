//! Runs on a thread pool of a given size, for the checks that results do
//! not depend on the number of threads.

/// `f` run on a fresh pool of `threads` threads.
pub fn on_threads<T: Send>(threads: usize, f: impl FnOnce() -> T + Send) -> T {
    rayon::ThreadPoolBuilder::new()
        .num_threads(threads)
        .build()
        .unwrap()
        .install(f)
}
