//! `schemas/campaign.schema.json` is the schema the code generates (set GRANFLOW_UPDATE_SCHEMA=1 to rewrite it), and
//! every campaign file in `campaigns/` validates against it and parses.

use std::path::{Path, PathBuf};

fn campaign_files(dir: &Path, out: &mut Vec<PathBuf>) {
    for entry in std::fs::read_dir(dir).unwrap() {
        let path = entry.unwrap().path();
        if path.is_dir() {
            campaign_files(&path, out);
        } else if path.extension().is_some_and(|e| e == "yaml" || e == "yml") {
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
    let mut files = Vec::new();
    campaign_files(&root.join("campaigns"), &mut files);
    assert!(!files.is_empty());
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
}
