//! Campaign progress on the terminal: indicatif bars on a TTY (the campaign: done/failed/running/ETA; one line per
//! running job: simulated time and steps/s), periodic plain lines otherwise, nothing when quiet.

use std::collections::HashMap;
use std::io::IsTerminal;
use std::time::{Duration, Instant};

use indicatif::{MultiProgress, ProgressBar, ProgressDrawTarget, ProgressStyle};

enum Mode {
    Quiet,
    Bars {
        multi: MultiProgress,
        campaign: ProgressBar,
        jobs: HashMap<String, ProgressBar>,
    },
    Lines {
        last: Instant,
        progress: HashMap<String, (u64, u64, f64)>,
    },
}

pub struct Progress {
    mode: Mode,
    total: usize,
    done: usize,
    failed: usize,
    start: Instant,
    done_at_start: usize,
    /// Each running job's completed fraction when this run first heard of it (a resumed job starts part-way) and now.
    fractions: HashMap<String, (f64, f64)>,
}

impl Progress {
    pub fn new(total: usize, done: usize, quiet: bool) -> Progress {
        let mode = if quiet {
            Mode::Quiet
        } else if std::io::stderr().is_terminal() {
            let multi = MultiProgress::with_draw_target(ProgressDrawTarget::stderr());
            let campaign = multi.add(ProgressBar::new(total as u64));
            campaign.set_style(
                ProgressStyle::with_template("{prefix:.bold} [{bar:30}] {pos}/{len} done {msg}")
                    .expect("valid template")
                    .progress_chars("=> "),
            );
            campaign.set_prefix("campaign");
            campaign.set_position(done as u64);
            Mode::Bars {
                multi,
                campaign,
                jobs: HashMap::new(),
            }
        } else {
            Mode::Lines {
                last: Instant::now(),
                progress: HashMap::new(),
            }
        };
        let mut p = Progress {
            mode,
            total,
            done,
            failed: 0,
            start: Instant::now(),
            done_at_start: done,
            fractions: HashMap::new(),
        };
        p.refresh();
        p
    }

    fn running(&self) -> usize {
        match &self.mode {
            Mode::Bars { jobs, .. } => jobs.len(),
            Mode::Lines { progress, .. } => progress.len(),
            Mode::Quiet => 0,
        }
    }

    fn refresh(&mut self) {
        let msg = format!(
            "{} failed, {} running{}",
            self.failed,
            self.running(),
            self.eta()
                .map(|e| format!(", ETA {:.0} s", e.as_secs_f64()))
                .unwrap_or_default()
        );
        if let Mode::Bars { campaign, .. } = &self.mode {
            campaign.set_position(self.done as u64);
            campaign.set_message(msg);
        }
    }

    pub fn started(&mut self, job_id: &str, label: &str) {
        match &mut self.mode {
            Mode::Bars { multi, jobs, .. } => {
                let bar = multi.add(ProgressBar::new(1));
                bar.set_style(
                    ProgressStyle::with_template("  {prefix} [{bar:20}] {percent:>3}% {msg}")
                        .expect("valid template")
                        .progress_chars("=> "),
                );
                bar.set_prefix(format!("{} ({label})", &job_id[..8.min(job_id.len())]));
                jobs.insert(job_id.to_string(), bar);
            }
            Mode::Lines { progress, .. } => {
                eprintln!("started {job_id} ({label})");
                progress.insert(job_id.to_string(), (0, 1, 0.0));
            }
            Mode::Quiet => {}
        }
        self.refresh();
    }

    pub fn progress(&mut self, job_id: &str, step: u64, total_steps: u64, time_s: f64, steps_per_s: f64) {
        let fraction = (step as f64 / total_steps.max(1) as f64).clamp(0.0, 1.0);
        self.fractions
            .entry(job_id.to_string())
            .and_modify(|(_, now)| *now = fraction)
            .or_insert((fraction, fraction));
        match &mut self.mode {
            Mode::Bars { jobs, .. } => {
                if let Some(bar) = jobs.get(job_id) {
                    bar.set_length(total_steps.max(1));
                    bar.set_position(step);
                    bar.set_message(format!("t = {time_s:.3} s, {steps_per_s:.0} steps/s"));
                }
            }
            Mode::Lines { progress, .. } => {
                progress.insert(job_id.to_string(), (step, total_steps.max(1), steps_per_s));
            }
            Mode::Quiet => {}
        }
    }

    pub fn ended(&mut self, job_id: &str) {
        self.fractions.remove(job_id);
        match &mut self.mode {
            Mode::Bars { multi, jobs, .. } => {
                if let Some(bar) = jobs.remove(job_id) {
                    bar.finish_and_clear();
                    multi.remove(&bar);
                }
            }
            Mode::Lines { progress, .. } => {
                progress.remove(job_id);
            }
            Mode::Quiet => {}
        }
        self.refresh();
    }

    pub fn done(&mut self) {
        self.done += 1;
        self.refresh();
    }

    pub fn failed(&mut self) {
        self.failed += 1;
        self.refresh();
    }

    pub fn message(&self, text: &str) {
        match &self.mode {
            Mode::Bars { multi, .. } => {
                let _ = multi.println(text);
            }
            Mode::Lines { .. } => eprintln!("{text}"),
            Mode::Quiet => {}
        }
    }

    /// Called periodically: prints a status line every 10 s when not drawing bars.
    pub fn tick(&mut self) {
        if matches!(self.mode, Mode::Bars { .. }) {
            self.refresh();
        }
        let (done, total, failed) = (self.done, self.total, self.failed);
        let eta = self.eta();
        if let Mode::Lines { last, progress } = &mut self.mode
            && last.elapsed() >= Duration::from_secs(10)
        {
            *last = Instant::now();
            let running: Vec<String> = progress
                .iter()
                .map(|(id, (s, t, r))| {
                    format!(
                        "{} {:.0}% ({r:.0} steps/s)",
                        &id[..8.min(id.len())],
                        100.0 * *s as f64 / *t as f64
                    )
                })
                .collect();
            eprintln!(
                "{done}/{total} done, {failed} failed, {} running{}{}",
                running.len(),
                eta.map(|e| format!(", ETA {:.0} s", e.as_secs_f64()))
                    .unwrap_or_default(),
                if running.is_empty() {
                    String::new()
                } else {
                    format!(": {}", running.join(", "))
                }
            );
        }
    }

    /// Time left at the rate of this run so far, counting the running jobs' completed fractions: the work done is
    /// the jobs finished in this run plus what the running ones did in it, the work left the jobs not yet done less
    /// what the running ones have done.
    fn eta(&self) -> Option<Duration> {
        eta(
            self.start.elapsed(),
            self.done - self.done_at_start,
            self.total.saturating_sub(self.done + self.failed),
            self.fractions.values().copied(),
        )
    }

    pub fn finish(&mut self) {
        if let Mode::Bars { campaign, .. } = &self.mode {
            campaign.finish();
        }
    }
}

/// See [`Progress::eta`]; `running` holds each running job's (fraction at first report, fraction now).
fn eta(elapsed: Duration, finished: usize, left: usize, running: impl Iterator<Item = (f64, f64)>) -> Option<Duration> {
    let (mut worked, mut started) = (finished as f64, 0.0);
    for (first, now) in running {
        worked += now - first;
        started += now;
    }
    let remaining = (left as f64 - started).max(0.0);
    (worked > 1e-9 && elapsed > Duration::ZERO).then(|| elapsed.mul_f64(remaining / worked))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn eta_counts_the_running_jobs_progress() {
        let minute = Duration::from_secs(60);
        // Two of three jobs done in 12 minutes, the last (run beside them) 98 % through: seconds, not minutes.
        let e = eta(12 * minute, 2, 1, [(0.0, 0.98)].into_iter()).expect("an estimate");
        assert!(e < Duration::from_secs(10), "{e:?}");
        // Nothing finished yet, two jobs half done after 5 minutes, four left: 15 more minutes.
        let e = eta(5 * minute, 0, 4, [(0.0, 0.5), (0.0, 0.5)].into_iter()).expect("an estimate");
        assert!((e.as_secs_f64() - 900.0).abs() < 1e-6, "{e:?}");
        // A resumed job that started at 40 % has done only the rest in this run.
        let e = eta(minute, 0, 1, [(0.4, 0.6)].into_iter()).expect("an estimate");
        assert!((e.as_secs_f64() - 120.0).abs() < 1e-6, "{e:?}");
        // No work yet: no estimate.
        assert_eq!(eta(minute, 0, 3, [(0.2, 0.2)].into_iter()), None);
    }
}
