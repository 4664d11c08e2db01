//! Scenarios: one simulation described in YAML (`granflow simulate <scenario.yaml>`), validated and turned into the
//! engine's configuration and initial particles. A campaign file embeds the same spec as its `base`.
//!
//! What does not live here: sweeps and jobs (`crate::campaign`), and the closest-name search behind the "did you
//! mean" of unknown keys (`crate::util::did_you_mean`).

mod build;
pub mod drying;
pub mod gas;
mod heat;
mod locate;
pub mod spec;

use std::path::{Path, PathBuf};

pub use build::{BuiltScenario, build, estimated_memory_bytes};
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
    #[error("{}{}: key `{key}`: {message}", path.display(), at.map_or(String::new(), |(l, c)| format!(":{l}:{c}")))]
    Invalid {
        path: PathBuf,
        /// Line and column (1-based) of the value in the file, where it is written there (see [`ConfigError::at`]).
        at: Option<(usize, usize)>,
        key: String,
        message: String,
    },
}

impl ConfigError {
    /// A value that is not valid, at `key` of the file `path` (located later by [`ConfigError::at`]).
    pub fn invalid(path: &Path, key: impl Into<String>, message: impl Into<String>) -> Self {
        ConfigError::Invalid {
            path: path.to_path_buf(),
            at: None,
            key: key.into(),
            message: message.into(),
        }
    }

    /// Gives an [`ConfigError::Invalid`] the line and column where `yaml`, the text of its file, writes the value
    /// at `written_key` (or its nearest written parent). Other errors are returned as they are.
    pub fn at(self, yaml: &str, written_key: &str) -> Self {
        match self {
            ConfigError::Invalid {
                path,
                at: None,
                key,
                message,
            } => ConfigError::Invalid {
                path,
                at: locate::locate(yaml, written_key),
                key,
                message,
            },
            other => other,
        }
    }

    /// As [`ConfigError::at`], with the error's own key as the written one.
    pub fn located(self, yaml: &str) -> Self {
        match &self {
            ConfigError::Invalid { key, .. } => {
                let key = key.clone();
                self.at(yaml, &key)
            }
            _ => self,
        }
    }
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
        // The location leads the message already (`file:line:column:`), so serde_norway's own copy of it goes.
        let message = e
            .to_string()
            .replacen(&format!(" at line {line} column {column}"), "", 1);
        ConfigError::Yaml {
            path: path.to_path_buf(),
            line,
            column,
            message: with_suggestion(plain_expectation(message)),
        }
    })
}

/// Says "expected a mapping of keys" where serde names the Rust type it wanted (`expected struct ScenarioSpec`).
fn plain_expectation(message: String) -> String {
    const STRUCT: &str = "expected struct ";
    let Some(i) = message.find(STRUCT) else {
        return message;
    };
    let rest = &message[i + STRUCT.len()..];
    let end = rest
        .find(|c: char| !(c.is_alphanumeric() || c == '_'))
        .unwrap_or(rest.len());
    format!("{}expected a mapping of keys{}", &message[..i], &rest[end..])
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
    match crate::util::did_you_mean(word, &known) {
        Some(k) if k != word => format!("{message}; did you mean `{k}`?"),
        _ => message,
    }
}

/// The largest input file (scenario or campaign) read: 64 MiB. A campaign's explicit list of ten thousand points or
/// a fill of a hundred thousand explicit particles is a few megabytes; parsing takes several times a file's size in
/// memory, so a file of gigabytes is refused before it is read.
pub const MAX_INPUT_BYTES: u64 = 64 << 20;

/// Reads an input file as text, refusing one larger than [`MAX_INPUT_BYTES`] before reading it.
pub fn read_input(path: &Path) -> Result<String, ConfigError> {
    let read_error = |source| ConfigError::Read {
        path: path.to_path_buf(),
        source,
    };
    let size = std::fs::metadata(path).map_err(read_error)?.len();
    if size > MAX_INPUT_BYTES {
        return Err(ConfigError::Yaml {
            path: path.to_path_buf(),
            line: 1,
            column: 1,
            message: format!(
                "the file is {size} bytes, more than the {MAX_INPUT_BYTES} an input file may have; is it the \
                 right file?"
            ),
        });
    }
    std::fs::read_to_string(path).map_err(read_error)
}

/// Reads, parses and validates a scenario file.
pub fn load(path: &Path) -> Result<BuiltScenario, ConfigError> {
    let text = read_input(path)?;
    build(parse(&text, path)?, path).map_err(|e| e.located(&text))
}
