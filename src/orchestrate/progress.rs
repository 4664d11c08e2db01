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
}

impl Progress {
    pub fn new(total: usize, done: usize, quiet: bool) -> Progress {
        let mode = if quiet {
            Mode::Quiet
        } else if std::io::stderr().is_terminal() {
            let multi = MultiProgress::with_draw_target(ProgressDrawTarget::stderr());
            let campaign = multi.add(ProgressBar::new(total as u64));
            campaign.set_style(
                ProgressStyle::with_template("{prefix:.bold} [{bar:30}] {pos}/{len} done {msg} ETA {eta}")
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
        let msg = format!("{} failed, {} running", self.failed, self.running());
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

    fn eta(&self) -> Option<Duration> {
        let finished = self.done - self.done_at_start;
        let left = self.total.saturating_sub(self.done + self.failed);
        (finished > 0).then(|| self.start.elapsed().mul_f64(left as f64 / finished as f64))
    }

    pub fn finish(&mut self) {
        if let Mode::Bars { campaign, .. } = &self.mode {
            campaign.finish();
        }
    }
}
