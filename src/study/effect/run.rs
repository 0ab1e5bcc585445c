//! An effect paint as a study's variant: its files (the result, the
//! patches, the flop plot), its state read back from them, its run by the
//! fast model.

use crate::config::paint::PaintScene;
use crate::output::h5;
use crate::pipeline::{self, memory::MemoryLimit};
use crate::study::run::{RunScene, State};
use std::path::PathBuf;

impl RunScene for PaintScene {
    fn result_path(&self) -> PathBuf {
        let [h5, ..] = pipeline::paint_files(self);
        h5
    }
    fn files(&self) -> Vec<PathBuf> {
        pipeline::paint_files(self).to_vec()
    }
    /// Done when the result reads back with this scene's input hash and
    /// its pictures (patches, flop curves, sparkle texture) exist.
    fn state(&self) -> State {
        let [path, patches, flop, sparkle] = pipeline::paint_files(self);
        if !path.exists() {
            return State::Missing;
        }
        match h5::read_paint(&path) {
            Err(e) => State::Unreadable(e.to_string()),
            Ok(r) if r.input_hash != self.provenance.input_hash => State::Mismatch {
                stored: r.input_hash,
            },
            Ok(_) if !patches.is_file() || !flop.is_file() || !sparkle.is_file() => State::NoTile,
            Ok(_) => State::Done,
        }
    }
    /// The fast model holds a few MB per variant (`plan` measures it), far
    /// below any memory limit: `memory` is not checked.
    fn run(&self, _memory: Option<MemoryLimit>) -> Result<(), String> {
        pipeline::run_paint(self, true)
            .map(|_| ())
            .map_err(|e| e.to_string())
    }
}
