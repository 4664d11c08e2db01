//! Campaigns: a YAML file sweeping parameters of a base scenario, expanded into jobs with stable ids.
//!
//! Everything here happens before any job starts and writes nothing: parse (file, line, column), expand the sweep
//! (key paths), resolve each point against the base scenario and validate the result as a scenario would be, check
//! the job count, duplicates and the metric names.

pub mod derived;
pub mod job;
pub mod metrics;
pub mod named;
pub mod prepare;
pub mod spec;
pub mod sweep;
pub mod validation;

use std::collections::HashMap;
use std::path::{Path, PathBuf};

pub use job::JobSpec;
pub use spec::CampaignSpec;

use crate::scenario::{self, ConfigError, ScenarioSpec};

/// A parsed, expanded campaign.
#[derive(Debug, Clone)]
pub struct Campaign {
    pub spec: CampaignSpec,
    /// The campaign file as written (stored in the database, so `resume` needs nothing else).
    pub yaml: String,
    /// Jobs in sweep order.
    pub jobs: Vec<JobSpec>,
    /// Parameter path → the axis name the sweep gives it (used in the database instead of the path).
    pub axis_names: std::collections::BTreeMap<String, String>,
}

impl Campaign {
    /// A short description of a job for logs and progress: `rotation_rpm=10, fill_top_m=0` (named axes only, when
    /// the sweep names any).
    pub fn label(&self, job: &JobSpec) -> String {
        let named: Vec<String> = job
            .params
            .iter()
            .filter_map(|(k, v)| self.axis_names.get(k).map(|n| format!("{n}={v}")))
            .collect();
        if named.is_empty() {
            job.label()
        } else {
            named.join(", ")
        }
    }

    /// The name a parameter is stored and queried under: the axis name, else a named set's name
    /// (`named.layout` → `layout`), else the path.
    pub fn param_name<'a>(&'a self, path: &'a str) -> &'a str {
        self.axis_names
            .get(path)
            .map_or_else(|| named::set_of(path).unwrap_or(path), String::as_str)
    }
}

fn invalid(path: &Path, key: impl Into<String>, message: impl Into<String>) -> ConfigError {
    ConfigError::invalid(path, key, message)
}

/// Reads and expands a campaign file. Jobs are resolved but not yet validated as scenarios (see [`validate_jobs`]).
pub fn load(path: &Path) -> Result<Campaign, ConfigError> {
    let yaml = scenario::read_input(path)?;
    from_yaml(&yaml, path)
}

/// As [`load`], from text (`path` is used in messages).
pub fn from_yaml(yaml: &str, path: &Path) -> Result<Campaign, ConfigError> {
    let spec: CampaignSpec = scenario::parse_yaml(yaml, path)?;
    let param_keys = first_param_keys(&spec);
    expand(spec, yaml, path, &param_keys).map_err(|e| located(e, yaml, &param_keys))
}

/// Each swept parameter path → the key in the campaign file that sets it first (`sweep.grid[0].param`).
fn first_param_keys(spec: &CampaignSpec) -> HashMap<String, String> {
    let mut param_keys: HashMap<String, String> = HashMap::new();
    for (param, key) in sweep::param_keys(&spec.sweep, "sweep") {
        param_keys.entry(param).or_insert(key);
    }
    param_keys
}

/// Gives an error about the campaign file the line that writes the failing value: for a key of `base` that a sweep
/// parameter sets (the key is that parameter or lies inside it), the parameter's entry in `sweep`; otherwise the
/// key itself, or its nearest parent written in the file.
fn located(e: ConfigError, yaml: &str, param_keys: &HashMap<String, String>) -> ConfigError {
    let ConfigError::Invalid { key, .. } = &e else {
        return e;
    };
    let inside = |k: &str, p: &str| {
        k.strip_prefix(p)
            .is_some_and(|r| r.is_empty() || r.starts_with(['.', '[']))
    };
    let written = key
        .strip_prefix("base.")
        .and_then(|k| {
            param_keys
                .iter()
                .filter(|(p, _)| inside(k, p))
                .max_by(|a, b| a.0.len().cmp(&b.0.len()).then_with(|| b.0.cmp(a.0)))
        })
        .map_or_else(|| key.clone(), |(_, sweep_key)| sweep_key.clone());
    e.at(yaml, &written)
}

/// The checks and the sweep expansion of [`from_yaml`], after the text has parsed.
fn expand(
    spec: CampaignSpec,
    yaml: &str,
    path: &Path,
    param_keys: &HashMap<String, String>,
) -> Result<Campaign, ConfigError> {
    check_finite(yaml).map_err(|(key, m)| invalid(path, key, m))?;
    check_name(&spec.name).map_err(|m| invalid(path, "name", m))?;
    named::check(&spec.named).map_err(|(key, m)| invalid(path, key, m))?;
    let job_metrics = metrics::check(&spec).map_err(|(key, m)| invalid(path, key, m))?;
    if spec.checkpoint.every_steps == 0 {
        return Err(invalid(
            path,
            "checkpoint.every_steps",
            "expected a number of steps > 0",
        ));
    }
    if spec.checkpoint.keep == 0 {
        return Err(invalid(path, "checkpoint.keep", "expected at least 1 checkpoint kept"));
    }
    match &spec.executor {
        spec::ExecutorSpec::Local(local) => {
            if local.threads_per_job == 0 {
                return Err(invalid(path, "executor.local.threads_per_job", "expected at least 1"));
            }
            if local.max_parallel == Some(0) {
                return Err(invalid(path, "executor.local.max_parallel", "expected at least 1"));
            }
            if let Some(t) = local.job_timeout_s
                && !(t.is_finite() && t > 0.0)
            {
                return Err(invalid(
                    path,
                    "executor.local.job_timeout_s",
                    format!("expected a time > 0, got {t}"),
                ));
            }
            if !(local.heartbeat_timeout_s.is_finite() && local.heartbeat_timeout_s > 0.0) {
                return Err(invalid(
                    path,
                    "executor.local.heartbeat_timeout_s",
                    format!("expected a time > 0, got {}", local.heartbeat_timeout_s),
                ));
            }
        }
        spec::ExecutorSpec::Slurm(slurm) => check_slurm(slurm).map_err(|(key, m)| invalid(path, key, m))?,
    }

    if let Some(v) = &spec.validation {
        v.check(&spec.metrics).map_err(|(key, m)| invalid(path, key, m))?;
    }
    check_job_count(&spec, yaml, path)?;
    let points = sweep::expand(&spec.sweep, "sweep", spec.max_jobs).map_err(|e| invalid(path, e.key, e.message))?;
    let names = sweep::axis_names(&spec.sweep);
    for (k, d) in spec.derived.iter().enumerate() {
        if let Some((key, message)) = d.invalid_field() {
            return Err(invalid(path, format!("derived[{k}].{key}"), message));
        }
        for m in d.required_metrics() {
            if !job_metrics.contains(&m) {
                return Err(invalid(
                    path,
                    format!("derived[{k}]"),
                    format!("needs the metric `{}` in `metrics`", m.name()),
                ));
            }
        }
        let known: Vec<String> = sweep::param_keys(&spec.sweep, "sweep")
            .into_iter()
            .map(|(p, _)| {
                names
                    .iter()
                    .find(|(q, _)| *q == p)
                    .map_or(p.clone(), |(_, n)| n.clone())
            })
            .collect();
        if !known.iter().any(|n| n == d.param()) {
            return Err(invalid(
                path,
                format!("derived[{k}]"),
                format!(
                    "`{}` is not a sweep parameter; the sweep has {}",
                    d.param(),
                    known.join(", ")
                ),
            ));
        }
    }
    // The entry of a sweep axis in the file: where its `param` is, with `field` in place of `param`.
    let axis_entry = |param: &str, field: &str| {
        param_keys.get(param).map(|k| {
            k.strip_suffix(".param")
                .map_or(k.clone(), |axis| format!("{axis}.{field}"))
        })
    };
    for (k, (p, n)) in names.iter().enumerate() {
        if names[..k].iter().any(|(p2, n2)| n2 == n && p2 != p) {
            let error = invalid(path, "sweep", format!("axis name `{n}` is given to two parameters"));
            return Err(match axis_entry(p, "name") {
                Some(entry) => error.at(yaml, &entry),
                None => error,
            });
        }
    }
    let swept: Vec<String> = param_keys.keys().cloned().collect();
    let shared = match &spec.prepare {
        Some(p) => prepare::shared_paths(p, &swept, &names).map_err(|(key, m)| invalid(path, key, m))?,
        None => Vec::new(),
    };
    let base = base_document(&spec);
    let mut jobs = Vec::with_capacity(points.len());
    let mut seen: HashMap<String, usize> = HashMap::new();
    // The points as written, to find which value two points that make one job spell differently.
    let written_points = points.clone();
    for (ordinal, point) in points.into_iter().enumerate() {
        let job = resolve(&spec, &job_metrics, &base, point, ordinal, param_keys, &shared, path)?;
        if let Some(&first) = seen.get(&job.job_id) {
            let error = invalid(
                path,
                "sweep",
                format!(
                    "sweep points {first} and {ordinal} give the same job ({}); remove the duplicate",
                    describe(&job.params)
                ),
            );
            let spelt_differently = written_points[first].iter().find_map(|(param, value)| {
                let other = written_points[ordinal].iter().find(|(p, _)| p == param)?;
                (other.1 != *value).then_some(param.as_str())
            });
            return Err(match spelt_differently.and_then(|p| axis_entry(p, "values")) {
                Some(entry) => error.at(yaml, &entry),
                None => error,
            });
        }
        seen.insert(job.job_id.clone(), ordinal);
        jobs.push(job);
    }
    if let Some(p) = &spec.prepare {
        attach_preparations(&mut jobs, p.until_s, &shared).map_err(|(key, m)| invalid(path, key, m))?;
    }
    Ok(Campaign {
        spec,
        yaml: yaml.to_string(),
        jobs,
        axis_names: names.into_iter().collect(),
    })
}

/// The Slurm executor's settings that can be judged without asking Slurm (the partition, time limit, account and
/// QOS are asked of `sbatch --test-only` before anything is submitted). Each text goes to `sbatch` as one argument.
fn check_slurm(slurm: &spec::SlurmExecutor) -> Result<(), (String, String)> {
    let key = |k: &str| format!("executor.slurm.{k}");
    if slurm.cpus_per_task == 0 {
        return Err((key("cpus_per_task"), "expected at least 1".into()));
    }
    if slurm.array_throttle == Some(0) {
        return Err((key("array_throttle"), "expected at least 1 task at once".into()));
    }
    if !(slurm.poll_interval_s.is_finite() && slurm.poll_interval_s >= 0.1 && slurm.poll_interval_s <= 3600.0) {
        return Err((
            key("poll_interval_s"),
            format!("expected 0.1 to 3600 s, got {}", slurm.poll_interval_s),
        ));
    }
    if slurm.signal_before_end_s == 0 || slurm.signal_before_end_s > 65_535 {
        return Err((
            key("signal_before_end_s"),
            format!(
                "expected 1 to 65535 s (Slurm's limit), got {}",
                slurm.signal_before_end_s
            ),
        ));
    }
    let texts = [
        ("partition", slurm.partition.as_deref()),
        ("time_limit", slurm.time_limit.as_deref()),
        ("memory", slurm.memory.as_deref()),
        ("account", slurm.account.as_deref()),
        ("qos", slurm.qos.as_deref()),
    ];
    for (name, text) in texts {
        if let Some(t) = text
            && (t.trim().is_empty() || t.chars().any(char::is_whitespace))
        {
            return Err((key(name), format!("expected a word without spaces, got {t:?}")));
        }
    }
    for (k, option) in slurm.sbatch_options.iter().enumerate() {
        if !option.starts_with('-') || option.contains('\n') {
            return Err((
                format!("executor.slurm.sbatch_options[{k}]"),
                format!("expected one sbatch option starting with `-` (e.g. --constraint=skylake), got {option:?}"),
            ));
        }
        let name = option.split('=').next().unwrap_or(option);
        const OWN: [&str; 6] = ["--array", "-a", "--output", "-o", "--parsable", "--wrap"];
        if OWN.contains(&name) {
            return Err((
                format!("executor.slurm.sbatch_options[{k}]"),
                format!("{name} is set by granflow itself"),
            ));
        }
    }
    Ok(())
}

/// Refuses a sweep of more than `max_jobs` jobs, counted without expanding it, at the line of its largest axis
/// (where a typo of a few zeros is), and a `max_jobs` above [`spec::MAX_JOBS_CEILING`] at its own line.
fn check_job_count(spec: &CampaignSpec, yaml: &str, path: &Path) -> Result<(), ConfigError> {
    if spec.max_jobs > spec::MAX_JOBS_CEILING {
        return Err(invalid(
            path,
            "max_jobs",
            format!(
                "expected at most {} jobs per campaign, got {}; split the study into several campaigns",
                spec::MAX_JOBS_CEILING,
                spec.max_jobs
            ),
        )
        .located(yaml));
    }
    let size = sweep::count(&spec.sweep, "sweep");
    if size.points <= spec.max_jobs as u128 {
        return Ok(());
    }
    let points = if size.points == u128::MAX {
        format!("at least {}", u128::MAX)
    } else {
        size.points.to_string()
    };
    let (key, why) = match &size.largest_axis {
        Some((key, n)) => (key.clone(), format!(" (its largest axis has {n} points)")),
        None => ("sweep".to_string(), String::new()),
    };
    Err(invalid(
        path,
        key,
        format!(
            "the sweep expands into {points} jobs{why}, more than max_jobs = {}; if this is intended, raise \
             `max_jobs` at the top level of the campaign file (at most {})",
            spec.max_jobs,
            spec::MAX_JOBS_CEILING
        ),
    )
    .located(yaml))
}

/// Rejects non-finite numbers (`.nan`, `.inf`) in `base` and `sweep`: jobs are resolved through JSON, which has
/// no such values and would silently turn them into `null` (read back as a missing optional value, or as a type
/// error naming the wrong thing). Errors are (key path, message).
fn check_finite(yaml: &str) -> Result<(), (String, String)> {
    fn walk(v: &serde_norway::Value, key: &str) -> Result<(), (String, String)> {
        use serde_norway::Value;
        match v {
            Value::Number(n) => match n.as_f64() {
                Some(x) if !x.is_finite() => Err((key.to_string(), format!("expected a finite number, got {x}"))),
                _ => Ok(()),
            },
            Value::Sequence(items) => items
                .iter()
                .enumerate()
                .try_for_each(|(i, item)| walk(item, &format!("{key}[{i}]"))),
            Value::Mapping(map) => map.iter().try_for_each(|(k, item)| {
                let name = match k {
                    Value::String(s) => s.clone(),
                    other => serde_norway::to_string(other).unwrap_or_default().trim().to_string(),
                };
                walk(item, &format!("{key}.{name}"))
            }),
            Value::Tagged(tagged) => walk(&tagged.value, key),
            Value::Null | Value::Bool(_) | Value::String(_) => Ok(()),
        }
    }
    // The text has parsed as a campaign already, so it parses as a YAML value.
    let Ok(doc) = serde_norway::from_str::<serde_norway::Value>(yaml) else {
        return Ok(());
    };
    for section in ["base", "sweep"] {
        if let Some(v) = doc.get(section) {
            walk(v, section)?;
        }
    }
    Ok(())
}

fn check_name(name: &str) -> Result<(), String> {
    if name.is_empty() || !name.chars().all(|c| c.is_ascii_alphanumeric() || "-_.".contains(c)) || name.starts_with('.')
    {
        return Err(format!(
            "expected a name of letters, digits, `-`, `_` and `.` (it names the output directory), got `{name}`"
        ));
    }
    Ok(())
}

/// Gives every job its preparation ([`prepare::preparation`]), with the shared parameters at the values of the
/// sweep's first job and of its last.
fn attach_preparations(jobs: &mut [JobSpec], until_s: f64, shared: &[String]) -> Result<(), (String, String)> {
    let values_of = |job: &JobSpec| -> Vec<serde_json::Value> {
        let doc = serde_json::to_value(&job.scenario).expect("a scenario serialises");
        shared
            .iter()
            .map(|p| sweep::get_path(&doc, p).cloned().unwrap_or(serde_json::Value::Null))
            .collect()
    };
    let (Some(first_job), Some(last_job)) = (jobs.first(), jobs.last()) else {
        return Ok(());
    };
    let (first, last) = (values_of(first_job), values_of(last_job));
    for job in jobs.iter_mut() {
        job.prepared = Some(prepare::preparation(&job.scenario, until_s, shared, &first, &last)?);
    }
    Ok(())
}

/// The base scenario as a JSON document with every field present (defaults included), the campaign's name and
/// checkpoint policy filled in.
fn base_document(spec: &CampaignSpec) -> serde_json::Value {
    let mut base = spec.base.clone();
    base.name = spec.name.clone();
    base.output.checkpoint_every_steps = spec.checkpoint.every_steps;
    base.output.keep_checkpoints = spec.checkpoint.keep;
    serde_json::to_value(&base).expect("a scenario serialises")
}

/// Applies one sweep point to the base and derives the job's seed and id; every job reduces `metrics` (the spec's,
/// checked by [`metrics::check`]). `param_keys` gives the key in the campaign file where each parameter path is set
/// (for messages). The seed derives from the campaign seed and the point's parameters other than `shared` (those a
/// preparation is shared across: the jobs of one preparation share its random numbers).
#[allow(clippy::too_many_arguments)]
fn resolve(
    spec: &CampaignSpec,
    metrics: &[metrics::JobMetric],
    base: &serde_json::Value,
    mut point: sweep::Point,
    ordinal: usize,
    param_keys: &HashMap<String, String>,
    shared: &[String],
    path: &Path,
) -> Result<JobSpec, ConfigError> {
    let mut doc = base.clone();
    // What the scenario receives: the point's parameters, a named set's member in place of its name.
    let mut assignments =
        named::assignments(&spec.named, &point, param_keys).map_err(|(key, m)| invalid(path, key, m))?;
    let mut seen_paths: Vec<&str> = Vec::new();
    // Parameters whose last key the base left out (a field at its default): path, key in the campaign file, and
    // the message should the scenario not know the key.
    let mut inserted: Vec<(String, &str, String)> = Vec::new();
    for named::Assignment {
        path: param,
        value,
        key,
        via,
    } in &assignments
    {
        let key = key.as_str();
        if seen_paths.contains(&param.as_str()) {
            let by = via
                .as_ref()
                .map_or(String::new(), |v| format!(" (once by the member `{v}` names)"));
            return Err(invalid(
                path,
                key,
                format!("parameter `{param}` is set twice in one point{by}"),
            ));
        }
        seen_paths.push(param);
        if param == "name" {
            return Err(invalid(
                path,
                key,
                "the scenario name is the campaign's (`name` at the top level); it cannot be swept",
            ));
        }
        // An optional section the base leaves out (`cohesion`, `gas`) may be set whole by the sweep.
        if let (Some(section), serde_json::Value::Object(map)) = (optional_section(param), &mut doc) {
            map.entry(section).or_insert(serde_json::Value::Null);
        }
        let added = sweep::set_path_with_sections(&mut doc, param, value.clone(), optional_sections(), true)
            .map_err(|m| invalid(path, key, format!("parameter `{param}`: {m}")))?;
        if let Some(unknown) = added {
            inserted.push((
                sweep::canonical_path(param).unwrap_or_else(|_| param.clone()),
                key,
                unknown,
            ));
        }
    }
    let mut scenario: ScenarioSpec = serde_path_to_error::deserialize(&doc).map_err(|e| {
        let key = e.path().to_string();
        // A key the sweep added that the scenario does not know: reported at the sweep's key.
        if let Some((param, sweep_key, unknown)) = inserted.iter().find(|(p, _, _)| *p == key) {
            // Without a suggestion from the keys written there, serde's list of every field it knows.
            let detail = if unknown.contains("did you mean") {
                unknown.clone()
            } else {
                format!("{unknown}; {}", e.inner())
            };
            return invalid(path, *sweep_key, format!("parameter `{param}`: {detail}"));
        }
        invalid(
            path,
            format!("base.{key}"),
            format!("{} (at sweep point {ordinal}: {})", e.inner(), describe(&point)),
        )
    })?;
    // Each value as the scenario reads it (`20` for a number of rpm is `20.0`), so that two spellings of one value
    // make one job (same seed, same id: reported as a duplicate) rather than two.
    let resolved = serde_json::to_value(&scenario).expect("a scenario serialises");
    for (param, value) in &mut point {
        if let Some(v) = sweep::get_path(&resolved, param) {
            *value = v.clone();
        }
    }
    for a in &mut assignments {
        if let Some(v) = sweep::get_path(&resolved, &a.path) {
            a.value = v.clone();
        }
    }
    if !assignments.iter().any(|a| a.path == "seed") {
        // From the values the scenario receives, so that a named member seeds as its values written out would.
        let seeded: Vec<(&String, &serde_json::Value)> = assignments
            .iter()
            .filter(|a| !shared.contains(&a.path) && a.via.as_ref().is_none_or(|v| !shared.contains(v)))
            .map(|a| (&a.path, &a.value))
            .collect();
        let params = serde_json::to_string(&seeded).expect("params serialise");
        let mut bytes = spec.seed.to_le_bytes().to_vec();
        bytes.extend_from_slice(params.as_bytes());
        scenario.seed = xxhash_rust::xxh3::xxh3_64(&bytes);
    }
    let mut job = JobSpec {
        format: job::JOB_FORMAT,
        job_id: String::new(),
        campaign: spec.name.clone(),
        engine_version: env!("CARGO_PKG_VERSION").to_string(),
        params: point,
        scenario,
        metrics: metrics.to_vec(),
        analysis: spec.analysis.clone(),
        prepared: None,
    };
    job.job_id = job.compute_id();
    Ok(job)
}

/// The top-level key of `param` if it names an optional section of the scenario (one the schema does not
/// require), which a re-serialised base omits when it is absent.
fn optional_section(param: &str) -> Option<String> {
    let first = param.split(['.', '[']).next()?;
    optional_sections()
        .iter()
        .any(|k| k == first)
        .then(|| first.to_string())
}

/// The scenario's top-level keys that its schema does not require.
fn optional_sections() -> &'static [String] {
    static OPTIONAL: std::sync::OnceLock<Vec<String>> = std::sync::OnceLock::new();
    OPTIONAL.get_or_init(|| {
        let schema = schemars::schema_for!(ScenarioSpec);
        let required: Vec<&str> = schema
            .get("required")
            .and_then(|r| r.as_array())
            .map(|r| r.iter().filter_map(|k| k.as_str()).collect())
            .unwrap_or_default();
        schema
            .get("properties")
            .and_then(|p| p.as_object())
            .map(|p| p.keys().filter(|k| !required.contains(&k.as_str())).cloned().collect())
            .unwrap_or_default()
    })
}

fn describe(point: &sweep::Point) -> String {
    point
        .iter()
        .map(|(k, v)| format!("{k} = {v}"))
        .collect::<Vec<_>>()
        .join(", ")
}

/// Validates every given job of `campaign` as a scenario (geometry, materials, particles fitting), naming the sweep
/// point of the first that fails and the line of `path`, the campaign's file, that sets the value. Builds the
/// particles, so it costs what building the jobs costs. When the base scenario alone fails the same way, the sweep
/// has nothing to do with the error and no sweep point is named.
pub fn validate_jobs<'a>(
    campaign: &Campaign,
    jobs: impl IntoIterator<Item = &'a JobSpec>,
    path: &Path,
) -> Result<(), ConfigError> {
    let param_keys = first_param_keys(&campaign.spec);
    let Some((job, key, message)) = jobs
        .into_iter()
        .find_map(|job| {
            job_error(job, path).err().map(|e| match e {
                ConfigError::Invalid { key, message, .. } => Ok((job, key, message)),
                other => Err(other),
            })
        })
        .transpose()?
    else {
        return Ok(());
    };
    let base = base_document(&campaign.spec);
    let base_job = resolve(
        &campaign.spec,
        &job.metrics,
        &base,
        Vec::new(),
        0,
        &param_keys,
        &[],
        path,
    )?;
    let base_fails_alike = matches!(
        job_error(&base_job, path),
        Err(ConfigError::Invalid { key: k, message: m, .. }) if k == key && m == message
    );
    let message = if base_fails_alike || job.params.is_empty() {
        message
    } else {
        format!("{message} (at sweep point {})", describe(&job.params))
    };
    // The values a named member gave this job are written at the member.
    let mut param_keys = param_keys;
    for (param, value) in &job.params {
        if let (Some(set), Some(name)) = (named::set_of(param), value.as_str())
            && let Some(member) = campaign.spec.named.get(set).and_then(|m| m.get(name))
        {
            for p in member.keys().filter_map(|p| sweep::canonical_path(p).ok()) {
                param_keys.insert(p, format!("named.{set}.{name}"));
            }
        }
    }
    Err(located(invalid(path, key, message), &campaign.yaml, &param_keys))
}

/// The first problem of one job as a scenario (keys of the scenario prefixed with `base.`) or with its metrics.
fn job_error(job: &JobSpec, path: &Path) -> Result<(), ConfigError> {
    if let Err(e) = scenario::build(job.scenario.clone(), path) {
        return Err(match e {
            ConfigError::Invalid { key, message, .. } => invalid(path, format!("base.{key}"), message),
            other => other,
        });
    }
    metrics::check_job(job).map_err(|(key, m)| invalid(path, key, m))
}

/// The JSON Schema of the campaign file, generated from the types that parse it (`schemas/campaign.schema.json` is
/// this, checked by a test).
pub fn json_schema() -> serde_json::Value {
    let mut schema = serde_json::to_value(schemars::schema_for!(CampaignSpec)).expect("a schema serialises");
    if let Some(map) = schema.as_object_mut() {
        map.insert("title".into(), "granflow campaign".into());
        map.insert(
            "description".into(),
            "A granflow campaign file: a base scenario, a sweep over its parameters, metrics, executor and retry \
             settings. Generated from the code (`granflow schema`)."
                .into(),
        );
    }
    schema
}

/// The output directory of a campaign: `--out` if given, else `results/<name>`.
pub fn output_dir(spec: &CampaignSpec, out: Option<&Path>) -> PathBuf {
    out.map_or_else(|| PathBuf::from("results").join(&spec.name), Path::to_path_buf)
}
