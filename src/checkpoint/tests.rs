//! Tests of the checkpoint files: round trips bit for bit, damaged, truncated and foreign files rejected (checksum,
//! seal, version), inconsistent states refused, the rotating series, and the checksum recipe and dataset table that
//! `schemas/checkpoint.md` documents.

use super::*;
use crate::engine::Vec3;
use crate::engine::channels::{CHANNELS, ChannelGroups, ParticleChannels};
use crate::engine::contacts::{ContactStore, WallId};
use crate::engine::models::ContactHistory;
use crate::engine::models::history::{CohesionHistory, DurationHistory, NormalHistory, TangentialHistory};
use crate::engine::particles::{ParticleId, Particles, SpeciesId};
use crate::engine::state::RngState;

/// A value placed once in the positions, to find its bytes in the file.
const DISTINCTIVE: f64 = 0.731_592_653_589_793_2e-3;
const SUBNORMAL: f64 = f64::from_bits(1);

fn v(x: f64, y: f64, z: f64) -> Vec3 {
    Vec3::new(x, y, z)
}

fn history(k: f64, yielded: bool) -> ContactHistory {
    ContactHistory {
        active: true,
        normal: NormalHistory {
            yielded,
            max_overlap_m: 3.3e-6 * k,
            max_normal_force_n: 12.75 + k,
        },
        tangential: TangentialHistory {
            shear: v(1.1e-7 * k, -2.3e-8 * k, -0.0),
            reversal_force_n: v(0.31 * k, 1.7e-3, -4.9e-2 * k),
            increment_direction: v(0.6, -0.8 * k / k.abs(), SUBNORMAL),
        },
        duration: DurationHistory {
            duration_s: 2.5e-4 * k.abs(),
        },
        cohesion: CohesionHistory {
            bridge_volume_m3: 1.5e-13 * k.abs(),
            in_well: k > 0.0,
        },
    }
}

/// A record with a cohesion state only (a bridge or well at a gap).
fn cohesion_only(bridge_volume_m3: f64, in_well: bool) -> ContactHistory {
    ContactHistory {
        cohesion: CohesionHistory {
            bridge_volume_m3,
            in_well,
        },
        ..ContactHistory::INACTIVE
    }
}

fn sample_state() -> SimState {
    let mut p = Particles::default();
    for i in 0..5u32 {
        let f = f64::from(i) + 1.0;
        p.id.push(ParticleId(i));
        p.species.push(SpeciesId((i % 2) as u16));
        p.radius_m.push(1.0e-3 * (1.0 + 0.1234567 * f));
        p.mass_kg.push(2.5e-6 * f.sqrt());
        p.inertia_kg_m2.push(1.0e-12 / 3.0 * f);
        p.position_m.push(v(0.01 * f / 7.0, -0.003 * f, 0.1 + 1.0 / (f + 13.0)));
        p.velocity_m_per_s.push(v(-0.0, 1.0e-310 * f, 0.577_215_664 * f));
        p.angular_velocity_rad_per_s.push(v(SUBNORMAL, -SUBNORMAL * f, 3.0 / f));
        p.force_n.push(v(f * 1.0e-3 / 3.0, -9.81 * f, f64::MIN_POSITIVE));
        p.torque_n_m
            .push(v(-1.0e-9 * f, f64::from_bits(0x7ff8_0000_dead_beef), f64::MAX / f));
        p.liquid_m3.push(1.0e-12 / f);
        p.sprayed_m3.push(3.0e-13 * f);
        p.temperature_k.push(293.15 + f / 3.0);
    }
    p.position_m[2].x = DISTINCTIVE;
    p.channels = ParticleChannels::new(
        5,
        ChannelGroups {
            statistics: true,
            heat: true,
        },
    );
    for (k, info) in CHANNELS.iter().enumerate() {
        for (i, x) in (info.get_mut)(&mut p.channels).iter_mut().enumerate() {
            *x = 1.25e-3 * (k + 1) as f64 + i as f64;
        }
    }
    let contacts = ContactStore {
        pairs: vec![
            (ParticleId(0), ParticleId(1), history(1.0, false)),
            (ParticleId(0), ParticleId(2), cohesion_only(2.5e-13, false)),
            (ParticleId(0), ParticleId(3), history(-2.0, true)),
            (ParticleId(2), ParticleId(4), history(3.5, false)),
            (ParticleId(3), ParticleId(4), cohesion_only(0.0, true)),
        ],
        walls: vec![
            (ParticleId(1), WallId(0), history(-0.5, true)),
            (ParticleId(1), WallId(1), cohesion_only(0.0, true)),
            (ParticleId(3), WallId(1), history(7.25, false)),
        ],
    };
    let mut seed = [0u8; 32];
    for (k, b) in seed.iter_mut().enumerate() {
        *b = (k as u8).wrapping_mul(37).wrapping_add(11);
    }
    SimState {
        step: 123_456_789,
        time_s: 0.012_345_678_9,
        dt_s: 1.0e-6 + f64::EPSILON,
        particles: p,
        wall_angle_rad: vec![0.25, -1.5e-7],
        contacts,
        rng: RngState {
            seed,
            stream: 0xdead_beef_1234_5678,
            word_pos: (1u128 << 70) + 12_345,
        },
        heat_ledger: Some(crate::engine::heat_ledger::HeatLedger {
            initial_energy_j: 12.5,
            wall_to_particles_j: SUBNORMAL,
            gas_boundary_in_j: 3.0e-4,
            gas_boundary_out_j: -0.0,
            gas_continuity_j: -1.25e-9,
        }),
        // Net-force sums for the two walls.
        net_force: Some(crate::engine::net_force::NetForceTally {
            steps: 37,
            fluid_n: Vec3::new(1.0e-3, 0.25, -DISTINCTIVE),
            wall_contact_n: vec![Vec3::new(0.0, 2.5, 1e-300), Vec3::new(-0.125, 3.0e-7, 0.0)],
            wall_cohesion_n: vec![Vec3::new(0.0, -0.5, 0.0), Vec3::new(7.0, 0.0, -1.0e-9)],
        }),
        // A 2 × 3 × 1 gas grid: 6 cells, 9 / 8 / 12 faces.
        gas: Some(crate::engine::gas::coupled::GasSnapshot {
            pressure_pa: (0..6).map(|k| 101.5 * k as f64 - 3.0).collect(),
            velocity_m_per_s: [
                (0..9).map(|k| 0.1 * k as f64).collect(),
                (0..8).map(|k| -0.3 * k as f64 + 1e-17).collect(),
                vec![0.0; 12],
            ],
            porosity: vec![0.41, 0.5, 0.999, 1.0, 0.6, 0.45],
            time_s: 0.012,
            reaction_n_per_m3: [vec![1.5; 9], vec![-2.25; 8], vec![0.0; 12]],
            beta_sum: [vec![310.5; 9], vec![12.0; 8], vec![0.0; 12]],
            beta_velocity_sum: [vec![-3.5; 9], vec![7.25e-3; 8], vec![0.0; 12]],
            reaction_steps: 7,
            last: crate::engine::gas::coupled::GasStepStats {
                outer_iterations: 12,
                linear_iterations: 345,
                mass_imbalance: 1.25e-9,
                converged: true,
            },
            held_drag: Some(crate::engine::gas::held_drag::HeldDragSnapshot {
                position_m: (0..5).map(|k| v(0.01 * k as f64, 0.0625, -1e-300)).collect(),
                velocity_m_per_s: (0..5).map(|k| v(-0.5, 0.25 * k as f64, SUBNORMAL)).collect(),
                velocity_sum_m_per_s: (0..5).map(|k| v(3.0 * k as f64, -7.5, 1e-9)).collect(),
            }),
            scalars: vec![
                crate::engine::gas::coupled::GasScalarSnapshot {
                    name: "temperature_k".into(),
                    unit: "K".into(),
                    value: vec![300.0, 301.5, 1e-300, 400.0, 299.25, 350.125],
                    exchange: crate::engine::gas::ExchangeAccumulator {
                        coefficient_sum: vec![0.0; 6],
                        coefficient_value_sum: vec![0.0; 6],
                        transfer_sum: vec![-0.5, 2.0e-9, 0.0, 3.25, -7.0, 1.0],
                        steps: 3,
                    },
                },
                crate::engine::gas::coupled::GasScalarSnapshot {
                    // A drying run's vapour (its accumulator is never filled between gas steps).
                    name: "vapour_mass_fraction".into(),
                    unit: "kg/kg".into(),
                    value: vec![0.0, 1e-3, SUBNORMAL, 0.02, 5e-300, 0.0125],
                    exchange: crate::engine::gas::ExchangeAccumulator::new(6),
                },
            ],
            drying: Some(crate::engine::drying::DryingLedger {
                initial_liquid_kg: 1.25e-4,
                initial_vapour_kg: 0.0,
                sprayed_kg: SUBNORMAL,
                evaporated_kg: -3.5e-9,
                vapour_in_kg: 1e-300,
                vapour_out_kg: 7.0e-7,
            }),
        }),
    }
}

fn sample_meta() -> CheckpointMeta {
    CheckpointMeta {
        engine_version: env!("CARGO_PKG_VERSION").to_string(),
        model_names: vec!["thornton".into(), "walton_braun".into(), "none".into()],
        wall_names: vec!["drum".into(), "lid".into()],
        scenario_json: r#"{"name":"tumbler","μ":0.3,"walls":["drum","lid"]}"#.to_string(),
    }
}

fn round_trip(state: &SimState, meta: &CheckpointMeta) {
    let dir = tempfile::tempdir().expect("tempdir");
    let path = dir.path().join("ckpt-000000000001.h5");
    write_checkpoint(&path, state, meta).expect("write");
    assert!(!tmp_path(&path).exists(), "temporary file left behind");
    let (back, back_meta) = read_checkpoint(&path).expect("read");
    if let Some(e) = crate::engine::state::first_difference(state, &back) {
        panic!("round trip changed the state: {e}");
    }
    assert_eq!(&back_meta, meta);
}

fn flip_bit_at_value(path: &Path, value: f64) {
    let mut bytes = std::fs::read(path).expect("read file");
    let needle = value.to_le_bytes();
    let hits: Vec<usize> = bytes
        .windows(8)
        .enumerate()
        .filter(|(_, w)| *w == needle)
        .map(|(k, _)| k)
        .collect();
    assert_eq!(
        hits.len(),
        1,
        "the distinctive value must occur exactly once in the file"
    );
    bytes[hits[0] + 3] ^= 0x10;
    std::fs::write(path, bytes).expect("write file");
}

#[test]
fn round_trip_is_bit_identical() {
    let state = sample_state();
    assert!(state.rng.word_pos > u128::from(u64::MAX));
    round_trip(&state, &sample_meta());
}

#[test]
fn first_difference_names_the_first_differing_field() {
    let a = sample_state();
    let mut b = a.clone();
    b.particles.velocity_m_per_s[0].x = 0.0; // was -0.0: equal as numbers, different bits
    let diff = crate::engine::state::first_difference(&a, &b).expect("differs");
    assert!(diff.starts_with("particles.velocity_m_per_s[0].x"), "{diff}");
    let mut c = a.clone();
    c.contacts.walls[2].2.normal.max_overlap_m += 1e-20;
    let diff = crate::engine::state::first_difference(&a, &c).expect("differs");
    assert!(
        diff.starts_with("contacts.walls[2]") && diff.contains("normal.max_overlap_m"),
        "{diff}"
    );
    // Every field of the table is compared (here the cohesion slot's, last in the record).
    let mut d = a.clone();
    d.contacts.pairs[1].2.cohesion.bridge_volume_m3 *= 1.0 + f64::EPSILON;
    let diff = crate::engine::state::first_difference(&a, &d).expect("differs");
    assert!(diff.contains("cohesion.bridge_volume_m3"), "{diff}");
}

#[test]
fn empty_contacts_and_no_walls_round_trip() {
    let mut state = sample_state();
    state.contacts = ContactStore::default();
    state.wall_angle_rad.clear();
    if let Some(tally) = state.net_force.as_mut() {
        tally.wall_contact_n.clear();
        tally.wall_cohesion_n.clear();
    }
    let meta = CheckpointMeta {
        wall_names: Vec::new(),
        model_names: Vec::new(),
        scenario_json: String::new(),
        ..sample_meta()
    };
    round_trip(&state, &meta);
}

#[test]
fn a_state_without_gas_or_net_forces_round_trips() {
    let mut state = sample_state();
    state.gas = None;
    state.net_force = None;
    state.heat_ledger = None;
    round_trip(&state, &sample_meta());
}

#[test]
fn no_particles_round_trip() {
    let mut state = sample_state();
    state.particles = Particles::default();
    state.contacts = ContactStore::default();
    state.gas.as_mut().expect("the sample has a gas").held_drag = None;
    round_trip(&state, &sample_meta());
}

#[test]
fn large_scenario_json_round_trips() {
    let meta = CheckpointMeta {
        scenario_json: "{\"x\":1234567890}".repeat(20_000),
        ..sample_meta()
    };
    round_trip(&sample_state(), &meta);
}

#[test]
fn truncated_file_is_an_error_naming_the_file() {
    let dir = tempfile::tempdir().expect("tempdir");
    let path = dir.path().join("ckpt-000000000001.h5");
    write_checkpoint(&path, &sample_state(), &sample_meta()).expect("write");
    let bytes = std::fs::read(&path).expect("read file");
    std::fs::write(&path, &bytes[..bytes.len() / 2]).expect("truncate");
    let err = read_checkpoint(&path).expect_err("a truncated file must not read");
    assert_eq!(err.path(), path);
    assert!(err.to_string().contains(&path.display().to_string()), "{err}");
}

#[test]
fn flipped_bit_in_data_is_a_checksum_mismatch() {
    let dir = tempfile::tempdir().expect("tempdir");
    let path = dir.path().join("ckpt-000000000001.h5");
    write_checkpoint(&path, &sample_state(), &sample_meta()).expect("write");
    flip_bit_at_value(&path, DISTINCTIVE);
    let err = read_checkpoint(&path).expect_err("a flipped bit must be detected");
    assert!(matches!(err, CheckpointError::Corrupt { .. }), "{err:?}");
    let msg = err.to_string();
    assert!(msg.contains("checksum mismatch"), "{msg}");
    assert!(msg.contains(&path.display().to_string()), "{msg}");
}

#[test]
fn changed_content_is_a_content_checksum_mismatch() {
    let dir = tempfile::tempdir().expect("tempdir");
    let path = dir.path().join("ckpt-000000000001.h5");
    let state = sample_state();
    write_checkpoint(&path, &state, &sample_meta()).expect("write");
    {
        let file = hdf5::File::open_rw(&path).expect("open");
        let mut radius = state.particles.radius_m.clone();
        radius[3] = f64::from_bits(radius[3].to_bits() ^ 1);
        file.dataset("particles/radius_m")
            .expect("dataset")
            .write_raw(&radius)
            .expect("write");
    }
    // A valid seal over the changed file: only the content checksum can notice.
    seal(&path).expect("reseal");
    let err = read_checkpoint(&path).expect_err("changed content must be detected");
    assert!(matches!(err, CheckpointError::Corrupt { .. }), "{err:?}");
    assert!(err.to_string().contains("content checksum mismatch"), "{err}");
}

#[test]
fn truncated_hdf5_behind_a_valid_seal_is_an_hdf5_error() {
    let dir = tempfile::tempdir().expect("tempdir");
    let path = dir.path().join("ckpt-000000000001.h5");
    write_checkpoint(&path, &sample_state(), &sample_meta()).expect("write");
    let bytes = std::fs::read(&path).expect("read file");
    std::fs::write(&path, &bytes[..bytes.len() / 2]).expect("truncate");
    seal(&path).expect("reseal");
    let err = read_checkpoint(&path).expect_err("libhdf5 must refuse a truncated file");
    assert!(matches!(err, CheckpointError::Hdf5 { .. }), "{err:?}");
    assert!(err.to_string().contains(&path.display().to_string()), "{err}");
}

#[test]
fn every_flipped_bit_and_every_cut_is_rejected() {
    let dir = tempfile::tempdir().expect("tempdir");
    let path = dir.path().join("ckpt-000000000001.h5");
    write_checkpoint(&path, &sample_state(), &sample_meta()).expect("write");
    let orig = std::fs::read(&path).expect("read file");
    // Every byte of the seal block, then every 7th byte (the same check covers all of them; this keeps the
    // test fast in debug builds).
    let offsets = (0..SEAL_BYTES as usize).chain((SEAL_BYTES as usize..orig.len()).step_by(7));
    for k in offsets {
        let mut bytes = orig.clone();
        bytes[k] ^= 1 << (k % 8);
        std::fs::write(&path, &bytes).expect("write file");
        let err = read_checkpoint(&path).expect_err("a flipped bit must be detected");
        assert!(matches!(err, CheckpointError::Corrupt { .. }), "byte {k}: {err:?}");
    }
    for len in (0..orig.len()).step_by(97) {
        std::fs::write(&path, &orig[..len]).expect("write file");
        let err = read_checkpoint(&path).expect_err("a cut file must be detected");
        assert!(matches!(err, CheckpointError::Corrupt { .. }), "length {len}: {err:?}");
    }
}

#[test]
fn other_version_is_rejected() {
    let dir = tempfile::tempdir().expect("tempdir");
    let path = dir.path().join("ckpt-000000000001.h5");
    write_checkpoint(&path, &sample_state(), &sample_meta()).expect("write");
    {
        let file = hdf5::File::open_rw(&path).expect("open");
        file.attr("format_version")
            .expect("attr")
            .write_scalar(&(CHECKPOINT_FORMAT_VERSION + 1))
            .expect("write attr");
    }
    seal(&path).expect("reseal");
    let err = read_checkpoint(&path).expect_err("the next version must be rejected");
    assert!(
        matches!(
            err,
            CheckpointError::Version {
                found,
                expected: CHECKPOINT_FORMAT_VERSION,
                ..
            } if found == CHECKPOINT_FORMAT_VERSION + 1
        ),
        "{err:?}"
    );
}

#[test]
fn foreign_hdf5_file_is_rejected() {
    let dir = tempfile::tempdir().expect("tempdir");
    let path = dir.path().join("other.h5");
    {
        let file = hdf5::File::create(&path).expect("create");
        file.new_dataset::<f64>().shape([3]).create("x").expect("dataset");
    }
    let err = read_checkpoint(&path).expect_err("not a checkpoint");
    assert!(err.to_string().contains("no checkpoint seal"), "{err}");
    // Even with a valid seal, a file without the checkpoint attributes is rejected by name.
    std::fs::remove_file(&path).expect("remove");
    {
        let file = hdf5::File::with_options()
            .with_fcpl(|p| p.userblock(SEAL_BYTES))
            .create(&path)
            .expect("create");
        file.new_dataset::<f64>().shape([3]).create("x").expect("dataset");
    }
    seal(&path).expect("seal");
    let err = read_checkpoint(&path).expect_err("not a checkpoint");
    assert!(err.to_string().contains("missing root attribute format"), "{err}");
}

#[test]
fn inconsistent_state_is_not_written() {
    let dir = tempfile::tempdir().expect("tempdir");
    let path = dir.path().join("ckpt-000000000001.h5");
    let mut state = sample_state();
    state.contacts.walls[0].1 = WallId(5);
    let err = write_checkpoint(&path, &state, &sample_meta()).expect_err("wall 5 does not exist");
    assert!(matches!(err, CheckpointError::InvalidState { .. }), "{err:?}");
    let mut state = sample_state();
    state.particles.mass_kg.pop();
    let err = write_checkpoint(&path, &state, &sample_meta()).expect_err("mass_kg is short");
    assert!(err.to_string().contains("/particles/mass_kg"), "{err}");
    assert!(!path.exists() && !tmp_path(&path).exists());
}

#[test]
fn series_keeps_newest_and_falls_back_past_corrupt() {
    let dir = tempfile::tempdir().expect("tempdir");
    let series = CheckpointSeries::new(dir.path().join("run"), 3);
    let meta = sample_meta();
    let mut state = sample_state();
    for step in [100, 200, 300, 400] {
        state.step = step;
        let path = series.write(&state, &meta).expect("write");
        assert_eq!(path, series.path_for_step(step));
    }
    let steps: Vec<u64> = series.list().expect("list").into_iter().map(|(s, _)| s).collect();
    assert_eq!(steps, [400, 300, 200]);
    assert!(!series.path_for_step(100).exists());

    let newest = series.path_for_step(400);
    flip_bit_at_value(&newest, DISTINCTIVE);
    let loaded = series
        .latest_valid()
        .expect("latest_valid")
        .expect("a valid checkpoint");
    assert_eq!(loaded.path, series.path_for_step(300));
    assert_eq!(loaded.state.step, 300);
    assert_eq!(loaded.meta, meta);
    assert_eq!(loaded.rejected.len(), 1);
    assert_eq!(loaded.rejected[0].path(), newest);
    assert!(loaded.rejected[0].to_string().contains("ckpt-000000000400.h5"));

    // Truncating the next one as well falls back to 200, with both rejections listed newest first.
    let p300 = series.path_for_step(300);
    let bytes = std::fs::read(&p300).expect("read");
    std::fs::write(&p300, &bytes[..bytes.len() / 2]).expect("truncate");
    let loaded = series
        .latest_valid()
        .expect("latest_valid")
        .expect("a valid checkpoint");
    assert_eq!(loaded.state.step, 200);
    let rejected: Vec<&Path> = loaded.rejected.iter().map(|e| e.path()).collect();
    assert_eq!(rejected, [newest.as_path(), p300.as_path()]);
}

#[test]
fn series_without_valid_checkpoints_is_none() {
    let dir = tempfile::tempdir().expect("tempdir");
    let series = CheckpointSeries::new(dir.path().join("missing"), 2);
    assert!(series.list().expect("list").is_empty());
    assert!(series.latest_valid().expect("latest_valid").is_none());
    std::fs::create_dir_all(series.dir()).expect("mkdir");
    std::fs::write(series.path_for_step(5), b"not hdf5").expect("write");
    assert!(series.latest_valid().expect("latest_valid").is_none());
}

#[test]
fn file_name_must_match_step() {
    let dir = tempfile::tempdir().expect("tempdir");
    let series = CheckpointSeries::new(dir.path(), 2);
    let state = sample_state();
    write_checkpoint(&series.path_for_step(999), &state, &sample_meta()).expect("write");
    assert!(series.latest_valid().expect("latest_valid").is_none());
}

#[test]
fn list_ignores_tmp_and_other_files() {
    let dir = tempfile::tempdir().expect("tempdir");
    let series = CheckpointSeries::new(dir.path(), 3);
    let mut state = sample_state();
    state.step = 10;
    series.write(&state, &sample_meta()).expect("write");
    let tmp = tmp_path(&series.path_for_step(20));
    std::fs::write(&tmp, b"half-written").expect("write tmp");
    for other in ["notes.txt", "ckpt-.h5", "ckpt-12x.h5", "ckpt-000000000030.h5.bak"] {
        std::fs::write(dir.path().join(other), b"x").expect("write other");
    }
    std::fs::create_dir(series.path_for_step(40)).expect("mkdir");
    let listed = series.list().expect("list");
    assert_eq!(listed, [(10, series.path_for_step(10))]);
    let loaded = series.latest_valid().expect("latest_valid").expect("valid");
    assert!(loaded.rejected.is_empty());
    // Writing again does not trip over (or delete) the leftover temporary file of another step.
    state.step = 11;
    series.write(&state, &sample_meta()).expect("write");
    assert!(tmp.exists());
}

#[test]
fn series_never_deletes_the_file_just_written() {
    let dir = tempfile::tempdir().expect("tempdir");
    let series = CheckpointSeries::new(dir.path(), 1);
    let mut state = sample_state();
    state.step = 500;
    series.write(&state, &sample_meta()).expect("write");
    state.step = 300;
    let path = series.write(&state, &sample_meta()).expect("write");
    assert!(path.exists());
}

/// Recomputes `checksum_xxh3_64` from the recipe in `schemas/checkpoint.md`, independently of `layout`.
#[test]
fn content_checksum_follows_the_documented_recipe() {
    fn s(out: &mut Vec<u8>, v: &str) {
        out.extend((v.len() as u64).to_le_bytes());
        out.extend(v.as_bytes());
    }
    fn ds(out: &mut Vec<u8>, path: &str, shape: &[usize], data: &[u8]) {
        s(out, path);
        out.extend((shape.len() as u64).to_le_bytes());
        for &d in shape {
            out.extend((d as u64).to_le_bytes());
        }
        out.extend(data);
    }
    fn f(v: impl IntoIterator<Item = f64>) -> Vec<u8> {
        v.into_iter().flat_map(|x| x.to_bits().to_le_bytes()).collect()
    }
    fn v3(v: &[Vec3]) -> Vec<u8> {
        f(v.iter().flat_map(|x| [x.x, x.y, x.z]))
    }
    let state = sample_state();
    let meta = sample_meta();
    let dir = tempfile::tempdir().expect("tempdir");
    let path = dir.path().join("ckpt-000000000001.h5");
    write_checkpoint(&path, &state, &meta).expect("write");
    let stored: u64 = hdf5::File::open(&path)
        .expect("open")
        .attr("checksum_xxh3_64")
        .expect("attr")
        .read_scalar()
        .expect("read");

    let mut b = Vec::new();
    s(&mut b, "granflow-checkpoint");
    b.extend(CHECKPOINT_FORMAT_VERSION.to_le_bytes());
    s(&mut b, &meta.engine_version);
    b.extend(state.step.to_le_bytes());
    b.extend(state.time_s.to_bits().to_le_bytes());
    b.extend(state.dt_s.to_bits().to_le_bytes());
    for list in [&meta.model_names, &meta.wall_names] {
        b.extend((list.len() as u64).to_le_bytes());
        for name in list {
            s(&mut b, name);
        }
    }
    s(&mut b, &meta.scenario_json);
    let p = &state.particles;
    let n = p.len();
    let ids: Vec<u8> = p.id.iter().flat_map(|i| i.0.to_le_bytes()).collect();
    let species: Vec<u8> = p.species.iter().flat_map(|i| i.0.to_le_bytes()).collect();
    ds(&mut b, "particles/id", &[n], &ids);
    ds(&mut b, "particles/species", &[n], &species);
    ds(&mut b, "particles/radius_m", &[n], &f(p.radius_m.iter().copied()));
    ds(&mut b, "particles/mass_kg", &[n], &f(p.mass_kg.iter().copied()));
    ds(
        &mut b,
        "particles/inertia_kg_m2",
        &[n],
        &f(p.inertia_kg_m2.iter().copied()),
    );
    ds(&mut b, "particles/position_m", &[n, 3], &v3(&p.position_m));
    ds(&mut b, "particles/velocity_m_per_s", &[n, 3], &v3(&p.velocity_m_per_s));
    let omega = v3(&p.angular_velocity_rad_per_s);
    ds(&mut b, "particles/angular_velocity_rad_per_s", &[n, 3], &omega);
    ds(&mut b, "particles/force_n", &[n, 3], &v3(&p.force_n));
    ds(&mut b, "particles/torque_n_m", &[n, 3], &v3(&p.torque_n_m));
    // (group, i bytes, partner bytes, histories)
    type Table = (&'static str, Vec<u8>, Vec<u8>, Vec<ContactHistory>);
    let tables: [Table; 2] = [
        (
            "pairs",
            state.contacts.pairs.iter().flat_map(|c| c.0.0.to_le_bytes()).collect(),
            state.contacts.pairs.iter().flat_map(|c| c.1.0.to_le_bytes()).collect(),
            state.contacts.pairs.iter().map(|c| c.2).collect(),
        ),
        (
            "walls",
            state.contacts.walls.iter().flat_map(|c| c.0.0.to_le_bytes()).collect(),
            state.contacts.walls.iter().flat_map(|c| c.1.0.to_le_bytes()).collect(),
            state.contacts.walls.iter().map(|c| c.2).collect(),
        ),
    ];
    for (table, i, partner, h) in &tables {
        let m = h.len();
        let partner_name = if *table == "pairs" { "j" } else { "wall" };
        let active: Vec<u8> = h.iter().map(|x| u8::from(x.active)).collect();
        ds(&mut b, &format!("contacts/{table}/i"), &[m], i);
        ds(&mut b, &format!("contacts/{table}/{partner_name}"), &[m], partner);
        ds(&mut b, &format!("contacts/{table}/active"), &[m], &active);
    }
    let walls = state.wall_angle_rad.len();
    ds(
        &mut b,
        "walls/angle_rad",
        &[walls],
        &f(state.wall_angle_rad.iter().copied()),
    );
    ds(&mut b, "rng/seed", &[32], &state.rng.seed);
    ds(&mut b, "rng/stream", &[], &state.rng.stream.to_le_bytes());
    ds(
        &mut b,
        "rng/word_pos_hi",
        &[],
        &((state.rng.word_pos >> 64) as u64).to_le_bytes(),
    );
    ds(
        &mut b,
        "rng/word_pos_lo",
        &[],
        &(state.rng.word_pos as u64).to_le_bytes(),
    );
    let gas = state.gas.as_ref().expect("the sample has a gas");
    ds(
        &mut b,
        "gas/pressure_pa",
        &[gas.pressure_pa.len()],
        &f(gas.pressure_pa.iter().copied()),
    );
    ds(
        &mut b,
        "gas/porosity",
        &[gas.porosity.len()],
        &f(gas.porosity.iter().copied()),
    );
    for (k, axis) in ["x", "y", "z"].iter().enumerate() {
        let v = &gas.velocity_m_per_s[k];
        ds(
            &mut b,
            &format!("gas/velocity_{axis}_m_per_s"),
            &[v.len()],
            &f(v.iter().copied()),
        );
    }
    for (k, axis) in ["x", "y", "z"].iter().enumerate() {
        let v = &gas.reaction_n_per_m3[k];
        ds(
            &mut b,
            &format!("gas/drag_reaction_sum_{axis}_n_per_m3"),
            &[v.len()],
            &f(v.iter().copied()),
        );
    }
    for (k, axis) in ["x", "y", "z"].iter().enumerate() {
        let v = &gas.beta_sum[k];
        ds(
            &mut b,
            &format!("gas/drag_beta_sum_{axis}_n_s_per_m4"),
            &[v.len()],
            &f(v.iter().copied()),
        );
    }
    for (k, axis) in ["x", "y", "z"].iter().enumerate() {
        let v = &gas.beta_velocity_sum[k];
        ds(
            &mut b,
            &format!("gas/drag_beta_velocity_sum_{axis}_n_per_m3"),
            &[v.len()],
            &f(v.iter().copied()),
        );
    }
    ds(&mut b, "gas/time_s", &[1], &gas.time_s.to_bits().to_le_bytes());
    ds(
        &mut b,
        "gas/drag_reaction_steps",
        &[1],
        &gas.reaction_steps.to_le_bytes(),
    );
    ds(
        &mut b,
        "gas/last_step/outer_iterations",
        &[1],
        &gas.last.outer_iterations.to_le_bytes(),
    );
    ds(
        &mut b,
        "gas/last_step/linear_iterations",
        &[1],
        &gas.last.linear_iterations.to_le_bytes(),
    );
    ds(
        &mut b,
        "gas/last_step/mass_imbalance",
        &[1],
        &gas.last.mass_imbalance.to_bits().to_le_bytes(),
    );
    ds(&mut b, "gas/last_step/converged", &[1], &[u8::from(gas.last.converged)]);
    let heat = &gas.scalars[0];
    ds(&mut b, "gas/temperature_k", &[6], &f(heat.value.iter().copied()));
    let transfer = f(heat.exchange.transfer_sum.iter().copied());
    ds(&mut b, "gas/heat_transfer_sum_k_kg_per_m3_s", &[6], &transfer);
    ds(
        &mut b,
        "gas/heat_exchange_steps",
        &[1],
        &heat.exchange.steps.to_le_bytes(),
    );
    let vapour = &gas.scalars[1];
    ds(
        &mut b,
        "gas/vapour_mass_fraction",
        &[6],
        &f(vapour.value.iter().copied()),
    );
    let ledger = gas.drying.expect("the sample dries");
    for (name, value) in [
        ("gas/drying/initial_liquid_kg", ledger.initial_liquid_kg),
        ("gas/drying/initial_vapour_kg", ledger.initial_vapour_kg),
        ("gas/drying/sprayed_kg", ledger.sprayed_kg),
        ("gas/drying/evaporated_kg", ledger.evaporated_kg),
        ("gas/drying/vapour_in_kg", ledger.vapour_in_kg),
        ("gas/drying/vapour_out_kg", ledger.vapour_out_kg),
    ] {
        ds(&mut b, name, &[1], &value.to_bits().to_le_bytes());
    }
    let held = gas.held_drag.as_ref().expect("the sample holds held drag");
    ds(&mut b, "gas/held_drag/position_m", &[n, 3], &v3(&held.position_m));
    ds(
        &mut b,
        "gas/held_drag/velocity_m_per_s",
        &[n, 3],
        &v3(&held.velocity_m_per_s),
    );
    let sums = v3(&held.velocity_sum_m_per_s);
    ds(&mut b, "gas/held_drag/velocity_sum_m_per_s", &[n, 3], &sums);
    ds(&mut b, "particles/liquid_m3", &[n], &f(p.liquid_m3.iter().copied()));
    ds(&mut b, "particles/sprayed_m3", &[n], &f(p.sprayed_m3.iter().copied()));
    ds(
        &mut b,
        "particles/temperature_k",
        &[n],
        &f(p.temperature_k.iter().copied()),
    );
    let heat = state.heat_ledger.expect("the sample has an energy ledger");
    for (name, value) in [
        ("heat_ledger/initial_energy_j", heat.initial_energy_j),
        ("heat_ledger/wall_to_particles_j", heat.wall_to_particles_j),
        ("heat_ledger/gas_boundary_in_j", heat.gas_boundary_in_j),
        ("heat_ledger/gas_boundary_out_j", heat.gas_boundary_out_j),
        ("heat_ledger/gas_continuity_j", heat.gas_continuity_j),
    ] {
        ds(&mut b, name, &[1], &value.to_bits().to_le_bytes());
    }
    let tally = state.net_force.as_ref().expect("the sample records net forces");
    let walls = tally.wall_contact_n.len();
    ds(&mut b, "net_force/steps", &[1], &tally.steps.to_le_bytes());
    ds(
        &mut b,
        "net_force/fluid_sum_n",
        &[1, 3],
        &f(tally.fluid_n.iter().copied()),
    );
    for (name, sums) in [
        ("net_force/wall_contact_sum_n", &tally.wall_contact_n),
        ("net_force/wall_cohesion_sum_n", &tally.wall_cohesion_n),
    ] {
        ds(
            &mut b,
            name,
            &[walls, 3],
            &f(sums.iter().flat_map(|v| v.iter().copied())),
        );
    }
    // The history records' fields, as the documentation lists them: pairs, then walls, slot by slot.
    for (table, _, _, h) in &tables {
        let m = h.len();
        let flag = |get: fn(&ContactHistory) -> bool| -> Vec<u8> { h.iter().map(|x| u8::from(get(x))).collect() };
        let vec = |get: fn(&ContactHistory) -> Vec3| v3(&h.iter().map(get).collect::<Vec<_>>());
        let scalar = |get: fn(&ContactHistory) -> f64| f(h.iter().map(get));
        let path = |name: &str| format!("contacts/{table}/{name}");
        ds(&mut b, &path("yielded"), &[m], &flag(|x| x.normal.yielded));
        ds(
            &mut b,
            &path("max_overlap_m"),
            &[m],
            &scalar(|x| x.normal.max_overlap_m),
        );
        let max_force = scalar(|x| x.normal.max_normal_force_n);
        ds(&mut b, &path("max_normal_force_n"), &[m], &max_force);
        ds(&mut b, &path("shear"), &[m, 3], &vec(|x| x.tangential.shear));
        let reversal = vec(|x| x.tangential.reversal_force_n);
        ds(&mut b, &path("reversal_force_n"), &[m, 3], &reversal);
        let direction = vec(|x| x.tangential.increment_direction);
        ds(&mut b, &path("increment_direction"), &[m, 3], &direction);
        ds(&mut b, &path("duration_s"), &[m], &scalar(|x| x.duration.duration_s));
        let volume = scalar(|x| x.cohesion.bridge_volume_m3);
        ds(&mut b, &path("bridge_volume_m3"), &[m], &volume);
        ds(&mut b, &path("in_well"), &[m], &flag(|x| x.cohesion.in_well));
    }
    // The channels, as the documentation lists them.
    let c = &p.channels;
    for (name, values) in [
        ("contacts_ended", &c.contacts_ended),
        ("contact_time_ended_s", &c.contact_time_ended_s),
        ("wall_contacts_ended", &c.wall_contacts_ended),
        ("wall_contact_time_ended_s", &c.wall_contact_time_ended_s),
        ("wall_contact_time_s", &c.wall_contact_time_s),
        ("heat_flow_w", &c.heat_flow_w),
    ] {
        ds(
            &mut b,
            &format!("particles/channels/{name}"),
            &[n],
            &f(values.iter().copied()),
        );
    }

    assert_eq!(stored, xxhash_rust::xxh3::xxh3_64(&b));
}

#[test]
fn schema_documents_every_dataset() {
    let doc = include_str!("../../schemas/checkpoint.md");
    for spec in layout::all_datasets() {
        assert!(
            doc.contains(&format!("`/{}`", spec.path)),
            "schemas/checkpoint.md lacks /{}",
            spec.path
        );
    }
}
