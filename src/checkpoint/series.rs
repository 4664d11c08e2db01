//! [`CheckpointSeries`]: the rotating checkpoints of one run in one directory, and finding the newest good one.
//!
//! Files are named `ckpt-{step:012}.h5`, so that they sort by step; anything else in the directory (temporary
//! `*.h5.tmp` files of an interrupted write, logs, results) is ignored.

use std::path::{Path, PathBuf};

use super::{CheckpointError, CheckpointMeta, read_checkpoint, write_checkpoint};
use crate::engine::SimState;

const PREFIX: &str = "ckpt-";
const SUFFIX: &str = ".h5";

/// Checkpoints of one run in a directory: files `ckpt-{step:012}.h5`, keeping the newest `keep`.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct CheckpointSeries {
    dir: PathBuf,
    keep: usize,
}

/// A checkpoint that was read and verified by [`CheckpointSeries::latest_valid`].
#[derive(Debug)]
pub struct LoadedCheckpoint {
    /// The file the state was read from.
    pub path: PathBuf,
    pub state: SimState,
    pub meta: CheckpointMeta,
    /// Why each newer checkpoint was rejected, newest first (each error names its file).
    pub rejected: Vec<CheckpointError>,
}

/// The step encoded in a checkpoint file name, or `None` if `name` is not one.
fn parse_step(name: &str) -> Option<u64> {
    let digits = name.strip_prefix(PREFIX)?.strip_suffix(SUFFIX)?;
    if digits.is_empty() || !digits.bytes().all(|b| b.is_ascii_digit()) {
        return None;
    }
    digits.parse().ok()
}

impl CheckpointSeries {
    /// A series in `dir` keeping the newest `keep` checkpoints (a `keep` of 0 is taken as 1). Touches nothing on
    /// disk; the directory is created by the first [`CheckpointSeries::write`].
    pub fn new(dir: impl Into<PathBuf>, keep: usize) -> Self {
        CheckpointSeries {
            dir: dir.into(),
            keep: keep.max(1),
        }
    }

    /// The directory holding the checkpoints.
    pub fn dir(&self) -> &Path {
        &self.dir
    }

    /// How many checkpoints are kept.
    pub fn keep(&self) -> usize {
        self.keep
    }

    /// The file of the checkpoint at `step`: `<dir>/ckpt-{step:012}.h5`.
    pub fn path_for_step(&self, step: u64) -> PathBuf {
        self.dir.join(format!("{PREFIX}{step:012}{SUFFIX}"))
    }

    /// Writes the checkpoint for `state.step` (creating the directory if needed, replacing a checkpoint of the same
    /// step), then deletes the oldest checkpoints beyond `keep`, only after the new one is renamed into place. The
    /// file just written is never deleted, even if files of later steps (from an abandoned continuation of the
    /// run) are present. Returns the path written.
    pub fn write(&self, state: &SimState, meta: &CheckpointMeta) -> Result<PathBuf, CheckpointError> {
        std::fs::create_dir_all(&self.dir)
            .map_err(|e| CheckpointError::io(&self.dir, "creating the checkpoint directory", e))?;
        let path = self.path_for_step(state.step);
        write_checkpoint(&path, state, meta)?;
        let others = self.list()?.into_iter().filter(|(step, _)| *step != state.step);
        for (_, old) in others.skip(self.keep - 1) {
            match std::fs::remove_file(&old) {
                Ok(()) => {}
                // Someone else (a concurrent cleanup) removed it already: the goal is reached.
                Err(e) if e.kind() == std::io::ErrorKind::NotFound => {}
                Err(e) => return Err(CheckpointError::io(&old, "deleting an old checkpoint", e)),
            }
        }
        Ok(path)
    }

    /// All checkpoint files present, newest first (by the step parsed from the name). Temporary files and other
    /// files are ignored; a missing directory has no checkpoints.
    pub fn list(&self) -> Result<Vec<(u64, PathBuf)>, CheckpointError> {
        let entries = match std::fs::read_dir(&self.dir) {
            Ok(entries) => entries,
            Err(e) if e.kind() == std::io::ErrorKind::NotFound => return Ok(Vec::new()),
            Err(e) => {
                return Err(CheckpointError::io(&self.dir, "listing the checkpoint directory", e));
            }
        };
        let mut found = Vec::new();
        for entry in entries {
            let entry = entry.map_err(|e| CheckpointError::io(&self.dir, "listing the checkpoint directory", e))?;
            let Some(step) = entry.file_name().to_str().and_then(parse_step) else {
                continue;
            };
            let is_dir = entry.file_type().map(|t| t.is_dir()).unwrap_or(false);
            if !is_dir {
                found.push((step, entry.path()));
            }
        }
        found.sort_by(|a, b| b.cmp(a));
        Ok(found)
    }

    /// The newest checkpoint that reads and verifies (including that the state's step matches the file name),
    /// plus the errors of every newer one that was rejected, so that the caller can report
    /// "ckpt-…: corrupt (…), using ckpt-… instead". `Ok(None)` if there is no checkpoint or none is valid; in the
    /// latter case each rejection is logged as a warning, since there is no [`LoadedCheckpoint`] to carry it.
    pub fn latest_valid(&self) -> Result<Option<LoadedCheckpoint>, CheckpointError> {
        let mut rejected = Vec::new();
        for (step, path) in self.list()? {
            match read_checkpoint(&path) {
                Ok((state, _)) if state.step != step => rejected.push(CheckpointError::corrupt(
                    &path,
                    format!("the file name says step {step} but the state is at step {}", state.step),
                )),
                Ok((state, meta)) => {
                    return Ok(Some(LoadedCheckpoint {
                        path,
                        state,
                        meta,
                        rejected,
                    }));
                }
                Err(e) => rejected.push(e),
            }
        }
        for e in &rejected {
            tracing::warn!("rejected checkpoint: {e}");
        }
        Ok(None)
    }
}
