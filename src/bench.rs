//! `granflow bench dem`: the DEM throughput benchmark of `../shared/bench/README.md`, optionally run side by side
//! with LIGGGHTS on its reference input in the same invocation, printing both throughputs, the physics of both
//! (kinetic-energy history, final bed height) and the ratio.
//!
//! The problem is `scenarios/bench-settle.yaml` (compiled in). LIGGGHTS runs an exact copy of `in.settle`
//! (`benches/liggghts/in.settle`, compiled in; `--liggghts-input` gives another) in a temporary directory with two thermo columns added (highest and mean particle height); nothing else changes.

use std::path::{Path, PathBuf};
use std::process::Command;
use std::time::Instant;

use crate::engine::Simulation;
use crate::error::{Error, Result};
use crate::scenario;

pub const BENCH_SCENARIO: &str = include_str!("../scenarios/bench-settle.yaml");

/// The LIGGGHTS reference input of the benchmark (a copy of `../shared/bench/liggghts/in.settle`, compiled in).
pub const LIGGGHTS_INPUT: &str = include_str!("../benches/liggghts/in.settle");

#[derive(Debug, Clone)]
pub struct DemBenchOptions {
    pub threads: usize,
    pub steps: u64,
    pub liggghts: bool,
    /// Also run one thread, interleaved with the `threads` run (see [`run_interleaved`]).
    pub speedup: bool,
    /// As `speedup`, and also measure the machine's ceiling for it (see [`run_interleaved`]).
    pub ceiling: bool,
    pub liggghts_input: Option<PathBuf>,
    pub liggghts_binary: PathBuf,
}

/// One sample of a run's physics: step, translational KE (J), highest and mean centre height (m).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct PhysicsSample {
    pub step: u64,
    pub kinetic_energy_j: f64,
    pub top_z_m: f64,
    pub mean_z_m: f64,
}

#[derive(Debug, Clone)]
pub struct RunFigures {
    pub particles: usize,
    pub steps: u64,
    pub loop_time_s: f64,
    pub samples: Vec<PhysicsSample>,
}

impl RunFigures {
    pub fn particle_steps_per_s(&self) -> f64 {
        self.particles as f64 * self.steps as f64 / self.loop_time_s
    }
}

const SAMPLE_EVERY: u64 = 5000;

fn sample(sim: &Simulation) -> PhysicsSample {
    let p = &sim.particles;
    let mut top = f64::NEG_INFINITY;
    let mut sum = 0.0;
    for x in &p.position_m {
        top = top.max(x.z);
        sum += x.z;
    }
    PhysicsSample {
        step: sim.step,
        kinetic_energy_j: p.translational_kinetic_energy_j(),
        top_z_m: top,
        mean_z_m: sum / p.len() as f64,
    }
}

/// Peak resident memory of this process (VmHWM), bytes.
fn peak_rss_bytes() -> Option<u64> {
    let status = std::fs::read_to_string("/proc/self/status").ok()?;
    let line = status.lines().find(|l| l.starts_with("VmHWM:"))?;
    let kb: u64 = line.split_whitespace().nth(1)?.parse().ok()?;
    Some(kb * 1024)
}

fn bench_simulation(threads: usize) -> Result<Simulation> {
    let built = scenario::build(
        scenario::parse(BENCH_SCENARIO, Path::new("scenarios/bench-settle.yaml"))?,
        Path::new("scenarios/bench-settle.yaml"),
    )?;
    Ok(Simulation::new(
        built.config.clone(),
        built.particles,
        built.dt_s,
        built.rng,
        threads,
    )?)
}

/// Steps per turn of [`run_interleaved`].
const INTERLEAVE_STEPS: u64 = 1000;

/// What [`run_interleaved`] measured.
pub struct Interleaved {
    /// The `threads` run.
    pub many: RunFigures,
    /// The one-thread run.
    pub one: RunFigures,
    /// The `threads` simulation at the end.
    pub sim: Simulation,
    /// The first difference between the `threads` run's and the one-thread run's final states (`None`:
    /// bit-identical, as the engine guarantees for any thread count).
    pub difference: Option<String>,
    /// With `ceiling`: the machine's own ceiling for the speed-up (see [`run_interleaved`]).
    pub ceiling: Option<Ceiling>,
}

/// `threads` independent one-thread runs of the benchmark, one after another and side by side.
pub struct Ceiling {
    /// Time of the runs one after another over time of the same runs side by side.
    pub speedup: f64,
    /// The first difference between a side-by-side run's final state and the one-thread run's (`None`: identical).
    pub difference: Option<String>,
}

/// Runs the benchmark on `threads` threads and on one thread in turns of [`INTERLEAVE_STEPS`] steps (the order
/// rotating from turn to turn), timing each run's turns only. A machine whose speed drifts during the benchmark
/// (a shared virtual machine's does, by 10 % and more between runs a minute apart) then slows both runs alike,
/// and their ratio measures the parallel speed-up rather than the drift.
///
/// With `ceiling`, two more contestants take their turns: `threads` independent one-thread simulations of the same
/// problem run one after another, and another `threads` run side by side, each on its own thread with nothing
/// shared. Their time ratio is what this machine gives `threads` busy threads on this work: where the virtual
/// machine's cores share a physical core's execution units, or the host runs other work beside them, it falls short
/// of `threads`. It is a reference rather than a strict bound on a divided run: the copies hold `threads` times the
/// data, so a run that divides one copy can come out a little above it.
pub fn run_interleaved(threads: usize, steps: u64, ceiling: bool) -> Result<Interleaved> {
    let mut many = bench_simulation(threads)?;
    let mut one = bench_simulation(1)?;
    let copies = if ceiling { threads } else { 0 };
    let mut after_another = (0..copies).map(|_| bench_simulation(1)).collect::<Result<Vec<_>>>()?;
    let mut side_by_side = (0..copies).map(|_| bench_simulation(1)).collect::<Result<Vec<_>>>()?;
    let mut samples = vec![sample(&many)];
    let contestants = if ceiling { 4 } else { 2 };
    let mut time_s = [0.0f64; 4];
    let mut turn = 0u64;
    while many.step < steps {
        let chunk = (INTERLEAVE_STEPS - many.step % INTERLEAVE_STEPS).min(steps - many.step);
        for k in 0..contestants {
            let which = (turn as usize + k) % contestants;
            let start = Instant::now();
            match which {
                0 => many.run_steps(chunk)?,
                1 => one.run_steps(chunk)?,
                2 => after_another.iter_mut().try_for_each(|s| s.run_steps(chunk))?,
                _ => std::thread::scope(|scope| {
                    let runs: Vec<_> = side_by_side
                        .iter_mut()
                        .map(|s| scope.spawn(move || s.run_steps(chunk)))
                        .collect();
                    runs.into_iter()
                        .try_for_each(|r| r.join().expect("a side-by-side benchmark run panicked"))
                })?,
            }
            time_s[which] += start.elapsed().as_secs_f64();
        }
        turn += 1;
        if many.step % SAMPLE_EVERY == 0 || many.step == steps {
            samples.push(sample(&many));
        }
    }
    let particles = many.particles.len();
    let one_state = one.snapshot();
    let difference = crate::engine::state::first_difference(&many.snapshot(), &one_state);
    let ceiling = ceiling.then(|| Ceiling {
        speedup: time_s[2] / time_s[3],
        difference: side_by_side
            .iter()
            .find_map(|s| crate::engine::state::first_difference(&s.snapshot(), &one_state)),
    });
    let figures = |loop_time_s: f64, samples: Vec<PhysicsSample>| RunFigures {
        particles,
        steps,
        loop_time_s,
        samples,
    };
    Ok(Interleaved {
        many: figures(time_s[0], samples),
        one: figures(time_s[1], Vec::new()),
        sim: many,
        difference,
        ceiling,
    })
}

/// Runs granflow on the benchmark problem.
pub fn run_granflow(threads: usize, steps: u64) -> Result<(RunFigures, Simulation)> {
    let mut sim = bench_simulation(threads)?;
    let mut samples = vec![sample(&sim)];
    let start = Instant::now();
    while sim.step < steps {
        let chunk = (SAMPLE_EVERY - sim.step % SAMPLE_EVERY).min(steps - sim.step);
        sim.run_steps(chunk)?;
        if sim.step % SAMPLE_EVERY == 0 || sim.step == steps {
            samples.push(sample(&sim));
        }
    }
    let loop_time_s = start.elapsed().as_secs_f64();
    Ok((
        RunFigures {
            particles: sim.particles.len(),
            steps,
            loop_time_s,
            samples,
        },
        sim,
    ))
}

/// Runs LIGGGHTS on a copy of the reference input `text` (named `source` in messages) with height columns added to
/// its thermo output.
pub fn run_liggghts(binary: &Path, text: &str, source: &str, steps: u64) -> Result<(RunFigures, Option<f64>)> {
    let mut modified = String::new();
    let mut saw_thermo_style = false;
    for line in text.lines() {
        if line.trim_start().starts_with("thermo_style") {
            saw_thermo_style = true;
            modified.push_str("compute gf_ztop all reduce max z\ncompute gf_zmean all reduce ave z\n");
            modified.push_str("thermo_style custom step atoms ke c_gf_ztop c_gf_zmean\n");
        } else if line.trim_start().starts_with("run ") && steps != 20_000 {
            modified.push_str(&format!("run {steps}\n"));
        } else {
            modified.push_str(line);
            modified.push('\n');
        }
    }
    if !saw_thermo_style {
        return Err(Error::External(format!("{source} has no thermo_style line to extend")));
    }
    let dir = tempfile::tempdir().map_err(|e| Error::io("create temporary directory", std::env::temp_dir(), e))?;
    let copy = dir.path().join("in.settle");
    std::fs::write(&copy, modified).map_err(|e| Error::io("write", &copy, e))?;
    let output = Command::new(binary)
        .arg("-in")
        .arg(&copy)
        .current_dir(dir.path())
        .output()
        .map_err(|e| Error::io("run", binary, e))?;
    let stdout = String::from_utf8_lossy(&output.stdout);
    if !output.status.success() {
        return Err(Error::External(format!(
            "{} failed ({}): {}",
            binary.display(),
            output.status,
            stdout.lines().rev().take(5).collect::<Vec<_>>().join(" | ")
        )));
    }
    parse_liggghts_log(&stdout)
}

/// Parses LIGGGHTS' thermo table and "Loop time of T on 1 procs for S steps with N atoms".
pub fn parse_liggghts_log(log: &str) -> Result<(RunFigures, Option<f64>)> {
    let mut samples = Vec::new();
    let mut in_table = false;
    let mut figures = None;
    let mut memory_mb = None;
    for line in log.lines() {
        let t = line.trim();
        if t.starts_with("Memory usage per processor") {
            memory_mb = t
                .split('=')
                .nth(1)
                .and_then(|s| s.split_whitespace().next())
                .and_then(|s| s.parse().ok());
        }
        if t.starts_with("Step") {
            in_table = true;
            continue;
        }
        if t.starts_with("Loop time of") {
            in_table = false;
            let words: Vec<&str> = t.split_whitespace().collect();
            let num = |k: usize| words.get(k).and_then(|w| w.trim_end_matches(',').parse::<f64>().ok());
            if let (Some(time), Some(steps), Some(atoms)) = (num(3), num(8), num(11)) {
                figures.get_or_insert((time, steps as u64, atoms as usize));
            }
            continue;
        }
        if in_table {
            let cols: Vec<f64> = t.split_whitespace().filter_map(|w| w.parse().ok()).collect();
            if cols.len() == 5 {
                samples.push(PhysicsSample {
                    step: cols[0] as u64,
                    kinetic_energy_j: cols[2],
                    top_z_m: cols[3],
                    mean_z_m: cols[4],
                });
            } else {
                in_table = false;
            }
        }
    }
    let (loop_time_s, steps, particles) =
        figures.ok_or_else(|| Error::External("LIGGGHTS printed no 'Loop time of' line".into()))?;
    Ok((
        RunFigures {
            particles,
            steps,
            loop_time_s,
            samples,
        },
        memory_mb,
    ))
}

fn rel(a: f64, b: f64) -> f64 {
    if b == 0.0 { f64::NAN } else { (a - b) / b }
}

/// Runs the benchmark and prints its report; the last line is `ratio_vs_liggghts: <x>` when LIGGGHTS ran.
pub fn bench_dem(opts: &DemBenchOptions) -> Result<()> {
    let (ours, sim, one_thread, ceiling) = if (opts.speedup || opts.ceiling) && opts.threads > 1 {
        let run = run_interleaved(opts.threads, opts.steps, opts.ceiling)?;
        (run.many, run.sim, Some((run.one, run.difference)), run.ceiling)
    } else {
        let (ours, sim) = run_granflow(opts.threads, opts.steps)?;
        (ours, sim, None, None)
    };
    let heap = sim.heap_bytes();
    println!(
        "granflow: {} particles, {} steps, {} thread(s): loop time {:.2} s, {:.4e} particle-steps/s, {} neighbour-list builds (cell searches) and {} refilters of the force pass's list",
        ours.particles,
        ours.steps,
        sim.threads(),
        ours.loop_time_s,
        ours.particle_steps_per_s(),
        sim.neighbor_builds(),
        sim.neighbor_refilters()
    );
    if let Some((one, difference)) = &one_thread {
        println!(
            "granflow: the same on 1 thread, interleaved in turns of {INTERLEAVE_STEPS} steps: loop time {:.2} s, {:.4e} particle-steps/s; final states {}",
            one.loop_time_s,
            one.particle_steps_per_s(),
            match difference {
                None => "bit-identical".to_string(),
                Some(d) => format!("DIFFER: {d}"),
            }
        );
        let speedup = one.loop_time_s / ours.loop_time_s;
        println!("speedup_vs_1_thread: {speedup:.3}");
        if let Some(d) = difference {
            return Err(Error::External(format!(
                "the {}-thread and 1-thread runs ended in different states ({d})",
                opts.threads
            )));
        }
        if let Some(c) = &ceiling {
            println!(
                "granflow: {n} independent 1-thread runs of the same problem, interleaved with the above: side by side on {n} threads {:.3} times as fast as one after another; final states {}",
                c.speedup,
                match &c.difference {
                    None => "bit-identical to the 1-thread run's".to_string(),
                    Some(d) => format!("DIFFER: {d}"),
                },
                n = opts.threads
            );
            println!("ceiling_independent_runs: {:.3}", c.speedup);
            println!("speedup_share_of_ceiling: {:.3}", speedup / c.speedup);
            if let Some(d) = &c.difference {
                return Err(Error::External(format!(
                    "a side-by-side 1-thread run ended in a different state ({d})"
                )));
            }
        }
    }
    let (pair_contacts, wall_contacts) = sim.contact_counts();
    println!(
        "granflow: at the end: {:.2} candidate pairs in the force pass's list (inner skin {} mm), {:.2} particle contacts and {:.3} wall contacts per particle",
        sim.candidate_pairs() as f64 / ours.particles as f64,
        sim.config.inner_skin_m * 1e3,
        pair_contacts as f64 / ours.particles as f64,
        wall_contacts as f64 / ours.particles as f64
    );
    let t = sim.timers;
    let total = (t.force + t.neighbor + t.integrate).as_secs_f64().max(1e-12);
    println!(
        "granflow: stages: force loop (with fused kicks and drift) {:.1} %, neighbour {:.1} %, separate kick-drift passes {:.1} %",
        100.0 * t.force.as_secs_f64() / total,
        100.0 * t.neighbor.as_secs_f64() / total,
        100.0 * t.integrate.as_secs_f64() / total
    );
    println!(
        "granflow: memory: {:.0} bytes/particle in engine arrays; peak resident {:.1} MB for the whole process",
        heap as f64 / ours.particles as f64,
        peak_rss_bytes().map_or(f64::NAN, |b| b as f64 / 1e6)
    );
    if !opts.liggghts {
        for s in &ours.samples {
            println!(
                "granflow: step {:>6} KE {:.5e} J, highest centre {:.5} m, mean centre {:.5} m",
                s.step, s.kinetic_energy_j, s.top_z_m, s.mean_z_m
            );
        }
        return Ok(());
    }
    let (text, source) = match &opts.liggghts_input {
        Some(p) => (
            std::fs::read_to_string(p).map_err(|e| Error::io("read", p, e))?,
            p.display().to_string(),
        ),
        None => (LIGGGHTS_INPUT.to_string(), "benches/liggghts/in.settle".to_string()),
    };
    let (theirs, memory_mb) = run_liggghts(&opts.liggghts_binary, &text, &source, opts.steps)?;
    println!(
        "liggghts: {} particles, {} steps, 1 process: loop time {:.2} s, {:.4e} particle-steps/s{}",
        theirs.particles,
        theirs.steps,
        theirs.loop_time_s,
        theirs.particle_steps_per_s(),
        memory_mb.map_or(String::new(), |m| format!(
            ", memory {m:.2} MB ({:.0} bytes/particle, its own estimate)",
            m * 1.048576e6 / theirs.particles as f64
        ))
    );
    println!(
        "physics:   step      KE granflow (J)  KE liggghts (J)  diff     top z granflow  top z liggghts  mean z granflow  mean z liggghts  diff"
    );
    for s in &ours.samples {
        if let Some(l) = theirs.samples.iter().find(|l| l.step == s.step) {
            println!(
                "physics: {:>6}  {:>15.5e}  {:>15.5e}  {:>+7.2} %  {:>14.5}  {:>14.5}  {:>15.5}  {:>15.5}  {:>+6.2} %",
                s.step,
                s.kinetic_energy_j,
                l.kinetic_energy_j,
                100.0 * rel(s.kinetic_energy_j, l.kinetic_energy_j),
                s.top_z_m,
                l.top_z_m,
                s.mean_z_m,
                l.mean_z_m,
                100.0 * rel(s.mean_z_m, l.mean_z_m)
            );
        }
    }
    println!(
        "ratio_vs_liggghts: {:.3}",
        ours.particle_steps_per_s() / theirs.particle_steps_per_s()
    );
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The compiled-in LIGGGHTS input is the shared reference, where that is beside the checkout; and it sets up the
    /// problem of `scenarios/bench-settle.yaml` (box, particle count from the lattice, material, steps).
    #[test]
    fn the_liggghts_input_is_the_shared_reference() {
        let shared = Path::new(env!("CARGO_MANIFEST_DIR")).join("../shared/bench/liggghts/in.settle");
        if let Ok(reference) = std::fs::read_to_string(&shared) {
            assert_eq!(
                LIGGGHTS_INPUT,
                reference,
                "benches/liggghts/in.settle differs from {}",
                shared.display()
            );
        }
        for line in [
            "region reg block 0 0.06 0 0.06 0 0.3 units box",
            "fix m1 all property/global youngsModulus peratomtype 1.0e7",
            "fix m2 all property/global poissonsRatio peratomtype 0.33",
            "run 20000",
        ] {
            assert!(
                LIGGGHTS_INPUT.lines().any(|l| l.trim() == line),
                "no `{line}` in the input"
            );
        }
    }

    #[test]
    fn parses_a_liggghts_log() {
        let log = "Memory usage per processor = 18.4905 Mbytes\n    Step    Atoms         KinEng     c_gf_ztop c_gf_zmean\n       0    29160              0 0.288 0.1 \n    5000    29160      0.0621384 0.2 0.05\nLoop time of 110.872 on 1 procs for 5000 steps with 29160 atoms, finish time Sun\n";
        let (f, mem) = parse_liggghts_log(log).expect("parses");
        assert_eq!(f.particles, 29160);
        assert_eq!(f.steps, 5000);
        assert!((f.loop_time_s - 110.872).abs() < 1e-9);
        assert_eq!(f.samples.len(), 2);
        assert_eq!(f.samples[1].kinetic_energy_j, 0.0621384);
        assert_eq!(mem, Some(18.4905));
    }

    #[test]
    fn interleaved_runs_with_the_ceiling_all_end_in_the_one_thread_state() {
        // Past the first turn, so that every contestant runs in two turns and the order rotates.
        let run = run_interleaved(2, INTERLEAVE_STEPS + 150, true).expect("the benchmark runs");
        assert_eq!(run.difference, None);
        assert_eq!(run.sim.step, INTERLEAVE_STEPS + 150);
        assert_eq!(run.sim.threads(), 2);
        let ceiling = run.ceiling.expect("asked for");
        assert_eq!(ceiling.difference, None);
        for ratio in [ceiling.speedup, run.one.loop_time_s / run.many.loop_time_s] {
            assert!(ratio.is_finite() && ratio > 0.0, "ratio {ratio}");
        }
        assert_eq!(run.many.samples.first().map(|s| s.step), Some(0));
        assert_eq!(run.many.samples.last().map(|s| s.step), Some(INTERLEAVE_STEPS + 150));
    }
}
