//! Scenarios: one simulation described in YAML (`granflow simulate <scenario.yaml>`), validated and turned into the
//! engine's configuration and initial particles. The campaign layer will embed the same spec as its `base`.

mod build;
pub mod gas;
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
    parse_yaml(text, path)
}

/// Parses YAML text into `T` (unknown keys rejected by `T`'s serde attributes); errors carry the file, line and
/// column, and an unknown key gets a "did you mean" when a known key is close to it.
pub fn parse_yaml<T: serde::de::DeserializeOwned>(text: &str, path: &Path) -> Result<T, ConfigError> {
    // Enums are written as single-key maps (`normal: { hertz: { restitution: 0.9 } }`), the form the model names
    // take everywhere else, rather than serde_norway's default YAML tags (`!hertz`).
    let de = serde_norway::Deserializer::from_str(text);
    serde_norway::with::singleton_map_recursive::deserialize(de).map_err(|e: serde_norway::Error| {
        let (line, column) = e.location().map_or((0, 0), |l| (l.line(), l.column()));
        ConfigError::Yaml {
            path: path.to_path_buf(),
            line,
            column,
            message: with_suggestion(e.to_string()),
        }
    })
}

/// Appends "did you mean `x`?" to serde's "unknown field `y`, expected one of `a`, `b`" (or "unknown variant")
/// when one of the known names is close.
pub fn with_suggestion(message: String) -> String {
    let Some(rest) = ["unknown field `", "unknown variant `"]
        .iter()
        .find_map(|prefix| message.find(prefix).map(|i| &message[i + prefix.len()..]))
    else {
        return message;
    };
    let Some(end) = rest.find('`') else {
        return message;
    };
    let word = &rest[..end];
    // After the word: "`, expected one of `a`, `b` at line ..." — the names are every other piece between backticks.
    let known: Vec<&str> = rest[end..].split('`').skip(2).step_by(2).collect();
    match crate::campaign::sweep::did_you_mean(word, &known) {
        Some(k) if k != word => format!("{message}; did you mean `{k}`?"),
        _ => message,
    }
}

/// Reads, parses and validates a scenario file.
pub fn load(path: &Path) -> Result<BuiltScenario, ConfigError> {
    let text = std::fs::read_to_string(path).map_err(|source| ConfigError::Read {
        path: path.to_path_buf(),
        source,
    })?;
    build(parse(&text, path)?, path)
}
