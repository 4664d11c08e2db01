//! Scenarios: one simulation described in YAML (`granflow simulate <scenario.yaml>`), validated and turned into the
//! engine's configuration and initial particles. The campaign layer will embed the same spec as its `base`.

mod build;
pub mod spec;

use std::path::{Path, PathBuf};

pub use build::{BuiltScenario, build};
pub use spec::ScenarioSpec;

/// Invalid input, found before anything runs or is written.
#[derive(Debug, thiserror::Error)]
pub enum ConfigError {
    #[error("cannot read {}: {source}", path.display())]
    Read {
        path: PathBuf,
        #[source]
        source: std::io::Error,
    },
    #[error("{}:{line}:{column}: {message}", path.display())]
    Yaml {
        path: PathBuf,
        line: usize,
        column: usize,
        message: String,
    },
    #[error("{}: key `{key}`: {message}", path.display())]
    Invalid {
        path: PathBuf,
        key: String,
        message: String,
    },
}

/// Parses scenario YAML text; `path` is used in messages only.
pub fn parse(text: &str, path: &Path) -> Result<ScenarioSpec, ConfigError> {
    // Enums are written as single-key maps (`normal: { hertz: { restitution: 0.9 } }`), the form the model names
    // take everywhere else, rather than serde_norway's default YAML tags (`!hertz`).
    let de = serde_norway::Deserializer::from_str(text);
    serde_norway::with::singleton_map_recursive::deserialize(de).map_err(|e: serde_norway::Error| {
        let (line, column) = e.location().map_or((0, 0), |l| (l.line(), l.column()));
        ConfigError::Yaml {
            path: path.to_path_buf(),
            line,
            column,
            message: e.to_string(),
        }
    })
}

/// Reads, parses and validates a scenario file.
pub fn load(path: &Path) -> Result<BuiltScenario, ConfigError> {
    let text = std::fs::read_to_string(path).map_err(|source| ConfigError::Read {
        path: path.to_path_buf(),
        source,
    })?;
    build(parse(&text, path)?, path)
}
