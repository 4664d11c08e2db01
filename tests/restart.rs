//! Exact restart and thread-count determinism, through the real binary where a fresh process matters.
//!
//! - 2N steps uninterrupted ≡ N steps, stop (checkpoint), resume in a fresh process, N more — every array
//!   bit-identical, for a drum with Thornton + Walton-Braun contacts and active baffles, switching thread counts
//!   across the restart.
//! - 1, 2 and 3 threads give bit-identical states after 1000 steps of a dense packing, whatever the ranges' shares.
//! - A corrupt newest checkpoint is reported by name and the previous one is used.

mod common;

use std::path::Path;

use common::{built, granflow_ok, simulation};
use granflow::checkpoint::{CheckpointSeries, read_checkpoint};
use granflow::engine::state::{SimState, first_difference};

const DRUM: &str = r#"
name: restart-drum
domain: { lo_m: [-0.041, -0.041, 0.0], hi_m: [0.041, 0.041, 0.012], periodic: [false, false, true] }
gravity: { vector_m_per_s2: [0.0, -9.81, 0.0] }
species:
  - { name: glass, radius_m: 0.0015, density_kg_per_m3: 2500.0, youngs_modulus_pa: 5.0e7, poisson_ratio: 0.3, friction_coefficient: 0.4, yield_force_n: 0.02 }
contact: { normal: { thornton: {} }, tangential: { walton_braun: {} } }
walls:
  - drum:
      name: drum
      species: glass
      axis_point_m: [0.0, 0.0, 0.0]
      axis: [0.0, 0.0, 1.0]
      radius_m: 0.04
      rotation_rpm: 120.0
      baffles:
        - traditional: { count: 4, length_m: 0.01, half_thickness_m: 0.001, tilt_deg: 20.0 }
        - axial: { count: 1, length_m: 0.03, half_thickness_m: 0.001 }
fill:
  - lattice: { species: glass, spacing_m: 0.003, lo_m: [-0.04, -0.04, 0.0], hi_m: [0.04, 0.002, 0.012], origin_m: [0.0, 0.0, 0.0015], inside_drum: drum }
time: { dt_s: 1.0e-5, end_time_s: 0.03 }
output: { checkpoint_every_steps: 500, keep_checkpoints: 2, series_every_steps: 100 }
seed: 3
"#;

fn final_state(dir: &Path) -> SimState {
    let series = CheckpointSeries::new(dir, 2);
    let loaded = series.latest_valid().expect("lists").expect("a checkpoint exists");
    assert!(loaded.rejected.is_empty());
    loaded.state
}

#[test]
fn restart_in_a_fresh_process_is_bit_identical() {
    let tmp = tempfile::tempdir().expect("temp dir");
    let dir = tmp.path();
    std::fs::write(dir.join("drum.yaml"), DRUM).expect("write scenario");

    granflow_ok(&["simulate", "drum.yaml", "--out", "whole", "--quiet"], dir);
    // N = 1500 steps with 2 threads, stop; then the rest in a new process on 1 thread.
    granflow_ok(
        &[
            "simulate",
            "drum.yaml",
            "--out",
            "split",
            "--max-steps",
            "1500",
            "--threads",
            "2",
            "--quiet",
        ],
        dir,
    );
    let middle = final_state(&dir.join("split"));
    assert_eq!(middle.step, 1500);
    let log = granflow_ok(&["simulate", "drum.yaml", "--out", "split", "--threads", "1"], dir).stderr;
    assert!(log.contains("resuming from"), "{log}");

    let whole = final_state(&dir.join("whole"));
    let split = final_state(&dir.join("split"));
    assert_eq!(whole.step, 3000);
    // The run must exercise what the restart has to carry: yielded Thornton contacts, Walton-Braun history,
    // baffle contacts and a turned drum.
    let yielded = whole.contacts.pairs.iter().filter(|c| c.2.normal.yielded).count();
    let baffle_contacts = whole.contacts.walls.iter().filter(|c| c.1.0 >= 1).count();
    println!(
        "restart: {} pair contacts ({yielded} yielded), {} wall contacts ({baffle_contacts} on baffles), drum angle {:.3} rad",
        whole.contacts.pairs.len(),
        whole.contacts.walls.len(),
        whole.wall_angle_rad[0]
    );
    assert!(whole.contacts.pairs.len() > 100 && yielded > 0 && baffle_contacts > 0);
    assert!(
        middle.contacts.walls.iter().any(|c| c.1.0 >= 1),
        "baffle contacts cross the restart"
    );
    if let Some(diff) = first_difference(&whole, &split) {
        panic!("restarted run differs from the uninterrupted one: {diff}");
    }
}

/// A dense packing: touching spheres on a lattice, compressed by gravity, every particle in contact.
fn dense_packing(law: &str) -> String {
    format!(
        r#"
name: dense
domain: {{ lo_m: [0.0, 0.0, 0.0], hi_m: [0.036, 0.036, 0.1] }}
gravity: {{ vector_m_per_s2: [0.0, 0.0, -9.81] }}
species:
  - {{ name: s, radius_m: 0.001, density_kg_per_m3: 2500.0, youngs_modulus_pa: 1.0e7, poisson_ratio: 0.3, friction_coefficient: 0.5, yield_force_n: 0.001 }}
contact: {law}
walls:
  - box: {{ species: s }}
fill:
  - lattice: {{ species: s, spacing_m: 0.002, lo_m: [0.001, 0.001, 0.001], hi_m: [0.0355, 0.0355, 0.04], origin_m: [0.001, 0.001, 0.001] }}
time: {{ dt_s: 2.0e-6, end_time_s: 1.0 }}
"#
    )
}

#[test]
fn one_two_and_three_threads_are_bit_identical() {
    for law in [
        "{ normal: { hertz: { restitution: 0.5 } }, tangential: mindlin, rolling: constant_directional_torque }",
        "{ normal: { thornton: {} }, tangential: { walton_braun: {} } }",
    ] {
        let b = built(&dense_packing(law));
        let states: Vec<SimState> = [1, 2, 3]
            .iter()
            .map(|&threads| {
                let mut sim = simulation(&b, threads);
                sim.run_steps(1000).expect("stable");
                sim.snapshot()
            })
            .collect();
        println!(
            "threads ({law}): {} particles, {} active pair contacts",
            states[0].particles.len(),
            states[0].contacts.pairs.len()
        );
        assert!(
            states[0].contacts.pairs.len() > states[0].particles.len(),
            "a dense packing"
        );
        for (k, s) in states.iter().enumerate().skip(1) {
            if let Some(diff) = first_difference(&states[0], s) {
                panic!("{} threads differ from 1 ({law}): {diff}", k + 1);
            }
        }
        // Any cut of the particles into ranges gives the same bits: here four very unequal ranges per thread.
        let mut odd = simulation(&b, 2);
        odd.range_block = vec![0.05, 1.0, 0.3, 0.02];
        odd.run_steps(1000).expect("stable");
        if let Some(diff) = first_difference(&states[0], &odd.snapshot()) {
            panic!(
                "2 threads with ranges of shares {:?} differ from 1 ({law}): {diff}",
                odd.range_block
            );
        }
    }
}

#[test]
fn corrupt_newest_checkpoint_falls_back_to_the_previous_one() {
    let tmp = tempfile::tempdir().expect("temp dir");
    let dir = tmp.path();
    std::fs::write(dir.join("drum.yaml"), DRUM).expect("write scenario");
    granflow_ok(
        &[
            "simulate",
            "drum.yaml",
            "--out",
            "run",
            "--max-steps",
            "1000",
            "--quiet",
        ],
        dir,
    );
    let series = CheckpointSeries::new(dir.join("run"), 2);
    let list = series.list().expect("lists");
    let (newest_step, newest) = list[0].clone();
    assert_eq!(newest_step, 1000);
    // Flip a bit in the middle of the file.
    let mut bytes = std::fs::read(&newest).expect("read");
    let middle = bytes.len() / 2;
    bytes[middle] ^= 0x10;
    std::fs::write(&newest, &bytes).expect("write");
    assert!(read_checkpoint(&newest).is_err());

    let log = granflow_ok(&["simulate", "drum.yaml", "--out", "run", "--max-steps", "10"], dir).stderr;
    let name = newest.file_name().expect("name").to_string_lossy().into_owned();
    assert!(
        log.contains(&name) && log.contains("using"),
        "warning names the bad file: {log}"
    );
    assert!(log.contains("step 500"), "resumed from the previous checkpoint: {log}");
}

#[test]
fn truncated_checkpoint_is_rejected_with_its_name() {
    let tmp = tempfile::tempdir().expect("temp dir");
    let dir = tmp.path();
    std::fs::write(dir.join("drum.yaml"), DRUM).expect("write scenario");
    granflow_ok(
        &["simulate", "drum.yaml", "--out", "run", "--max-steps", "500", "--quiet"],
        dir,
    );
    let series = CheckpointSeries::new(dir.join("run"), 2);
    let (_, newest) = series.list().expect("lists")[0].clone();
    let bytes = std::fs::read(&newest).expect("read");
    std::fs::write(&newest, &bytes[..bytes.len() / 3]).expect("truncate");
    let err = read_checkpoint(&newest).expect_err("truncated file is rejected");
    assert!(err.to_string().contains(&*newest.to_string_lossy()), "{err}");
}

/// `run_steps(n)` fuses each step's first half into the previous step's force loop; one step at a time does not.
/// Both must give the same bits, on one and on two threads.
#[test]
fn fused_and_unfused_stepping_are_bit_identical() {
    let b = built(DRUM);
    for threads in [1, 2] {
        let mut fused = simulation(&b, threads);
        fused.run_steps(700).expect("stable");
        let mut single = simulation(&b, threads);
        for _ in 0..700 {
            single.step().expect("stable");
        }
        if let Some(diff) = first_difference(&fused.snapshot(), &single.snapshot()) {
            panic!("{threads} thread(s): fused stepping differs from single steps: {diff}");
        }
    }
}

/// The two-level neighbour list (the force pass's list refiltered from the candidates within the skin) and a single
/// list give the same bits: the list only decides which pairs are examined, never their order.
#[test]
fn two_level_and_single_neighbour_lists_are_bit_identical() {
    let one_level = built(&format!("{DRUM}neighbor: {{ skin_m: 0.0006, inner_skin_m: 0.0006 }}\n"));
    let two_level = built(&format!(
        "{DRUM}neighbor: {{ skin_m: 0.0006, inner_skin_m: 0.00015 }}\n"
    ));
    for threads in [1, 2] {
        let mut single = simulation(&one_level, threads);
        let mut refiltered = simulation(&two_level, threads);
        single.run_steps(2000).expect("stable");
        refiltered.run_steps(2000).expect("stable");
        println!(
            "{threads} thread(s): single list {} builds, {} candidates; two levels {} builds + {} refilters, {} candidates",
            single.neighbor_builds(),
            single.candidate_pairs(),
            refiltered.neighbor_builds(),
            refiltered.neighbor_refilters(),
            refiltered.candidate_pairs()
        );
        assert_eq!(single.neighbor_refilters(), 0);
        assert!(refiltered.neighbor_refilters() > 10, "the run must refilter");
        assert!(refiltered.candidate_pairs() < single.candidate_pairs());
        if let Some(diff) = first_difference(&single.snapshot(), &refiltered.snapshot()) {
            panic!("{threads} thread(s): the two-level list changes the result: {diff}");
        }
    }
}
