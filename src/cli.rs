//! The command line (clap derive). Each subcommand parses into options and calls one library function; no logic
//! lives here beyond turning arguments into those options.

use std::path::{Path, PathBuf};

use clap::{Args, Parser, Subcommand};

use crate::bench::{DemBenchOptions, bench_dem};
use crate::campaign::Campaign;
use crate::error::Result;
use crate::inspect::{self, Format};
use crate::orchestrate::dispatcher::{DispatchOptions, run_campaign};
use crate::simulate::{SimulateOptions, simulate};
use crate::worker::{WorkerOptions, run_worker};

#[derive(Debug, Parser)]
#[command(
    name = "granflow",
    version,
    about = "Coupled DEM + CFD campaigns for particle-process engineering"
)]
pub struct Cli {
    #[command(subcommand)]
    pub command: Command,
}

#[derive(Debug, Subcommand)]
pub enum Command {
    /// Run one scenario (YAML) to its end time, with checkpoints and a time series; resumes when the output
    /// directory already holds a run of the same scenario.
    Simulate {
        /// The scenario file (YAML; `granflow models` lists the model names it may use).
        scenario: PathBuf,
        /// Output directory (default: results/<scenario name>).
        #[arg(long)]
        out: Option<PathBuf>,
        /// Threads for this simulation (results are bit-identical for any count).
        #[arg(long, default_value_t = 1)]
        threads: usize,
        /// Stop after this many steps in this invocation (the run stays resumable).
        #[arg(long)]
        max_steps: Option<u64>,
        /// No progress output; the summary is still printed.
        #[arg(long)]
        quiet: bool,
    },
    /// Benchmarks.
    Bench {
        #[command(subcommand)]
        which: BenchCommand,
    },
    /// List every model name with its parameters and units, and every per-job metric with its unit.
    Models,
    /// Print the JSON Schema of the campaign file (also in schemas/campaign.schema.json).
    Schema,
    /// Run a campaign: expand its sweep, run the jobs in worker processes, store their metrics.
    Run {
        /// The campaign file (YAML; its schema: `granflow schema`).
        campaign: PathBuf,
        /// Campaign directory (default: results/<campaign name>).
        #[arg(long)]
        out: Option<PathBuf>,
        #[command(flatten)]
        dispatch: DispatchArgs,
        /// Run even if the directory holds jobs this campaign file no longer produces.
        #[arg(long)]
        force: bool,
    },
    /// Finish an interrupted campaign (after Ctrl-C, kill -9 or a reboot).
    Resume {
        /// The campaign directory (it holds the campaign file as run).
        dir: PathBuf,
        #[command(flatten)]
        dispatch: DispatchArgs,
    },
    /// Jobs by state, running jobs' progress, failures with reasons, ETA.
    Status {
        /// The campaign directory.
        dir: PathBuf,
    },
    /// Query a campaign's results: a pivot table of one metric over two parameters, or read-only SQL.
    Query {
        /// The campaign directory.
        dir: PathBuf,
        /// Parameter for the columns and parameter for the rows (a swept path or its unique last key).
        #[arg(long, num_args = 2, value_names = ["PARAM_X", "PARAM_Y"], conflicts_with = "sql", requires = "metric")]
        pivot: Option<Vec<String>>,
        /// With --pivot: the metric in the cells (the mean over jobs that share a cell).
        #[arg(long)]
        metric: Option<String>,
        /// With --pivot: only jobs whose parameter has this value (repeatable), e.g. `--where radius_m=0.00135`
        /// to take one particle kind of several instead of averaging over them.
        #[arg(long = "where", value_name = "PARAM=VALUE", requires = "pivot")]
        filters: Vec<String>,
        /// Any read-only SQL over the tables of schemas/results.sql.
        #[arg(long)]
        sql: Option<String>,
        /// Output format.
        #[arg(long, value_enum, default_value = "table")]
        format: Format,
    },
    /// Pictures of a campaign's results (PNG and SVG, written inside the campaign's `plots/` unless --out says
    /// where); prints the files written.
    Plot {
        /// The campaign directory.
        dir: PathBuf,
        #[command(subcommand)]
        picture: PlotPicture,
    },
    /// Snapshots for ParaView (VTK XML, indexed by `particles.pvd` and `gas.pvd`) of every checkpoint a run or job
    /// directory holds; prints the files written. A run with `output.snapshots_every_s` writes them as it goes.
    Snapshots {
        /// The run's (`granflow simulate --out`) or a campaign job's directory.
        dir: PathBuf,
        /// Write them here instead of <dir>/snapshots.
        #[arg(long)]
        out: Option<PathBuf>,
    },
    /// Parameters and metrics, one row per job.
    Export {
        /// The campaign directory.
        dir: PathBuf,
        /// Output format.
        #[arg(long, value_enum, default_value = "csv")]
        format: Format,
    },
    /// Recompute the metrics of every finished job with this build's reducers (after a reducer changed), from each
    /// job's final checkpoint and series; updates result.json, the database and the derived metrics.
    Reduce {
        /// The campaign directory.
        dir: PathBuf,
    },
    /// The validation report (Markdown) of a validation campaign (one with a `validation:` section): our numbers
    /// next to the source's, a verdict.
    Report {
        /// The campaign directory.
        dir: PathBuf,
        /// Write the report here (atomically) instead of printing it.
        #[arg(long)]
        out: Option<PathBuf>,
    },
    /// Map square-well depths onto Hamaker constants by the head-on escape velocity (seed 001 ch. 7): for each
    /// well depth, the escape velocity and the Hamaker constant with the same one. Defaults: seed 001's beads and
    /// contacts (Table 6.2) and well depths (Table 7.1).
    CohesionMap {
        /// Square-well depths D, J (seed 001 Table 7.1: 1e-11 5e-11 1e-10).
        #[arg(long, num_args = 1.., default_values_t = [1e-11, 5e-11, 1e-10])]
        well_depth_j: Vec<f64>,
        /// Bead radius, m.
        #[arg(long, default_value_t = 0.5e-3)]
        radius_m: f64,
        /// Bead density, kg/m³.
        #[arg(long, default_value_t = 2650.0)]
        density_kg_per_m3: f64,
        /// Linear spring stiffness K_n, N/m.
        #[arg(long, default_value_t = 800.0)]
        stiffness_n_per_m: f64,
        /// Dashpot η_n, kg/s.
        #[arg(long, default_value_t = 0.79e-3)]
        damping_kg_per_s: f64,
        /// Hamaker inner cutoff H_cut, m.
        #[arg(long, default_value_t = 4e-10)]
        hamaker_cutoff_m: f64,
    },
    /// Run one job of a campaign in its directory (started by the dispatcher).
    #[command(hide = true)]
    Worker {
        job_dir: PathBuf,
        #[arg(long, default_value_t = 1)]
        threads: usize,
        /// Halve the scenario's time step this many times (a retry after a numerical failure).
        #[arg(long, default_value_t = 0)]
        dt_halvings: u32,
        /// Exit at once when stdin closes (the dispatcher is gone).
        #[arg(long)]
        watch_stdin: bool,
        #[arg(long)]
        max_steps: Option<u64>,
    },
}

/// Which done jobs a picture draws and where it goes (every picture takes these).
#[derive(Debug, Args)]
pub struct Chosen {
    /// Only jobs whose parameter has this value (repeatable), as `query --pivot --where`.
    #[arg(long = "where", value_name = "PARAM=VALUE")]
    pub filters: Vec<String>,
    /// Output file: `.png` or `.svg` for that format only, otherwise a stem given both extensions (default: named
    /// after the picture inside <dir>/plots/).
    #[arg(long)]
    pub out: Option<PathBuf>,
}

/// The pictures `granflow plot` draws.
#[derive(Debug, Subcommand)]
pub enum PlotPicture {
    /// A phase diagram: one metric over two swept parameters as a coloured map, the value in each cell, a colour bar
    /// with the metric's unit.
    Phase {
        /// The parameter along x (a swept path or its unique last key).
        #[arg(long)]
        x: String,
        /// The parameter along y.
        #[arg(long)]
        y: String,
        /// The metric in the cells (the mean over jobs that share a cell).
        #[arg(long)]
        metric: String,
        /// A classification drawn as markers over the cells: a second metric with at most 4 distinct values (e.g.
        /// wet_phase_mixed, seed 000's M/S rule on Ca_g), one shape per value, named under the map.
        #[arg(long)]
        markers: Option<String>,
        #[command(flatten)]
        chosen: Chosen,
    },
    /// A metric against one swept parameter, one line per value of a second (`--lines`); each point the mean over
    /// the jobs at it (replicates, other parameters) with their standard deviation as an error bar.
    Curve {
        /// The parameter along x (a swept path or its unique last key).
        #[arg(long)]
        x: String,
        /// One line per value of this parameter (default: one line).
        #[arg(long)]
        lines: Option<String>,
        /// The metric along y.
        #[arg(long)]
        metric: String,
        #[command(flatten)]
        chosen: Chosen,
    },
    /// A series column against time for each done job matching --where (at most 12), with the model its metric
    /// was fitted with drawn over it (intensity_of_segregation: the mixing rate's exponential; core temperatures:
    /// the h_w line).
    Series {
        /// The series column (a header name of the jobs' series.csv, e.g. intensity_of_segregation).
        #[arg(long)]
        column: String,
        #[command(flatten)]
        chosen: Chosen,
    },
    /// The pressure drop over the bed's weight per area against the gas velocity through the gas.inflow_levels
    /// cycle of each done job matching --where (at most 12), with U_mf,df, U_mf,th, U_mf,in and the stepped onset
    /// (as the job's metrics read them) marked.
    Fluidization {
        #[command(flatten)]
        chosen: Chosen,
    },
}

#[derive(Debug, clap::Args)]
pub struct DispatchArgs {
    /// Workers at once (default: from the campaign, else cores / threads per job).
    #[arg(long)]
    max_parallel: Option<usize>,
    /// Threads per worker (default: from the campaign).
    #[arg(long)]
    threads_per_job: Option<usize>,
    /// No progress display.
    #[arg(long)]
    quiet: bool,
}

#[derive(Debug, Subcommand)]
pub enum BenchCommand {
    /// DEM throughput on the settling-column problem of ../shared/bench/README.md.
    Dem {
        #[arg(long, default_value_t = 1)]
        threads: usize,
        #[arg(long, default_value_t = 20_000)]
        steps: u64,
        /// Also run LIGGGHTS on the reference input in the same invocation and print the ratio.
        #[arg(long)]
        liggghts: bool,
        /// With --threads N > 1: also run the problem on one thread, interleaved with the N-thread run in chunks of
        /// 1000 steps so that both see the same machine, and print `speedup_vs_1_thread: <x>`.
        #[arg(long)]
        speedup: bool,
        /// As --speedup, and also run N independent one-thread copies of the problem side by side and one after
        /// another, interleaved with the rest, printing `ceiling_independent_runs: <x>` (the most that dividing the
        /// work could gain on this machine) and `speedup_share_of_ceiling: <speedup / ceiling>`.
        #[arg(long)]
        ceiling: bool,
        /// The LIGGGHTS input (default: the compiled-in copy of benches/liggghts/in.settle).
        #[arg(long)]
        liggghts_input: Option<PathBuf>,
        #[arg(long, default_value = "liggghts")]
        liggghts_binary: PathBuf,
    },
    /// The dispatcher's cost per job (a campaign of one-step jobs) and the time to resume it when all are done.
    Campaign {
        #[arg(long, default_value_t = 1000)]
        jobs: usize,
        #[arg(long, default_value_t = 2)]
        max_parallel: usize,
        /// Also run the campaign on the Slurm cluster the environment points to (`executor: slurm`) and print both.
        #[arg(long)]
        slurm: bool,
    },
}

/// Exit code of `run`/`resume` when some jobs failed for good.
pub const EXIT_JOBS_FAILED: i32 = 6;
/// Exit code of `run`/`resume` when interrupted (jobs left pending).
pub const EXIT_INTERRUPTED: i32 = 130;

fn dispatch_campaign(campaign: &Campaign, source: &Path, out: &Path, args: DispatchArgs, force: bool) -> Result<i32> {
    let outcome = run_campaign(
        campaign,
        source,
        out,
        &DispatchOptions {
            max_parallel: args.max_parallel,
            threads_per_job: args.threads_per_job,
            quiet: args.quiet,
            force,
        },
    )?;
    eprintln!(
        "{}: {} done, {} failed, {} left{}",
        out.display(),
        outcome.done,
        outcome.failed,
        outcome.pending,
        if outcome.interrupted {
            " (interrupted: `granflow resume` finishes)"
        } else {
            ""
        }
    );
    Ok(if outcome.interrupted {
        EXIT_INTERRUPTED
    } else if outcome.failed > 0 {
        EXIT_JOBS_FAILED
    } else {
        0
    })
}

/// Runs the parsed command; returns the process exit code.
pub fn run(cli: Cli) -> Result<i32> {
    match cli.command {
        Command::Simulate {
            scenario,
            out,
            threads,
            max_steps,
            quiet,
        } => {
            let summary = simulate(&SimulateOptions {
                scenario_path: scenario,
                out_dir: out,
                threads,
                max_steps,
                quiet,
            })?;
            emit(&format!(
                "{}\n",
                serde_json::to_string_pretty(&summary).expect("summary serialises")
            ))?;
            Ok(0)
        }
        Command::Bench {
            which:
                BenchCommand::Dem {
                    threads,
                    steps,
                    liggghts,
                    speedup,
                    ceiling,
                    liggghts_input,
                    liggghts_binary,
                },
        } => bench_dem(&DemBenchOptions {
            threads,
            steps,
            liggghts,
            speedup,
            ceiling,
            liggghts_input,
            liggghts_binary,
        })
        .map(|()| 0),
        Command::Bench {
            which:
                BenchCommand::Campaign {
                    jobs,
                    max_parallel,
                    slurm,
                },
        } => crate::bench_campaign::bench_campaign(&crate::bench_campaign::CampaignBenchOptions {
            jobs,
            max_parallel,
            slurm,
        })
        .map(|()| 0),
        Command::Schema => {
            emit(&format!(
                "{}\n",
                serde_json::to_string_pretty(&crate::campaign::json_schema()).expect("a schema serialises")
            ))?;
            Ok(0)
        }
        Command::Models => {
            emit(&crate::models_doc::text())?;
            Ok(0)
        }
        Command::CohesionMap {
            well_depth_j,
            radius_m,
            density_kg_per_m3,
            stiffness_n_per_m,
            damping_kg_per_s,
            hamaker_cutoff_m,
        } => {
            use crate::analysis::escape_velocity::{HeadOnCollision, linear_spring_restitution};
            use crate::engine::models::cohesion::{Hamaker, SquareWell};
            let mass = density_kg_per_m3 * 4.0 / 3.0 * std::f64::consts::PI * radius_m.powi(3);
            let restitution = linear_spring_restitution(stiffness_n_per_m, damping_kg_per_s, 0.5 * mass);
            let bad = |what: &str| Err(crate::error::Error::External(format!("cohesion-map: {what}")));
            if !(restitution > 0.0 && restitution < 1.0) {
                return bad(&format!(
                    "the contact's restitution is {restitution}: expected in (0, 1)"
                ));
            }
            if well_depth_j.iter().any(|d| !(d.is_finite() && *d > 0.0)) {
                return bad("well depths must be positive");
            }
            let collision = HeadOnCollision {
                stiffness_n_per_m,
                damping_kg_per_s,
                particle_mass_kg: mass,
                radius_m,
                hamaker: Hamaker {
                    constant_j: 0.0,
                    cutoff_m: hamaker_cutoff_m,
                },
            };
            let mut text = format!(
                "particle mass {mass:.6e} kg, contact restitution {restitution:.5}, H_cut {hamaker_cutoff_m:e} m\n\
                 well_depth_j,escape_velocity_m_per_s,hamaker_constant_j\n"
            );
            for depth_j in well_depth_j {
                let well = SquareWell {
                    depth_j,
                    outer_to_inner_radius_ratio: 1.01,
                };
                let v = well.escape_velocity_m_per_s(mass, restitution);
                let a = collision.hamaker_constant_for_escape_velocity_j(v, 1e-5);
                text.push_str(&format!("{depth_j:e},{v:.6e},{a:.6e}\n"));
            }
            emit(&text)?;
            Ok(0)
        }
        Command::Run {
            campaign,
            out,
            dispatch,
            force,
        } => {
            let loaded = crate::campaign::load(&campaign)?;
            let dir = crate::campaign::output_dir(&loaded.spec, out.as_deref());
            dispatch_campaign(&loaded, &campaign, &dir, dispatch, force)
        }
        Command::Resume { dir, dispatch } => {
            let loaded = crate::campaign_dir::load_stored_campaign(&dir)?;
            let source = crate::campaign_dir::spec_copy_path(&dir);
            dispatch_campaign(&loaded, &source, &dir, dispatch, false)
        }
        Command::Plot { dir, picture } => {
            let written = match picture {
                PlotPicture::Phase {
                    x,
                    y,
                    metric,
                    markers,
                    chosen,
                } => crate::plot::phase(
                    &dir,
                    &x,
                    &y,
                    &metric,
                    markers.as_deref(),
                    &chosen.filters,
                    chosen.out.as_deref(),
                )?,
                PlotPicture::Curve {
                    x,
                    lines,
                    metric,
                    chosen,
                } => crate::plot::curve(
                    &dir,
                    &x,
                    lines.as_deref(),
                    &metric,
                    &chosen.filters,
                    chosen.out.as_deref(),
                )?,
                PlotPicture::Series { column, chosen } => {
                    crate::plot::series(&dir, &column, &chosen.filters, chosen.out.as_deref())?
                }
                PlotPicture::Fluidization { chosen } => {
                    crate::plot::fluidization(&dir, &chosen.filters, chosen.out.as_deref())?
                }
            };
            let list: Vec<String> = written.iter().map(|p| p.display().to_string()).collect();
            emit(&format!("{}\n", list.join("\n")))?;
            Ok(0)
        }
        Command::Status { dir } => {
            emit(&inspect::status(&dir)?)?;
            Ok(0)
        }
        Command::Query {
            dir,
            pivot,
            metric,
            filters,
            sql,
            format,
        } => {
            let text = match (pivot, sql) {
                (Some(axes), None) => inspect::pivot(
                    &dir,
                    &axes[0],
                    &axes[1],
                    metric.as_deref().unwrap_or_default(),
                    &filters,
                    format,
                )?,
                (None, Some(sql)) => inspect::sql(&dir, &sql, format)?,
                _ => {
                    return Err(crate::Error::Usage(
                        "query needs either --pivot <PARAM_X> <PARAM_Y> --metric <NAME> or --sql <QUERY>".into(),
                    ));
                }
            };
            emit(&text)?;
            Ok(0)
        }
        Command::Export { dir, format } => {
            emit(&inspect::export(&dir, format)?)?;
            Ok(0)
        }
        Command::Snapshots { dir, out } => {
            let written = crate::snapshot::from_checkpoints(&dir, out.as_deref())?;
            let list: Vec<String> = written.iter().map(|p| p.display().to_string()).collect();
            emit(&format!("{}\n", list.join("\n")))?;
            Ok(0)
        }
        Command::Reduce { dir } => {
            let n = crate::orchestrate::dispatcher::reduce_campaign_again(&dir)?;
            eprintln!("{}: reduced {n} finished job(s) again", dir.display());
            Ok(0)
        }
        Command::Report { dir, out } => {
            let (text, pass) = crate::report::report(&dir)?;
            match out {
                Some(path) => {
                    if let Some(parent) = path.parent().filter(|p| !p.as_os_str().is_empty()) {
                        std::fs::create_dir_all(parent)
                            .map_err(|e| crate::error::Error::io("create directory", parent, e))?;
                    }
                    crate::util::write_atomic(&path, text.as_bytes())?;
                    eprintln!("{}: {}", path.display(), text.lines().last().unwrap_or_default());
                }
                None => emit(&text)?,
            }
            // A failed validation is a result, not an error: exit 0, the verdict says it.
            let _ = pass;
            Ok(0)
        }
        Command::Worker {
            job_dir,
            threads,
            dt_halvings,
            watch_stdin,
            max_steps,
        } => Ok(run_worker(&WorkerOptions {
            job_dir,
            threads,
            dt_halvings,
            watch_stdin,
            max_steps,
        })),
    }
}

/// Writes a command's output to standard output. A reader that stops early (`granflow schema | head -1`) is not an
/// error: the rest is dropped, as other Unix tools do.
fn emit(text: &str) -> Result<(), crate::Error> {
    use std::io::Write;
    let mut out = std::io::stdout().lock();
    match out.write_all(text.as_bytes()).and_then(|()| out.flush()) {
        Err(e) if e.kind() != std::io::ErrorKind::BrokenPipe => {
            Err(crate::Error::io("write", std::path::Path::new("standard output"), e))
        }
        _ => Ok(()),
    }
}
