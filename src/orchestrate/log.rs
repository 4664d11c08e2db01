//! The campaign log: `tracing` events of the dispatcher, appended to `<campaign>/campaign.log`.

use std::path::Path;
use std::sync::Mutex;

/// Starts logging to `path` for the rest of the process (a no-op if a subscriber is already installed, as in tests
/// that run several campaigns in one process). The returned value keeps nothing alive; it marks the scope.
pub fn init(path: &Path) -> Option<()> {
    let file = std::fs::OpenOptions::new().create(true).append(true).open(path).ok()?;
    let subscriber = tracing_subscriber::fmt()
        .with_writer(Mutex::new(file))
        .with_ansi(false)
        .with_target(false)
        .finish();
    tracing::subscriber::set_global_default(subscriber).ok()
}
