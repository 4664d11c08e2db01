//! What a campaign's jobs cost in wall time, read from the store's attempts (each attempt's start and end): a job
//! resumed across several runs of the dispatcher has one attempt per run, and its own result records only the last
//! one's time. The campaign's wall time is the union of all attempts (the time at least one job ran: the pauses
//! between runs left out); its worker time the sum.

use std::collections::HashMap;

use crate::store::AttemptSpan;

/// The wall time of a campaign's ended attempts.
#[derive(Debug, Clone, PartialEq)]
pub(crate) struct WallTime {
    /// Per job: the sum of its ended attempts' durations, s.
    pub per_job_s: HashMap<String, f64>,
    /// The union of the attempts' spans: the time at least one job ran, s.
    pub busy_s: f64,
    /// The sum over attempts: worker time, s.
    pub worker_s: f64,
}

impl WallTime {
    /// From the attempts that ended (a running one counts when it ends).
    pub fn of(attempts: &[AttemptSpan]) -> WallTime {
        let spans: Vec<(&str, f64, f64)> = attempts
            .iter()
            .filter_map(|a| {
                let end = a.ended_s?;
                (end >= a.started_s).then_some((a.job_id.as_str(), a.started_s, end))
            })
            .collect();
        let mut per_job_s = HashMap::new();
        for &(job, start, end) in &spans {
            *per_job_s.entry(job.to_string()).or_insert(0.0) += end - start;
        }
        WallTime {
            per_job_s,
            busy_s: union_length_s(spans.iter().map(|&(_, s, e)| (s, e)).collect()),
            worker_s: spans.iter().map(|&(_, s, e)| e - s).sum(),
        }
    }

    /// The report's sentence on it.
    pub fn sentence(&self) -> String {
        if self.worker_s <= 0.0 {
            return "Wall time: no attempt has ended yet.\n\n".into();
        }
        format!(
            "Wall time: {} while jobs ran (the union of all attempts, the pauses between runs left out), {} of worker \
             time in all (the sum over attempts): {:.2} jobs at a time on average.\n\n",
            hours(self.busy_s),
            hours(self.worker_s),
            self.worker_s / self.busy_s
        )
    }
}

/// `s` seconds as minutes below two hours, hours above.
fn hours(s: f64) -> String {
    if s < 7200.0 {
        format!("{:.1} min", s / 60.0)
    } else {
        format!("{:.2} h", s / 3600.0)
    }
}

/// The total length of the union of the intervals `spans` (start, end).
fn union_length_s(mut spans: Vec<(f64, f64)>) -> f64 {
    spans.sort_by(|a, b| a.0.total_cmp(&b.0));
    let mut total = 0.0;
    let mut current: Option<(f64, f64)> = None;
    for (start, end) in spans {
        current = match current {
            Some((s, e)) if start <= e => Some((s, e.max(end))),
            Some((s, e)) => {
                total += e - s;
                Some((start, end))
            }
            None => Some((start, end)),
        };
    }
    total + current.map_or(0.0, |(s, e)| e - s)
}

#[cfg(test)]
mod tests {
    use super::*;

    fn attempt(job: &str, started_s: f64, ended_s: Option<f64>) -> AttemptSpan {
        AttemptSpan {
            job_id: job.into(),
            started_s,
            ended_s,
        }
    }

    /// Two jobs side by side, one of them resumed after a pause; a running attempt does not count yet.
    #[test]
    fn resumed_jobs_add_their_attempts_and_pauses_do_not_count() {
        let wall = WallTime::of(&[
            attempt("a", 0.0, Some(100.0)),
            attempt("b", 0.0, Some(60.0)),
            attempt("b", 200.0, Some(250.0)),
            attempt("c", 240.0, Some(300.0)),
            attempt("d", 300.0, None),
        ]);
        assert_eq!(wall.per_job_s["a"], 100.0);
        assert_eq!(wall.per_job_s["b"], 110.0);
        assert_eq!(wall.per_job_s["c"], 60.0);
        assert!(!wall.per_job_s.contains_key("d"));
        // [0, 100] and [200, 300]: the pause from 100 to 200 is left out.
        assert_eq!(wall.busy_s, 200.0);
        assert_eq!(wall.worker_s, 270.0);
        assert!(
            wall.sentence().contains("3.3 min while jobs ran"),
            "{}",
            wall.sentence()
        );
        assert!(wall.sentence().contains("1.35 jobs at a time"), "{}", wall.sentence());
    }

    #[test]
    fn nested_and_touching_spans_merge() {
        assert_eq!(
            union_length_s(vec![(5.0, 6.0), (0.0, 10.0), (10.0, 12.0), (20.0, 21.0)]),
            13.0
        );
        assert_eq!(union_length_s(vec![]), 0.0);
    }
}
