//! Seed 001's height mixing index as a series column (§7.2.2): the particles at or above the bed's median height
//! at one moment (family 1) and the rest (family 2) are followed by identity, and each series row holds the ratio of
//! their mean heights, 3 for a bed that stays segregated and 1 for a mixed one (`analysis::height_mixing_index`).
//!
//! The families are taken at the first series row the job itself writes at or after
//! `analysis.height_families_at_s` and kept in the job directory (`height_families.json`, written atomically before
//! any later checkpoint), so that a resumed job follows the same families and its series stays bit-identical.
//! Heights are measured along the base gravity vector's opposite from the domain's lowest corner (the distributor
//! of a bed standing on the domain's floor), as the index needs (it is not invariant to the origin).

use std::path::{Path, PathBuf};

use crate::analysis;
use crate::campaign::JobSpec;
use crate::campaign::metrics::JobMetric;
use crate::engine::{Simulation, Vec3};
use crate::error::Error;

/// The series column this sampler adds.
pub const COLUMN: &str = "height_mixing_index";

/// The file that holds the families once they are taken: the ids of family 1.
const FILE: &str = "height_families.json";

pub struct HeightFamilies {
    at_s: f64,
    /// Where the families file lives; `None` while running a shared preparation (no families are taken there).
    dir: Option<PathBuf>,
    /// Family 1 by particle id (index = id), once taken.
    family_one: Option<Vec<bool>>,
}

impl HeightFamilies {
    /// The sampler of a job in `dir` that asks for `height_mixing_index`, with its families if they were taken
    /// before (a resumed job). `dir` is `None` for a shared preparation's run, whose rows get no value.
    pub fn new(job: &JobSpec, dir: Option<&Path>) -> Result<Option<Self>, Error> {
        if !job.metrics.contains(&JobMetric::HeightMixingIndex) {
            return Ok(None);
        }
        let family_one = match dir {
            Some(d) => read_families(&d.join(FILE))?,
            None => None,
        };
        Ok(Some(HeightFamilies {
            at_s: job.analysis.height_families_at_s.unwrap_or(0.0),
            dir: dir.map(Path::to_path_buf),
            family_one,
        }))
    }

    /// The column's value for the current state (`nan` before the families are taken), as `,<value>`.
    pub fn row(&mut self, sim: &Simulation) -> Result<String, Error> {
        let heights = heights_m(sim);
        if self.family_one.is_none() {
            let Some(dir) = &self.dir else {
                return Ok(",nan".into());
            };
            if sim.time_s < self.at_s {
                return Ok(",nan".into());
            }
            let upper = analysis::above_median_height(&heights);
            let ids = &sim.particles.id;
            let mut by_id = vec![false; ids.iter().map(|i| i.index() + 1).max().unwrap_or(0)];
            for (id, &up) in ids.iter().zip(&upper) {
                by_id[id.index()] = up;
            }
            write_families(&dir.join(FILE), &by_id)?;
            self.family_one = Some(by_id);
        }
        let family = self.family_one.as_ref().expect("taken above");
        let upper: Vec<bool> = sim
            .particles
            .id
            .iter()
            .map(|id| family.get(id.index()).copied().unwrap_or(false))
            .collect();
        Ok(format!(",{:e}", analysis::height_mixing_index(&heights, &upper)))
    }
}

/// Each particle's centre height along the base gravity's opposite, from the domain's lowest corner, m.
fn heights_m(sim: &Simulation) -> Vec<f64> {
    let g = Vec3::from(sim.config.gravity.vector_m_per_s2);
    let up = if g.norm() > 0.0 { -g.normalize() } else { Vec3::z() };
    let (lo, hi) = (sim.config.domain.lo_m, sim.config.domain.hi_m);
    let floor_m = (0..8)
        .map(|c| {
            let corner = Vec3::new(
                if c & 1 == 0 { lo.x } else { hi.x },
                if c & 2 == 0 { lo.y } else { hi.y },
                if c & 4 == 0 { lo.z } else { hi.z },
            );
            corner.dot(&up)
        })
        .fold(f64::INFINITY, f64::min);
    sim.particles.position_m.iter().map(|x| x.dot(&up) - floor_m).collect()
}

fn read_families(path: &Path) -> Result<Option<Vec<bool>>, Error> {
    match std::fs::read_to_string(path) {
        Ok(text) => serde_json::from_str(&text)
            .map(Some)
            .map_err(|e| Error::External(format!("{}: not a families file: {e}", path.display()))),
        Err(e) if e.kind() == std::io::ErrorKind::NotFound => Ok(None),
        Err(e) => Err(Error::io("read", path, e)),
    }
}

/// Written through `write_atomic`: a kill leaves either no file or the whole one.
fn write_families(path: &Path, family_one: &[bool]) -> Result<(), Error> {
    let text = serde_json::to_string(family_one).expect("flags serialise");
    crate::util::atomic_file::write_atomic(path, text.as_bytes())?;
    Ok(())
}
