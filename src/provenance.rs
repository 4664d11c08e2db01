//! Which build of granflow made a result: its version, the git commit of its source and whether that source
//! differed from the commit (captured by `build.rs`). Every job's `result.json`, the database's attempts, every
//! `simulate` summary and every `granflow report` record it, so that numbers that move with the engine's last bits
//! can be traced to the build that made them.

/// The version from `Cargo.toml`.
pub const VERSION: &str = env!("CARGO_PKG_VERSION");
/// The full git commit of the source, or `unknown` (built outside a git checkout).
pub const COMMIT: &str = env!("GRANFLOW_GIT_COMMIT");
/// `clean` (the binary's sources are the commit's), `dirty` (they differed) or `unknown`.
pub const TREE: &str = env!("GRANFLOW_GIT_TREE");

/// This build, as one token: `0.1.0+929e43a12345` for a clean tree, `0.1.0+929e43a12345.dirty` when the sources
/// differed from the commit, `0.1.0+unknown` outside git.
pub fn build_id() -> String {
    let short = COMMIT.get(..12).unwrap_or(COMMIT);
    match TREE {
        "dirty" => format!("{VERSION}+{short}.dirty"),
        _ => format!("{VERSION}+{short}"),
    }
}

/// Which compilation of the force loop this process runs (see [`crate::machine::cpu_fast_path`]).
pub fn cpu_path() -> &'static str {
    if crate::machine::cpu_fast_path() {
        "x86-64-v3"
    } else {
        "x86-64"
    }
}

#[cfg(test)]
mod tests {
    #[test]
    fn the_build_id_names_the_version_and_a_commit() {
        let id = super::build_id();
        assert!(id.starts_with(&format!("{}+", super::VERSION)), "{id}");
        let commit = super::COMMIT;
        assert!(
            commit == "unknown" || (commit.len() == 40 && commit.chars().all(|c| c.is_ascii_hexdigit())),
            "{commit}"
        );
        assert!(["clean", "dirty", "unknown"].contains(&super::TREE));
    }
}
