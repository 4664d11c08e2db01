//! The campaign file as the user writes it (YAML, serde, unknown keys rejected): a `base` scenario, a `sweep` over
//! dotted parameter paths of that scenario, the metrics to reduce, how to run the jobs and what to do when they fail.

use serde::{Deserialize, Serialize};

use crate::analysis::mixing::Concentration;
use crate::scenario::ScenarioSpec;

#[derive(Debug, Clone, PartialEq, Serialize, Deserialize, schemars::JsonSchema)]
#[serde(deny_unknown_fields)]
pub struct CampaignSpec {
    /// Also the default output directory, `results/<name>/`. Letters, digits, `-`, `_` and `.` only.
    pub name: String,
    #[serde(default)]
    pub description: String,
    /// The scenario every job starts from (the keys of a scenario file; `name` may be left out).
    pub base: ScenarioSpec,
    /// Named sets of parameter values (a baffle layout, a material): set → member name → (parameter path →
    /// value). A sweep takes a set's member names as the values of the parameter `named.<set>`; each job then gets
    /// the member's values, and stores the name (`campaign::named`).
    #[serde(default, skip_serializing_if = "std::collections::BTreeMap::is_empty")]
    pub named: super::named::NamedSets,
    pub sweep: SweepNode,
    /// Per-job reducers by name (`granflow models` lists them); stored as metrics with units.
    // Read as text and checked by `metrics::check`, so that an unknown name is reported at its key with a
    // did-you-mean; the schema still lists the names.
    #[serde(default = "default_metrics")]
    #[schemars(with = "Vec<crate::campaign::metrics::JobMetric>")]
    pub metrics: Vec<String>,
    /// Settings of the reducers that need them.
    #[serde(default)]
    pub analysis: AnalysisSpec,
    #[serde(default)]
    pub executor: ExecutorSpec,
    /// Checkpoint cadence of every job (overrides the base scenario's `output`).
    #[serde(default)]
    pub checkpoint: CheckpointPolicy,
    #[serde(default)]
    pub retry: RetryPolicy,
    /// Seeds every job's random generator together with the job's parameters, unless the sweep sets `seed`.
    #[serde(default)]
    pub seed: u64,
    /// Refuse a sweep of more jobs than this (counted before anything is expanded). Default 10,000: a laptop's
    /// dispatcher and SQLite database handle that many comfortably (about 8 ms of overhead per job, 0.2 s to resume
    /// them all); at most 1,000,000.
    #[serde(default = "default_max_jobs")]
    pub max_jobs: usize,
    /// Campaign-level metrics computed from several jobs (e.g. u_mf from a velocity sweep).
    #[serde(default)]
    pub derived: Vec<super::derived::DerivedSpec>,
    /// Run the first seconds of jobs that cannot differ before then once per group of them, and start each job
    /// from that state (`campaign::prepare`).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub prepare: Option<super::prepare::PrepareSpec>,
    /// A validation campaign: the case it reproduces and the checks `granflow report` evaluates.
    #[serde(default)]
    pub validation: Option<super::validation::ValidationSpec>,
}

fn default_metrics() -> Vec<String> {
    use super::metrics::JobMetric;
    [
        JobMetric::KineticEnergy,
        JobMetric::BedTop,
        JobMetric::MeanHeight,
        JobMetric::CoordinationNumber,
    ]
    .iter()
    .map(|m| m.name().to_string())
    .collect()
}

fn default_max_jobs() -> usize {
    10_000
}

/// The most `max_jobs` may be raised to: every job is held in memory (its resolved scenario) while the campaign is
/// expanded and validated, a few kilobytes each.
pub const MAX_JOBS_CEILING: usize = 1_000_000;

/// One node of the sweep tree. Exactly one of the kinds is given:
/// - an axis: `param` with one of `values`, `linspace`, `logspace`;
/// - `grid`: the Cartesian product of its children (in order, the last varying fastest);
/// - `zip`: its children side by side (all of the same length);
/// - `list`: explicit points, each a map from parameter path to value.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize, Default, schemars::JsonSchema)]
#[serde(deny_unknown_fields)]
pub struct SweepNode {
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub param: Option<String>,
    /// A short name for the axis in the database, queries and exports (default: the parameter path).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub name: Option<String>,
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub values: Option<Vec<serde_json::Value>>,
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub linspace: Option<Range>,
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub logspace: Option<Range>,
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub grid: Option<Vec<SweepNode>>,
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub zip: Option<Vec<SweepNode>>,
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub list: Option<Vec<serde_json::Map<String, serde_json::Value>>>,
}

/// `num` points from `start` to `stop` inclusive: evenly spaced (`linspace`) or geometrically (`logspace`; `start`
/// and `stop` are the end values themselves, not their logarithms).
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize, schemars::JsonSchema)]
#[serde(deny_unknown_fields)]
pub struct Range {
    pub start: f64,
    pub stop: f64,
    pub num: usize,
}

#[derive(Debug, Clone, PartialEq, Serialize, Deserialize, schemars::JsonSchema)]
#[serde(deny_unknown_fields)]
pub struct AnalysisSpec {
    /// Binary mixing: which species is "A" for the intensity of segregation and the Lacey index.
    #[serde(default)]
    pub mixing_species: Option<String>,
    /// Nearest neighbours per sample (seed 000 eqs 2.77–2.78 use 10).
    #[serde(default = "default_neighbours")]
    pub mixing_neighbours: usize,
    /// Mixing state sampled every this many steps (a multiple of the series cadence).
    #[serde(default)]
    pub mixing_every_steps: Option<u64>,
    /// How a sample's concentration of the mixing species is counted: `number` (default; the seed's count of
    /// particles, right for unequal sizes too) or `volume` (volume fractions, each sample weighted by its
    /// particle's volume). The same for equal sizes. See `analysis::mixing::mixing_state`.
    #[serde(default, skip_serializing_if = "is_number_concentration")]
    pub mixing_concentration: Concentration,
    /// Time averages (pressure drop, mean height) start here, s; default: half the end time.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub average_from_s: Option<f64>,
    /// The porosity ε at which the granular capillary numbers evaluate the drag, with the slip speed U/ε from the
    /// inlet's superficial velocity U (seed 000 eq 4.3). Default 0.55: with it eq 4.3 gives seed 000 Table 3's
    /// Ca_g11 = 2.12 and Ca_g22 = 1.93 (air at 1.8 m/s, γ = 0.030 N/m from its Bo_g11) within 1 %.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub capillary_number_porosity: Option<f64>,
    /// The mixing rate constant fits IS(t) from this time on, s (default: from the start); for runs that settle or
    /// start a gas before mixing begins.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub mixing_fit_from_s: Option<f64>,
    /// Which pressure drop the cycle metrics (`gas.inflow_levels`: U_mf,df, U_mf,th, U_mf,in, the overshoot) read:
    /// `column` (default), the inlet face to the outlet against W/A of the whole bed; or `first_node`, seed 001's
    /// reading, the first node (the inlet layer's centre) to the outlet against W'/A, the weight beyond that node
    /// (notes §4.1).
    #[serde(default, skip_serializing_if = "CyclePressure::is_column")]
    pub cycle_pressure: CyclePressure,
    /// h_w (a heated drum) fits the core's heating from this time on, s (default: when the drum starts heating).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub heating_fit_from_s: Option<f64>,
    /// Seed 001's height mixing index (`height_mixing_index`) splits the particles into the families above and
    /// below the bed's median height at the first series row the job writes at or after this time, s (default 0:
    /// its first row; after a shared preparation, the first row after it: the packed bed the seed starts from).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub height_families_at_s: Option<f64>,
    /// The line of CV_m against 1/√t (the `coating_variability_fit_*` metrics), t the coating time since the spray
    /// started (`spray.start_s`), takes the series from this coating time on, s (default 1: seed 000 §6.3.2, "all
    /// data achieved over 1 second show a linear correlation").
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub coating_fit_from_s: Option<f64>,
    /// β of seed 000's critical flip frequency (eq. 3.5, `critical_flip_frequency_hz`): the segregation Péclet
    /// number over (1 − ρ̄), "a fitting parameter" (default 0.1, the value the seed fits for its chute, Fig. 19).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub segregation_beta: Option<f64>,
}

/// The pressure drop of the cycle metrics; see [`AnalysisSpec::cycle_pressure`].
#[derive(Debug, Clone, Copy, Default, PartialEq, Eq, Serialize, Deserialize, schemars::JsonSchema)]
#[serde(rename_all = "snake_case")]
pub enum CyclePressure {
    /// From the inlet face (the first layer of cells extrapolated) to the outlet, against W/A of the whole bed.
    #[default]
    Column,
    /// From the centre of the first layer of cells to the outlet, against W'/A of the particles beyond it.
    FirstNode,
}

impl CyclePressure {
    fn is_column(&self) -> bool {
        *self == CyclePressure::Column
    }
}

fn is_number_concentration(c: &Concentration) -> bool {
    *c == Concentration::Number
}

fn default_neighbours() -> usize {
    10
}

impl Default for AnalysisSpec {
    fn default() -> Self {
        AnalysisSpec {
            mixing_species: None,
            mixing_neighbours: default_neighbours(),
            mixing_every_steps: None,
            mixing_concentration: Concentration::Number,
            average_from_s: None,
            capillary_number_porosity: None,
            mixing_fit_from_s: None,
            cycle_pressure: CyclePressure::Column,
            heating_fit_from_s: None,
            height_families_at_s: None,
            coating_fit_from_s: None,
            segregation_beta: None,
        }
    }
}

#[derive(Debug, Clone, PartialEq, Serialize, Deserialize, schemars::JsonSchema)]
#[serde(rename_all = "snake_case", deny_unknown_fields)]
pub enum ExecutorSpec {
    /// Worker processes on this machine.
    Local(LocalExecutor),
    /// Job arrays on a Slurm cluster: one array task per job, `granflow worker` on the job's directory (which must
    /// be on a filesystem the compute nodes share); the dispatcher submits with `sbatch` and follows with `squeue`.
    Slurm(SlurmExecutor),
}

/// `executor: slurm: {…}`: what every array task asks Slurm for.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize, schemars::JsonSchema)]
#[serde(deny_unknown_fields)]
pub struct SlurmExecutor {
    /// `--partition` (default: the cluster's default partition).
    #[serde(default)]
    pub partition: Option<String>,
    /// `--time` of each task, in Slurm's forms (`minutes`, `HH:MM:SS`, `D-HH:MM:SS`, …; default: the partition's).
    /// A task reaching it is warned `signal_before_end_s` before, checkpoints and is requeued.
    #[serde(default)]
    pub time_limit: Option<String>,
    /// `--cpus-per-task`, also the worker's threads.
    #[serde(default = "one")]
    pub cpus_per_task: usize,
    /// `--mem` per task (e.g. `4G`; default: the partition's).
    #[serde(default)]
    pub memory: Option<String>,
    #[serde(default)]
    pub account: Option<String>,
    #[serde(default)]
    pub qos: Option<String>,
    /// Tasks of one array running at once (`--array=…%N`; default: no limit).
    #[serde(default)]
    pub array_throttle: Option<usize>,
    /// Further `sbatch` options, each one argument (e.g. `--constraint=skylake`).
    #[serde(default)]
    pub sbatch_options: Vec<String>,
    /// Seconds before the time limit (or a preemption) at which Slurm sends the task SIGTERM (`--signal`): the
    /// worker checkpoints and the task requeues itself.
    #[serde(default = "default_signal_before_end")]
    pub signal_before_end_s: u32,
    /// How often the dispatcher asks `squeue` about its tasks.
    #[serde(default = "default_poll_interval")]
    pub poll_interval_s: f64,
}

fn default_signal_before_end() -> u32 {
    120
}

fn default_poll_interval() -> f64 {
    10.0
}

impl Default for ExecutorSpec {
    fn default() -> Self {
        ExecutorSpec::Local(LocalExecutor::default())
    }
}

#[derive(Debug, Clone, PartialEq, Serialize, Deserialize, schemars::JsonSchema)]
#[serde(deny_unknown_fields)]
pub struct LocalExecutor {
    /// Workers at once. Default: the number of cores divided by `threads_per_job`.
    #[serde(default)]
    pub max_parallel: Option<usize>,
    #[serde(default = "one")]
    pub threads_per_job: usize,
    /// A job running longer than this is stopped and counted as a timeout.
    #[serde(default)]
    pub job_timeout_s: Option<f64>,
    /// A worker silent for longer than this is killed and counted as lost.
    #[serde(default = "default_heartbeat_timeout")]
    pub heartbeat_timeout_s: f64,
}

fn one() -> usize {
    1
}

fn default_heartbeat_timeout() -> f64 {
    60.0
}

impl Default for LocalExecutor {
    fn default() -> Self {
        LocalExecutor {
            max_parallel: None,
            threads_per_job: 1,
            job_timeout_s: None,
            heartbeat_timeout_s: default_heartbeat_timeout(),
        }
    }
}

#[derive(Debug, Clone, PartialEq, Serialize, Deserialize, schemars::JsonSchema)]
#[serde(deny_unknown_fields)]
pub struct CheckpointPolicy {
    #[serde(default = "default_checkpoint_every")]
    pub every_steps: u64,
    #[serde(default = "default_keep")]
    pub keep: usize,
}

fn default_checkpoint_every() -> u64 {
    5000
}
fn default_keep() -> usize {
    2
}

impl Default for CheckpointPolicy {
    fn default() -> Self {
        CheckpointPolicy {
            every_steps: default_checkpoint_every(),
            keep: default_keep(),
        }
    }
}

/// Extra attempts allowed per failure class. A configuration error never retries; a preempted job (stopped by a
/// signal after checkpointing) is requeued without using an attempt.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize, schemars::JsonSchema)]
#[serde(deny_unknown_fields)]
pub struct RetryPolicy {
    /// Non-finite values, excessive overlap, lost particle.
    #[serde(default)]
    pub numerical: u32,
    /// The worker exited abnormally (panic, I/O failure, unreadable checkpoint).
    #[serde(default = "two")]
    pub crash: u32,
    /// The worker was killed by a signal it did not handle (e.g. `kill -9`, out of memory).
    #[serde(default = "three")]
    pub killed: u32,
    #[serde(default)]
    pub timeout: u32,
    /// The worker stopped sending heartbeats.
    #[serde(default = "two")]
    pub lost: u32,
    /// A numerical retry resumes from the last checkpoint with the time step halved (once more per retry).
    #[serde(default = "yes")]
    pub halve_dt_on_numerical: bool,
}

fn yes() -> bool {
    true
}

fn two() -> u32 {
    2
}
fn three() -> u32 {
    3
}

impl Default for RetryPolicy {
    fn default() -> Self {
        RetryPolicy {
            numerical: 0,
            crash: 2,
            killed: 3,
            timeout: 0,
            lost: 2,
            halve_dt_on_numerical: true,
        }
    }
}
