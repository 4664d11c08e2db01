//! Writing a whole file atomically: to a temporary name beside it, synced, then renamed over it. A reader (or a
//! process restarted after a kill) finds the old file or the new one, never a part; this is what makes a job's
//! `result.json`, a run's `summary.json` and the rewritten `series.csv` safe against `kill -9`.
//!
//! What does not live here: checkpoints, which have their own seal and checksum (`crate::checkpoint`).

use std::io::Write;
use std::path::{Path, PathBuf};

/// A step of [`write_atomic`] failed (`crate::Error` turns it into its `Io` variant, with the same message).
#[derive(Debug, thiserror::Error)]
#[error("{action} {path}: {source}", path = path.display())]
pub struct AtomicWriteError {
    /// `create`, `write`, `sync` or `rename`.
    pub action: &'static str,
    /// The temporary file, or for `rename` the file written.
    pub path: PathBuf,
    #[source]
    pub source: std::io::Error,
}

/// Writes `bytes` to `path` through a temporary file (`path` with the extension `tmp`) and a rename.
pub fn write_atomic(path: &Path, bytes: &[u8]) -> Result<(), AtomicWriteError> {
    let tmp = path.with_extension("tmp");
    let failed = |action: &'static str, path: &Path| {
        let path = path.to_path_buf();
        move |source| AtomicWriteError { action, path, source }
    };
    let mut f = std::fs::File::create(&tmp).map_err(failed("create", &tmp))?;
    f.write_all(bytes).map_err(failed("write", &tmp))?;
    f.sync_all().map_err(failed("sync", &tmp))?;
    std::fs::rename(&tmp, path).map_err(failed("rename", path))
}

#[cfg(test)]
mod tests {
    use super::write_atomic;

    #[test]
    fn replaces_the_file_and_leaves_no_temporary_behind() {
        let dir = tempfile::tempdir().unwrap();
        let path = dir.path().join("result.json");
        write_atomic(&path, b"old").unwrap();
        write_atomic(&path, b"new").unwrap();
        assert_eq!(std::fs::read(&path).unwrap(), b"new");
        assert!(!dir.path().join("result.tmp").exists());
    }

    #[test]
    fn a_failure_names_the_file() {
        let dir = tempfile::tempdir().unwrap();
        let path = dir.path().join("missing-dir").join("summary.json");
        let err = write_atomic(&path, b"x").unwrap_err();
        assert_eq!(err.action, "create");
        assert!(
            err.to_string().starts_with("create ") && err.to_string().contains("summary.tmp"),
            "{err}"
        );
        let err = crate::Error::from(err);
        assert!(matches!(err, crate::Error::Io { action: "create", .. }), "{err}");
    }
}
