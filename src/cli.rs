//! The command line (clap derive). Each subcommand parses into options and calls one library function; no logic
//! lives here beyond turning arguments into those options.

use std::path::PathBuf;

use clap::{Parser, Subcommand};

use crate::bench::{DemBenchOptions, bench_dem};
use crate::error::Result;
use crate::simulate::{SimulateOptions, simulate};

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
        #[arg(long)]
        quiet: bool,
    },
    /// Benchmarks.
    Bench {
        #[command(subcommand)]
        which: BenchCommand,
    },
    /// List every model name with its parameters and units.
    Models,
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
        /// The LIGGGHTS input (default: ../shared/bench/liggghts/in.settle, searched upwards from here).
        #[arg(long)]
        liggghts_input: Option<PathBuf>,
        #[arg(long, default_value = "liggghts")]
        liggghts_binary: PathBuf,
    },
}

/// Runs the parsed command.
pub fn run(cli: Cli) -> Result<()> {
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
            println!(
                "{}",
                serde_json::to_string_pretty(&summary).expect("summary serialises")
            );
            Ok(())
        }
        Command::Bench {
            which:
                BenchCommand::Dem {
                    threads,
                    steps,
                    liggghts,
                    speedup,
                    liggghts_input,
                    liggghts_binary,
                },
        } => bench_dem(&DemBenchOptions {
            threads,
            steps,
            liggghts,
            speedup,
            liggghts_input,
            liggghts_binary,
        }),
        Command::Models => {
            print!("{}", crate::models_doc::MODELS);
            Ok(())
        }
    }
}
