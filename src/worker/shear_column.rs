//! The chute's shear rate as a series column (`shear_rate_per_s`): at every series row, the steepest difference of
//! the layer-averaged velocity along the flow between neighbouring dense layers one largest diameter thick, under
//! the gravity of that moment (which a zig-zag chute flips), by `analysis::shear_profile`. The metric of the same
//! name averages the column from `analysis.average_from_s`.

use crate::analysis::shear_profile::steepest_layer_shear_rate_per_s;
use crate::campaign::JobSpec;
use crate::campaign::metrics::JobMetric;
use crate::engine::{Simulation, Vec3};

/// The series column this sampler adds.
pub const COLUMN: &str = "shear_rate_per_s";

/// Whether `job` asks for a metric read from the column.
pub fn wanted(job: &JobSpec) -> bool {
    job.metrics.iter().any(|m| {
        matches!(
            m,
            JobMetric::ShearRate | JobMetric::CriticalFlipFrequency | JobMetric::FlipFrequencyRatio
        )
    })
}

/// The column's value for the current state, as `,<value>`.
pub fn row(sim: &Simulation) -> String {
    let p = &sim.particles;
    let layer_m = 2.0 * p.radius_m.iter().copied().fold(0.0_f64, f64::max);
    if layer_m <= 0.0 {
        return ",nan".into();
    }
    let gravity: Vec3 = sim.config.gravity.at(sim.time_s);
    format!(
        ",{:e}",
        steepest_layer_shear_rate_per_s(&p.position_m, &p.velocity_m_per_s, gravity, layer_m)
    )
}
