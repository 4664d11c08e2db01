//! `schemas/campaign.schema.json` is the schema the code generates (set GRANFLOW_UPDATE_SCHEMA=1 to rewrite it), and
//! every campaign file in `campaigns/` and `research/` (the probes) validates against it and parses.

use std::path::{Path, PathBuf};

/// Every committed campaign file: the product's (`campaigns/`) and the probes' (`research/`).
fn committed_campaign_files(root: &Path) -> Vec<PathBuf> {
    let mut files = Vec::new();
    for dir in ["campaigns", "research"] {
        campaign_files(&root.join(dir), &mut files);
    }
    files.sort();
    files
}

fn campaign_files(dir: &Path, out: &mut Vec<PathBuf>) {
    for entry in std::fs::read_dir(dir).unwrap() {
        let path = entry.unwrap().path();
        if path.is_dir() {
            campaign_files(&path, out);
        } else if path.extension().is_some_and(|e| e == "yaml" || e == "yml") && !is_scenario(&path) {
            out.push(path);
        }
    }
}

/// A scenario file (a top-level `domain`) rather than a campaign, e.g. research's single runs.
fn is_scenario(path: &Path) -> bool {
    let text = std::fs::read_to_string(path).unwrap();
    let doc: serde_json::Value = serde_norway::from_str(&text).unwrap();
    doc.get("domain").is_some()
}

/// The scenario files under `research/`.
fn research_scenarios(dir: &Path, out: &mut Vec<PathBuf>) {
    for entry in std::fs::read_dir(dir).unwrap() {
        let path = entry.unwrap().path();
        if path.is_dir() {
            research_scenarios(&path, out);
        } else if path.extension().is_some_and(|e| e == "yaml" || e == "yml") && is_scenario(&path) {
            out.push(path);
        }
    }
}

#[test]
fn the_committed_schema_is_the_generated_one() {
    let root = Path::new(env!("CARGO_MANIFEST_DIR"));
    let path = root.join("schemas/campaign.schema.json");
    let generated = serde_json::to_string_pretty(&granflow::campaign::json_schema()).unwrap() + "\n";
    if std::env::var_os("GRANFLOW_UPDATE_SCHEMA").is_some() {
        std::fs::write(&path, &generated).unwrap();
    }
    let committed = std::fs::read_to_string(&path).unwrap_or_default();
    assert!(
        committed == generated,
        "{} is out of date: run GRANFLOW_UPDATE_SCHEMA=1 cargo test --release --test campaign_schema",
        path.display()
    );
}

#[test]
fn every_campaign_file_validates_against_the_schema_and_parses() {
    let root = Path::new(env!("CARGO_MANIFEST_DIR"));
    let schema = granflow::campaign::json_schema();
    let validator = jsonschema::validator_for(&schema).expect("the schema is a valid JSON Schema");
    let files = committed_campaign_files(root);
    assert!(
        files.iter().any(|f| f.starts_with(root.join("research"))),
        "no probe campaign found"
    );
    for file in files {
        let text = std::fs::read_to_string(&file).unwrap();
        let doc: serde_json::Value = serde_norway::from_str(&text).unwrap();
        let errors: Vec<String> = validator
            .iter_errors(&doc)
            .map(|e| format!("{} at {}", e, e.instance_path()))
            .collect();
        assert!(errors.is_empty(), "{}: {}", file.display(), errors.join("; "));
        granflow::campaign::load(&file).unwrap_or_else(|e| panic!("{}: {e}", file.display()));
    }
}

/// Every committed campaign's every job, and every committed scenario, passes the whole validation (particles
/// built, the bounds of physics and memory checked): a new bound must not refuse a run the project ships.
#[test]
fn every_committed_job_and_scenario_validates() {
    let root = Path::new(env!("CARGO_MANIFEST_DIR"));
    for file in committed_campaign_files(root) {
        let campaign = granflow::campaign::load(&file).unwrap_or_else(|e| panic!("{}: {e}", file.display()));
        granflow::campaign::validate_jobs(&campaign, &campaign.jobs, &file)
            .unwrap_or_else(|e| panic!("{}: {e}", file.display()));
    }
    for entry in std::fs::read_dir(root.join("scenarios")).expect("scenarios/") {
        let file = entry.expect("entry").path();
        if file.extension().is_some_and(|e| e == "yaml") {
            granflow::scenario::load(&file).unwrap_or_else(|e| panic!("{}: {e}", file.display()));
        }
    }
    let mut research = Vec::new();
    research_scenarios(&root.join("research"), &mut research);
    for file in research {
        granflow::scenario::load(&file).unwrap_or_else(|e| panic!("{}: {e}", file.display()));
    }
}

#[test]
fn the_schema_rejects_what_the_parser_rejects() {
    let schema = granflow::campaign::json_schema();
    let validator = jsonschema::validator_for(&schema).unwrap();
    let root = Path::new(env!("CARGO_MANIFEST_DIR"));
    let text = std::fs::read_to_string(root.join("campaigns/quickstart.yaml")).unwrap();
    let mut doc: serde_json::Value = serde_norway::from_str(&text).unwrap();
    doc["sweep"]["grid"][0]["valuez"] = serde_json::json!([1.0]);
    assert!(!validator.is_valid(&doc), "an unknown key in a sweep node");
    let mut doc: serde_json::Value = serde_norway::from_str(&text).unwrap();
    doc["base"]["species"][0]["radius_m"] = serde_json::json!("big");
    assert!(!validator.is_valid(&doc), "a string for a number");
    let mut doc: serde_json::Value = serde_norway::from_str(&text).unwrap();
    doc["metrics"] = serde_json::json!(["lacey_index", "kinetic_energy_j"]);
    assert!(validator.is_valid(&doc), "known metric names");
    doc["metrics"] = serde_json::json!(["kinetic_energi_j"]);
    assert!(!validator.is_valid(&doc), "an unknown metric name");
}

/// A sweep may set an optional section the base leaves out (`cohesion` here: none, or a whole model), and an
/// unknown top-level key is still refused with the keys that exist.
#[test]
fn a_sweep_sets_an_optional_section_whole() {
    let text = |param: &str| {
        format!(
            r#"
name: sections
base:
  domain: {{ lo_m: [0.0, 0.0, 0.0], hi_m: [0.01, 0.01, 0.01] }}
  gravity: {{ vector_m_per_s2: [0.0, -9.81, 0.0] }}
  species:
    - {{ name: s, radius_m: 0.001, density_kg_per_m3: 2500.0, youngs_modulus_pa: 1.0e7, poisson_ratio: 0.3, friction_coefficient: 0.3 }}
  contact: {{ normal: {{ hertz: {{ restitution: 0.8 }} }}, tangential: mindlin }}
  fill:
    - lattice: {{ species: s, spacing_m: 0.003, lo_m: [0.0, 0.0, 0.0], hi_m: [0.01, 0.01, 0.01], origin_m: [0.0015, 0.0015, 0.0015] }}
  time: {{ dt_s: 1.0e-5, end_time_s: 0.001 }}
sweep:
  param: {param}
  values:
    - null
    - {{ hamaker: {{ constant_j: 1.0e-19, inner_cutoff_m: 4.0e-10, outer_cutoff_m: 1.0e-6 }} }}
metrics: [kinetic_energy_j]
"#
        )
    };
    let path = std::path::Path::new("sections.yaml");
    let campaign = granflow::campaign::from_yaml(&text("cohesion"), path).expect("the sweep expands");
    assert_eq!(campaign.jobs.len(), 2);
    assert!(campaign.jobs[0].scenario.cohesion.is_none());
    assert_eq!(campaign.jobs[1].scenario.cohesion.map(|c| c.name()), Some("hamaker"));
    let err = granflow::campaign::from_yaml(&text("cohesoin"), path).expect_err("a typo is refused");
    let message = err.to_string();
    assert!(
        message.contains("sweep") && message.contains("no `cohesoin`") && message.contains("did you mean `cohesion`"),
        "{message}"
    );
}

/// `granflow schema | head -1`: a reader that closes the pipe early ends the command quietly (exit 0, no panic),
/// as it would any Unix tool. The schema is larger than a pipe's buffer, so the write does meet the closed pipe.
#[test]
fn schema_into_a_reader_that_stops_early_exits_quietly() {
    use std::io::Read;
    use std::process::{Command, Stdio};
    let schema_len = serde_json::to_string_pretty(&granflow::campaign::json_schema())
        .unwrap()
        .len();
    assert!(
        schema_len > 1 << 16,
        "the schema ({schema_len} bytes) no longer fills a pipe's buffer"
    );
    let mut child = Command::new(env!("CARGO_BIN_EXE_granflow"))
        .arg("schema")
        .stdout(Stdio::piped())
        .stderr(Stdio::piped())
        .spawn()
        .expect("the granflow binary runs");
    let mut first = [0u8; 1];
    child.stdout.take().unwrap().read_exact(&mut first).unwrap();
    assert_eq!(&first, b"{");
    let out = child.wait_with_output().unwrap();
    let stderr = String::from_utf8_lossy(&out.stderr);
    assert!(out.status.success(), "exit {:?}: {stderr}", out.status.code());
    assert!(stderr.is_empty(), "stderr: {stderr}");
}
