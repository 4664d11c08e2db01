//! The engine's bits, pinned: six short reference runs end in exactly the states recorded in
//! `tests/reference/engine-digests.json` (one XXH3 digest per field of the final state: positions, velocities,
//! angular velocities, forces, torques, liquid, every contact-history and cohesion field, the gas fields).
//!
//! A refactor of the engine must change no bit; one that must (a reordered sum) says which run and why in its
//! commit, and the file is rewritten with `GRANFLOW_WRITE_REFERENCE=1 cargo test --release --test
//! engine_reference`. A mismatch names the run and the fields that differ.

mod common;

use std::collections::BTreeMap;
use std::path::Path;

use granflow::engine::Vec3;
use granflow::engine::models::ContactHistory;
use granflow::engine::models::history::HISTORY_FIELDS;
use granflow::engine::state::SimState;

/// The reference file, relative to the crate.
const REFERENCE: &str = "tests/reference/engine-digests.json";

/// Digest of a sequence of 64-bit words (floats by their bits), little-endian.
fn digest(words: impl IntoIterator<Item = u64>) -> String {
    let mut h = xxhash_rust::xxh3::Xxh3Default::new();
    let mut count = 0u64;
    for w in words {
        h.update(&w.to_le_bytes());
        count += 1;
    }
    format!("{:016x} ({count} words)", h.digest())
}

fn floats(v: &[f64]) -> String {
    digest(v.iter().map(|x| x.to_bits()))
}

fn vectors<'a>(v: impl IntoIterator<Item = &'a Vec3>) -> String {
    digest(
        v.into_iter()
            .flat_map(|x| [x.x.to_bits(), x.y.to_bits(), x.z.to_bits()]),
    )
}

/// One digest per field of the state, by a stable name (independent of how the engine stores it).
pub fn digests(s: &SimState) -> BTreeMap<String, String> {
    let mut d = BTreeMap::new();
    let p = &s.particles;
    d.insert("step".into(), digest([s.step, s.time_s.to_bits(), s.dt_s.to_bits()]));
    d.insert("particles.id".into(), digest(p.id.iter().map(|i| i.0 as u64)));
    d.insert("particles.species".into(), digest(p.species.iter().map(|i| i.0 as u64)));
    d.insert("particles.radius_m".into(), floats(&p.radius_m));
    d.insert("particles.mass_kg".into(), floats(&p.mass_kg));
    d.insert("particles.position_m".into(), vectors(&p.position_m));
    d.insert("particles.velocity_m_per_s".into(), vectors(&p.velocity_m_per_s));
    d.insert(
        "particles.angular_velocity_rad_per_s".into(),
        vectors(&p.angular_velocity_rad_per_s),
    );
    d.insert("particles.force_n".into(), vectors(&p.force_n));
    d.insert("particles.torque_n_m".into(), vectors(&p.torque_n_m));
    d.insert("particles.liquid_m3".into(), floats(&p.liquid_m3));
    d.insert("particles.sprayed_m3".into(), floats(&p.sprayed_m3));
    if !p.temperature_k.is_empty() {
        d.insert("particles.temperature_k".into(), floats(&p.temperature_k));
    }
    // The channels where a run records them (none of the reference runs does: their digests predate channels).
    for info in granflow::engine::channels::CHANNELS {
        let values = (info.get)(&p.channels);
        if !values.is_empty() {
            d.insert(format!("particles.channels.{}", info.name), floats(values));
        }
    }
    d.insert("walls.angle_rad".into(), floats(&s.wall_angle_rad));
    // Contacts: the records of touching pairs; cohesion: the records with a cohesion state (as the engine kept
    // them in two stores before they became one record per pair).
    let touching_pairs: Vec<_> = s.contacts.pairs.iter().filter(|(_, _, h)| h.active).collect();
    let touching_walls: Vec<_> = s.contacts.walls.iter().filter(|(_, _, h)| h.active).collect();
    d.insert(
        "contacts.pairs.keys".into(),
        digest(touching_pairs.iter().flat_map(|(i, j, _)| [i.0 as u64, j.0 as u64])),
    );
    d.insert(
        "contacts.walls.keys".into(),
        digest(touching_walls.iter().flat_map(|(i, w, _)| [i.0 as u64, w.0 as u64])),
    );
    for (table, histories) in [
        ("pairs", touching_pairs.iter().map(|(_, _, h)| *h).collect::<Vec<_>>()),
        ("walls", touching_walls.iter().map(|(_, _, h)| *h).collect::<Vec<_>>()),
    ] {
        d.insert(
            format!("contacts.{table}.flags"),
            digest(
                histories
                    .iter()
                    .map(|h| (h.active as u64) | ((h.normal.yielded as u64) << 1)),
            ),
        );
        d.insert(
            format!("contacts.{table}.tangential"),
            vectors(histories.iter().map(|h| &h.tangential.shear)),
        );
        d.insert(
            format!("contacts.{table}.reversal_force_n"),
            vectors(histories.iter().map(|h| &h.tangential.reversal_force_n)),
        );
        d.insert(
            format!("contacts.{table}.increment_direction"),
            vectors(histories.iter().map(|h| &h.tangential.increment_direction)),
        );
        d.insert(
            format!("contacts.{table}.max_overlap_m"),
            floats(&histories.iter().map(|h| h.normal.max_overlap_m).collect::<Vec<_>>()),
        );
        d.insert(
            format!("contacts.{table}.max_normal_force_n"),
            floats(
                &histories
                    .iter()
                    .map(|h| h.normal.max_normal_force_n)
                    .collect::<Vec<_>>(),
            ),
        );
    }
    // Any other history field (the duration slot, and fields added later), where a record holds a value in it: so
    // that a new field is pinned as soon as a reference run uses it, and older digests stay as they were.
    let listed = [
        "yielded",
        "max_overlap_m",
        "max_normal_force_n",
        "shear",
        "reversal_force_n",
        "increment_direction",
    ];
    for field in HISTORY_FIELDS
        .iter()
        .filter(|f| f.slot != "cohesion" && !listed.contains(&f.name))
    {
        let pairs: Vec<&ContactHistory> = s.contacts.pairs.iter().map(|r| &r.2).collect();
        let walls: Vec<&ContactHistory> = s.contacts.walls.iter().map(|r| &r.2).collect();
        for (table, records) in [("pairs", pairs), ("walls", walls)] {
            let values: Vec<String> = records.iter().map(|h| format!("{:?}", (field.get)(h))).collect();
            if records
                .iter()
                .any(|h| (field.get)(h) != (field.get)(&ContactHistory::INACTIVE))
            {
                d.insert(
                    format!("contacts.{table}.{}", field.name),
                    digest(values.iter().map(|v| xxhash_rust::xxh3::xxh3_64(v.as_bytes()))),
                );
            }
        }
    }
    let bridged_pairs: Vec<_> = s
        .contacts
        .pairs
        .iter()
        .filter(|(_, _, h)| !h.cohesion.is_empty())
        .collect();
    let bridged_walls: Vec<_> = s
        .contacts
        .walls
        .iter()
        .filter(|(_, _, h)| !h.cohesion.is_empty())
        .collect();
    d.insert(
        "cohesion.pairs.keys".into(),
        digest(bridged_pairs.iter().flat_map(|(i, j, _)| [i.0 as u64, j.0 as u64])),
    );
    d.insert(
        "cohesion.pairs.bridge_volume_m3".into(),
        floats(
            &bridged_pairs
                .iter()
                .map(|(_, _, h)| h.cohesion.bridge_volume_m3)
                .collect::<Vec<_>>(),
        ),
    );
    d.insert(
        "cohesion.pairs.in_well".into(),
        digest(bridged_pairs.iter().map(|(_, _, h)| h.cohesion.in_well as u64)),
    );
    d.insert(
        "cohesion.walls.keys".into(),
        digest(bridged_walls.iter().flat_map(|(i, w, _)| [i.0 as u64, w.0 as u64])),
    );
    d.insert(
        "cohesion.walls.bridge_volume_m3".into(),
        floats(
            &bridged_walls
                .iter()
                .map(|(_, _, h)| h.cohesion.bridge_volume_m3)
                .collect::<Vec<_>>(),
        ),
    );
    d.insert(
        "cohesion.walls.in_well".into(),
        digest(bridged_walls.iter().map(|(_, _, h)| h.cohesion.in_well as u64)),
    );
    if let Some(g) = &s.gas {
        d.insert(
            "gas.time_s".into(),
            digest([g.time_s.to_bits(), g.reaction_steps as u64]),
        );
        d.insert("gas.pressure_pa".into(), floats(&g.pressure_pa));
        d.insert("gas.porosity".into(), floats(&g.porosity));
        for k in 0..3 {
            d.insert(format!("gas.velocity_m_per_s[{k}]"), floats(&g.velocity_m_per_s[k]));
            d.insert(format!("gas.reaction_n_per_m3[{k}]"), floats(&g.reaction_n_per_m3[k]));
            d.insert(format!("gas.beta_sum[{k}]"), floats(&g.beta_sum[k]));
            d.insert(format!("gas.beta_velocity_sum[{k}]"), floats(&g.beta_velocity_sum[k]));
        }
    }
    d
}

/// A scenario file of the project, read as text.
fn scenario_text(relative: &str) -> String {
    std::fs::read_to_string(Path::new(env!("CARGO_MANIFEST_DIR")).join(relative)).expect("read scenario")
}

/// The resolved scenario of the first job of a committed campaign whose parameters satisfy `pick`.
fn campaign_job(relative: &str, pick: impl Fn(&str) -> bool) -> granflow::scenario::ScenarioSpec {
    let file = Path::new(env!("CARGO_MANIFEST_DIR")).join(relative);
    let campaign = granflow::campaign::load(&file).expect("campaign loads");
    let job = campaign
        .jobs
        .iter()
        .find(|j| pick(&j.params_json()))
        .expect("a job matches");
    job.scenario.clone()
}

/// Runs `spec` for `steps` steps on `threads` threads (with its gas) and returns the final state.
fn run(spec: granflow::scenario::ScenarioSpec, steps: u64, threads: usize) -> SimState {
    let built = granflow::scenario::build(spec, Path::new("reference.yaml")).expect("valid scenario");
    let mut sim = common::simulation(&built, threads);
    granflow::simulate::attach_gas(&built, &mut sim, None).expect("gas attaches");
    if built.spec.output.net_forces {
        sim.record_net_forces();
    }
    sim.run_steps(steps).expect("the reference run is sound");
    sim.snapshot()
}

fn parse(yaml: &str) -> granflow::scenario::ScenarioSpec {
    granflow::scenario::parse(yaml, Path::new("reference.yaml")).expect("parses")
}

/// The five reference runs: (name, final state).
fn reference_runs() -> Vec<(&'static str, SimState)> {
    let mut runs = Vec::new();
    // The benchmark's settling column (29,160 Hertz-Mindlin spheres), 5,000 steps on two threads (the bottom
    // layers land at about 3,000).
    runs.push((
        "bench-settle",
        run(parse(&scenario_text("scenarios/bench-settle.yaml")), 5000, 2),
    ));
    // The quickstart drum at 60 rpm and the half fill, 3,000 steps.
    runs.push((
        "quickstart-drum",
        run(
            campaign_job("campaigns/quickstart.yaml", |p| {
                p.contains("60.0") && p.contains(":0.0")
            }),
            3000,
            1,
        ),
    ));
    // Thornton + Walton-Braun in a drum with traditional and axial baffles, 20,000 steps (0.1 s: the random fill
    // falls onto the drum and the baffles); a yield force a sixth of the scenario's, so that contacts yield.
    let thornton = scenario_text("scenarios/drum-baffles.yaml").replace("yield_force_n: 0.06", "yield_force_n: 0.01");
    assert!(thornton.contains("yield_force_n: 0.01"));
    runs.push(("thornton-drum-baffles", run(parse(&thornton), 20_000, 1)));
    // The wet fluidized bed with bridges to the walls too, 3,000 steps (the beads reach the floor and bridge).
    let wet = scenario_text("scenarios/wet-fluidized-bed.yaml").replace(
        "liquid_bridge: { surface_tension_n_per_m: 0.030, viscosity_pa_s: 0.001 }",
        "liquid_bridge: { surface_tension_n_per_m: 0.030, viscosity_pa_s: 0.001, walls: true }",
    );
    assert!(wet.contains("walls: true"));
    runs.push(("wet-bed-wall-bridges", run(parse(&wet), 3000, 1)));
    // Seed 001's cohesive bed with its gas (4,000 beads, jets, cycle), Hamaker and square well, walls included.
    runs.push((
        "seed-001-hamaker",
        run(
            campaign_job("campaigns/seed-001-cohesion-beds.yaml", |p| {
                p.contains("1e-17") && p.contains("\"seed\":1")
            }),
            2000,
            1,
        ),
    ));
    runs.push((
        "seed-001-square-well",
        run(
            campaign_job("campaigns/seed-001-cohesion-beds.yaml", |p| {
                p.contains("2e-10") && p.contains("\"seed\":1")
            }),
            2000,
            1,
        ),
    ));
    runs
}

#[test]
fn reference_runs_end_in_their_recorded_bits() {
    let runs = reference_runs();
    let computed: BTreeMap<String, BTreeMap<String, String>> =
        runs.iter().map(|(name, s)| (name.to_string(), digests(s))).collect();
    let path = Path::new(env!("CARGO_MANIFEST_DIR")).join(REFERENCE);
    if std::env::var_os("GRANFLOW_WRITE_REFERENCE").is_some() {
        let text = serde_json::to_string_pretty(&computed).expect("serialises");
        std::fs::write(&path, text + "\n").expect("write the reference");
        eprintln!("wrote {}", path.display());
        return;
    }
    let text = std::fs::read_to_string(&path).expect("the reference file exists");
    let recorded: BTreeMap<String, BTreeMap<String, String>> = serde_json::from_str(&text).expect("reference JSON");
    let mut problems = Vec::new();
    for (name, fields) in &recorded {
        let Some(ours) = computed.get(name) else {
            problems.push(format!("{name}: not run"));
            continue;
        };
        let differing: Vec<&str> = fields
            .iter()
            .filter(|(k, v)| ours.get(*k) != Some(v))
            .map(|(k, _)| k.as_str())
            .chain(ours.keys().filter(|k| !fields.contains_key(*k)).map(String::as_str))
            .collect();
        if !differing.is_empty() {
            problems.push(format!("{name}: {}", differing.join(", ")));
        }
    }
    // The runs exercise what they are meant to: contacts, bridges to walls, cohesion states, the gas.
    let state = |name: &str| &runs.iter().find(|(n, _)| *n == name).expect("run").1;
    assert!(!state("bench-settle").contacts.pairs.is_empty());
    assert!(
        state("thornton-drum-baffles")
            .contacts
            .pairs
            .iter()
            .any(|(_, _, h)| h.normal.yielded)
    );
    assert!(!state("wet-bed-wall-bridges").contacts.cohesion().walls.is_empty());
    assert!(!state("wet-bed-wall-bridges").contacts.cohesion().pairs.is_empty());
    assert!(state("seed-001-hamaker").gas.is_some());
    assert!(!state("seed-001-square-well").contacts.cohesion().pairs.is_empty());
    assert!(
        problems.is_empty(),
        "fields that differ from {REFERENCE}:\n{}",
        problems.join("\n")
    );
}
