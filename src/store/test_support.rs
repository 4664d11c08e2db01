//! Fixtures shared by the store's tests: a store in a temporary directory and a small 3 × 2 sweep.

use tempfile::TempDir;

use super::{JobResult, Metric, NewJob, ParamValue, Store};

/// A fresh store at `<tempdir>/campaign.sqlite`; keep the directory alive as long as the store.
pub(crate) fn new_store() -> (TempDir, Store) {
    let dir = tempfile::tempdir().expect("temporary directory");
    let store = Store::open(dir.path().join("campaign.sqlite")).expect("open a new store");
    (dir, store)
}

/// A fresh store holding one campaign, and the campaign's id.
pub(crate) fn new_campaign() -> (TempDir, Store, i64) {
    let (dir, mut store) = new_store();
    let id = store
        .upsert_campaign("bed", "sweep: {}", "hash", "0.1.0")
        .expect("record the campaign");
    (dir, store, id)
}

/// Six jobs `j0`..`j5`: u_m_per_s ∈ {0.1, 0.2, 0.3} (x) × fill_level ∈ {0.3, 0.5} (y), drag = di_felice; listed
/// y-major with x descending for the second row, so that pivots have to sort.
pub(crate) fn sample_jobs() -> Vec<NewJob> {
    let grid = [(0.1, 0.3), (0.2, 0.3), (0.3, 0.3), (0.3, 0.5), (0.2, 0.5), (0.1, 0.5)];
    grid.iter()
        .enumerate()
        .map(|(ordinal, &(u, fill))| NewJob {
            job_id: format!("j{ordinal}"),
            ordinal: ordinal as i64,
            params_json: format!("{{\"u_m_per_s\":{u},\"fill_level\":{fill},\"drag\":\"di_felice\"}}"),
            params: vec![
                ("u_m_per_s".to_string(), ParamValue::Real(u)),
                ("fill_level".to_string(), ParamValue::Real(fill)),
                ("drag".to_string(), ParamValue::Text("di_felice".to_string())),
            ],
        })
        .collect()
}

/// A result with the given (name, value, unit) metrics and two timings.
pub(crate) fn job_result(metrics: &[(&str, f64, &str)]) -> JobResult {
    JobResult {
        metrics: metrics
            .iter()
            .map(|&(name, value, unit)| Metric {
                name: name.to_string(),
                value,
                unit: unit.to_string(),
            })
            .collect(),
        timings: vec![("forces".to_string(), 12.0), ("gas".to_string(), 6.5)],
        sim_time_s: 1.0,
        build: "0.1.0+test".into(),
        wall_time_s: 20.0,
        steps: 1000,
        finished_at: 1000.0,
    }
}

/// Runs `job_id` through start and result with the given metrics.
pub(crate) fn finish(store: &mut Store, job_id: &str, metrics: &[(&str, f64, &str)]) {
    store
        .mark_running(job_id, 1, "node1", 900.0, "0.1.0+test")
        .expect("mark running");
    store.finish_job(job_id, &job_result(metrics)).expect("finish job");
}
