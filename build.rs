//! Records which source built the binary: the git commit of the tree and whether the files that go into the binary
//! (`src/`, `build.rs`, `Cargo.toml`, `Cargo.lock`, `benches/liggghts/`) differed from it. Read by
//! `src/provenance.rs`; every job's `result.json`, the database's attempts and every report record it.

use std::process::Command;

fn git(args: &[&str]) -> Option<String> {
    let out = Command::new("git").args(args).output().ok()?;
    out.status
        .success()
        .then(|| String::from_utf8_lossy(&out.stdout).trim().to_string())
}

fn main() {
    // Rerun when the commit, the index or the binary's sources change (any of these can change the answer).
    for path in ["src", "build.rs", "Cargo.toml", "Cargo.lock", "benches/liggghts"] {
        println!("cargo:rerun-if-changed={path}");
    }
    if let Some(git_dir) = git(&["rev-parse", "--git-dir"]) {
        for file in ["HEAD", "index", "refs", "packed-refs"] {
            println!("cargo:rerun-if-changed={git_dir}/{file}");
        }
    }
    let commit = git(&["rev-parse", "HEAD"]).unwrap_or_else(|| "unknown".into());
    let dirty = git(&[
        "status",
        "--porcelain",
        "--untracked-files=no",
        "--",
        "src",
        "build.rs",
        "Cargo.toml",
        "Cargo.lock",
        "benches/liggghts",
    ])
    .map_or("unknown", |s| if s.is_empty() { "clean" } else { "dirty" });
    println!("cargo:rustc-env=GRANFLOW_GIT_COMMIT={commit}");
    println!("cargo:rustc-env=GRANFLOW_GIT_TREE={dirty}");
}
