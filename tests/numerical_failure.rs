//! Numerical failures are typed errors naming the step and particle, with exit code 3, and the run stays resumable
//! (its last checkpoint is intact).

mod common;

use common::granflow;

/// A particle shot at a soft wall with a time step far too large for the contact: it passes deep into the wall.
/// (Slow enough, 0.5 mm per step against its 1 mm radius, that validation cannot refuse it beforehand.)
const TOO_FAST: &str = r#"
name: too-fast
domain: { lo_m: [0.0, 0.0, 0.0], hi_m: [0.05, 0.05, 0.05] }
gravity: { vector_m_per_s2: [0.0, 0.0, 0.0] }
species:
  - { name: s, radius_m: 0.001, density_kg_per_m3: 2500.0, youngs_modulus_pa: 1.0e5, poisson_ratio: 0.3, friction_coefficient: 0.3 }
contact: { normal: { hertz: { restitution: 0.9 } }, tangential: mindlin }
walls:
  - box: { species: s }
fill:
  - explicit: { species: s, positions_m: [[0.025, 0.025, 0.01]], velocities_m_per_s: [[0.0, 0.0, -5.0]] }
time: { dt_s: 1.0e-4, end_time_s: 0.01 }
output: { checkpoint_every_steps: 10 }
"#;

#[test]
fn excessive_overlap_or_lost_particle_is_reported_with_step_and_particle() {
    let tmp = tempfile::tempdir().expect("temp dir");
    std::fs::write(tmp.path().join("fast.yaml"), TOO_FAST).expect("write");
    let out = granflow(&["simulate", "fast.yaml", "--out", "run", "--quiet"], tmp.path());
    let stderr = String::from_utf8_lossy(&out.stderr);
    assert_eq!(out.status.code(), Some(3), "{stderr}");
    assert!(stderr.contains("particle 0") && stderr.contains("step"), "{stderr}");
    assert!(
        stderr.contains("excessive overlap") || stderr.contains("lost"),
        "{stderr}"
    );
    // The initial checkpoint is still there and valid.
    let series = granflow::checkpoint::CheckpointSeries::new(tmp.path().join("run"), 3);
    assert!(series.latest_valid().expect("lists").is_some());
}
