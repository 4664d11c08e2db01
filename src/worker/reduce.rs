//! The per-job reducers: final-state metrics from the simulation, time-series metrics from `series.csv`. Which
//! metrics exist, their names, units and needs are `crate::campaign::metrics`' table; [`metrics`] computes each
//! one in a single `match` over [`JobMetric`].
//!
//! What does not live here: checking that a job can have a metric (done before it runs, `campaign::metrics`).

use std::path::Path;

use serde::{Deserialize, Serialize};

use crate::analysis;
use crate::campaign::JobSpec;
use crate::campaign::metrics::JobMetric;
use crate::campaign::spec::CyclePressure;
use crate::engine::models::cohesion_law::CohesionModel;
use crate::engine::particles::SpeciesId;
use crate::engine::{Simulation, Vec3};
use crate::error::Error;
use crate::scenario::BuiltScenario;

/// One reduced number with its unit.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct Metric {
    pub name: String,
    /// NaN when the reducer has nothing to say (e.g. no decay to fit); written as `null` in JSON.
    #[serde(serialize_with = "nan_as_null", deserialize_with = "null_as_nan")]
    pub value: f64,
    pub unit: String,
}

fn nan_as_null<S: serde::Serializer>(v: &f64, s: S) -> Result<S::Ok, S::Error> {
    if v.is_finite() {
        s.serialize_f64(*v)
    } else {
        s.serialize_none()
    }
}

fn null_as_nan<'de, D: serde::Deserializer<'de>>(d: D) -> Result<f64, D::Error> {
    Ok(Option::<f64>::deserialize(d)?.unwrap_or(f64::NAN))
}

/// Series columns the mixing sampler adds.
pub const MIXING_COLUMNS: &str = ",intensity_of_segregation,lacey_index";

/// Samples the mixing state of a binary mixture into the series.
pub struct MixingSampler {
    species_a: SpeciesId,
    neighbours: usize,
    concentration: analysis::mixing::Concentration,
    every_steps: Option<u64>,
}

impl MixingSampler {
    pub fn new(job: &JobSpec, built: &BuiltScenario) -> Option<Self> {
        let name = job.analysis.mixing_species.as_deref()?;
        Some(MixingSampler {
            species_a: built.config.species.find(name)?,
            neighbours: job.analysis.mixing_neighbours,
            concentration: job.analysis.mixing_concentration,
            every_steps: job.analysis.mixing_every_steps,
        })
    }

    fn state(&self, sim: &Simulation) -> analysis::mixing::MixingState {
        let p = &sim.particles;
        let volumes: Vec<f64> = p
            .radius_m
            .iter()
            .map(|r| 4.0 / 3.0 * std::f64::consts::PI * r * r * r)
            .collect();
        let is_a: Vec<bool> = p.species.iter().map(|&s| s == self.species_a).collect();
        analysis::mixing::mixing_state(&p.position_m, &volumes, &is_a, self.neighbours, self.concentration)
    }

    /// The extra series columns for the current state (`nan` between mixing samples).
    pub fn row(&mut self, sim: &Simulation) -> String {
        if self.every_steps.is_some_and(|k| !sim.step.is_multiple_of(k)) {
            return ",nan,nan".to_string();
        }
        let m = self.state(sim);
        format!(",{:e},{:e}", m.intensity_of_segregation, m.lacey_index)
    }
}

/// The time series of a job as columns.
#[derive(Debug, Clone)]
pub struct Series {
    pub names: Vec<String>,
    pub columns: Vec<Vec<f64>>,
}

impl Series {
    pub fn read(path: &Path) -> Result<Series, Error> {
        let text = std::fs::read_to_string(path).map_err(|e| Error::io("read", path, e))?;
        let mut lines = text.lines();
        let names: Vec<String> = lines
            .next()
            .ok_or_else(|| Error::External(format!("{}: empty series", path.display())))?
            .split(',')
            .map(str::to_string)
            .collect();
        let mut columns = vec![Vec::new(); names.len()];
        for (k, line) in lines.enumerate() {
            let fields: Vec<&str> = line.split(',').collect();
            if fields.len() != names.len() {
                return Err(Error::External(format!(
                    "{}: row {} has {} fields, expected {}",
                    path.display(),
                    k + 2,
                    fields.len(),
                    names.len()
                )));
            }
            for (c, f) in fields.iter().enumerate() {
                let v = f.parse::<f64>().map_err(|_| {
                    Error::External(format!("{}: row {}: `{f}` is not a number", path.display(), k + 2))
                })?;
                columns[c].push(v);
            }
        }
        Ok(Series { names, columns })
    }

    pub fn column(&self, name: &str) -> Option<&[f64]> {
        self.names
            .iter()
            .position(|n| n == name)
            .map(|k| self.columns[k].as_slice())
    }

    /// The unit of a series column (from its name's suffix).
    pub fn unit_of(name: &str) -> &'static str {
        if name == "step" || name.ends_with("contacts") || name == "core_particles" {
            "count"
        } else {
            crate::units::parameter_unit(name).unwrap_or("1")
        }
    }
}

/// Every metric the job asks for, in its order.
pub fn metrics(job: &JobSpec, built: &BuiltScenario, sim: &Simulation, series: &Series) -> Vec<Metric> {
    let sampler = MixingSampler::new(job, built);
    let mixing_final = sampler.as_ref().map(|s| s.state(sim));
    // (t, IS, Lacey) at the sampled rows.
    let mixing_series = || -> Option<(Vec<f64>, Vec<f64>, Vec<f64>)> {
        let t = series.column("time_s")?;
        let is = series.column("intensity_of_segregation")?;
        let lacey = series.column("lacey_index")?;
        let from_s = job.analysis.mixing_fit_from_s.unwrap_or(f64::NEG_INFINITY);
        let rows: Vec<usize> = (0..t.len()).filter(|&k| is[k].is_finite() && t[k] >= from_s).collect();
        Some((
            rows.iter().map(|&k| t[k]).collect(),
            rows.iter().map(|&k| is[k]).collect(),
            rows.iter().map(|&k| lacey[k]).collect(),
        ))
    };
    let average_from_s = job.analysis.average_from_s.unwrap_or(0.5 * built.spec.time.end_time_s);
    // The chute's shear rate (the series column's mean from average_from_s) and seed 000's f_crit (eq. 3.5) with
    // the density ratio of the two species, light over heavy.
    let shear_rate = || window(series, "shear_rate_per_s", average_from_s).map_or(f64::NAN, |w| mean(&w));
    let critical_frequency = || {
        // The species the particles are of (a wall's species places none).
        let (light, heavy) = sim
            .particles
            .species
            .iter()
            .map(|s| built.config.species.species[s.index()].density_kg_per_m3)
            .fold((f64::INFINITY, 0.0_f64), |(lo, hi), d| (lo.min(d), hi.max(d)));
        analysis::shear_profile::critical_flip_frequency_hz(
            job.analysis.segregation_beta.unwrap_or(0.1),
            shear_rate(),
            light / heavy,
        )
    };
    // The cycle is read once for all the cycle metrics that ask for it.
    let cycle_once = std::cell::OnceCell::new();
    let cycle = || cycle_once.get_or_init(|| cycle(job, built, sim, series)).as_ref();
    let core_once = std::cell::OnceCell::new();
    let core = || *core_once.get_or_init(|| wall_heat(job, sim, series, "core_temperature_k"));
    // The drying curve (t, X) and the coldest row of the mean particle temperature (t, T).
    let drying_curve = || {
        Some((
            series.column("time_s")?.to_vec(),
            series.column("moisture_content")?.to_vec(),
        ))
    };
    let mean_temperatures = || series.column("mean_temperature_k").filter(|t| !t.is_empty());
    // The largest |value| of a ledger's closure column (NaN rows, e.g. a ledger not yet started, make it NaN).
    let largest_magnitude = |name: &str| {
        series
            .column(name)
            .and_then(|c| {
                c.iter()
                    .map(|v| v.abs())
                    .reduce(|a, b| if a.is_nan() || b.is_nan() { f64::NAN } else { a.max(b) })
            })
            .unwrap_or(f64::NAN)
    };
    let coldest = || {
        let (t, temperature) = (series.column("time_s")?, series.column("mean_temperature_k")?);
        (0..t.len())
            .filter(|&k| temperature[k].is_finite())
            .min_by(|&a, &b| temperature[a].total_cmp(&temperature[b]))
            .map(|k| (t[k], temperature[k]))
    };
    // CV_m against 1/√t, t the coating time (since the spray started), from analysis.coating_fit_from_s on
    // (seed 000 §6.3.2).
    let coating_fit = || {
        let Some(CohesionModel::LiquidBridge(bridge)) = &built.spec.cohesion else {
            return None;
        };
        let spray_start_s = bridge.spray.as_ref()?.start_s;
        let from_s = job.analysis.coating_fit_from_s.unwrap_or(1.0);
        let (t, cv) = (series.column("time_s")?, series.column("coating_variability")?);
        let (x, y): (Vec<f64>, Vec<f64>) = t
            .iter()
            .map(|t| t - spray_start_s)
            .zip(cv)
            .filter(|(t, _)| *t >= from_s && *t > 0.0)
            .map(|(t, cv)| (1.0 / t.sqrt(), *cv))
            .unzip();
        analysis::fit::fit_line(&x, &y)
    };
    let bed_once = std::cell::OnceCell::new();
    let bed = || *bed_once.get_or_init(|| wall_heat(job, sim, series, "mean_temperature_k"));
    job.metrics
        .iter()
        .map(|&metric| {
            let value = match metric {
                JobMetric::KineticEnergy => sim.particles.kinetic_energy_j(),
                JobMetric::TranslationalKineticEnergy => sim.particles.translational_kinetic_energy_j(),
                JobMetric::BedTop => sim.bed_height_m().0,
                JobMetric::MeanHeight => sim.bed_height_m().1,
                JobMetric::CoordinationNumber => {
                    let (pairs, _) = sim.contact_counts();
                    analysis::mean_coordination_number(sim.particles.len(), pairs)
                }
                JobMetric::GranularTemperature => layered_granular_temperature(sim),
                JobMetric::IntensityOfSegregation => {
                    mixing_final.as_ref().map_or(f64::NAN, |m| m.intensity_of_segregation)
                }
                JobMetric::LaceyIndex => mixing_final.as_ref().map_or(f64::NAN, |m| m.lacey_index),
                JobMetric::MixingRateConstant => mixing_series()
                    .and_then(|(t, is, _)| analysis::fit::fit_exponential_decay(&t, &is))
                    .map_or(f64::NAN, |f| f.rate_constant_per_s),
                JobMetric::MixingRateToRandom => {
                    let random = mixing_final.as_ref().map_or(f64::NAN, |m| {
                        random_mixture_intensity(m.fraction_a, job.analysis.mixing_neighbours)
                    });
                    mixing_series()
                        .and_then(|(t, is, _)| analysis::fit::fit_exponential_decay_to(&t, &is, random))
                        .map_or(f64::NAN, |f| f.rate_constant_per_s)
                }
                JobMetric::ShearRate => shear_rate(),
                JobMetric::CriticalFlipFrequency => critical_frequency(),
                JobMetric::FlipFrequencyRatio => built
                    .spec
                    .gravity
                    .flip
                    .as_ref()
                    .map_or(f64::NAN, |flip| flip.frequency_hz / critical_frequency()),
                JobMetric::FlipRuleAgreement => {
                    let ratio = built
                        .spec
                        .gravity
                        .flip
                        .as_ref()
                        .map_or(f64::NAN, |flip| flip.frequency_hz / critical_frequency());
                    let is_end = mixing_final.map_or(f64::NAN, |m| m.intensity_of_segregation);
                    if ratio.is_nan() || ratio == 1.0 {
                        f64::NAN
                    } else {
                        (is_end - 0.25) * (1.0 - ratio).signum()
                    }
                }
                JobMetric::IntensityOfSegregationTimeAverage => {
                    window(series, "intensity_of_segregation", average_from_s).map_or(f64::NAN, |w| mean(&w))
                }
                JobMetric::TimeTo90PctMaxLacey => mixing_series()
                    .and_then(|(t, _, lacey)| analysis::fit::time_to_fraction_of_max(&t, &lacey, 0.9))
                    .map_or(f64::NAN, |t| t),
                // The series column's last value: the end state's row (`height_families`).
                JobMetric::HeightMixingIndex => series
                    .column("height_mixing_index")
                    .and_then(|c| c.iter().rev().find(|v| !v.is_nan()).copied())
                    .unwrap_or(f64::NAN),
                JobMetric::MeanHeightTimeAverage => {
                    window(series, "mean_height_m", average_from_s).map_or(f64::NAN, |w| mean(&w))
                }
                JobMetric::BedWeightPerArea => bed_weight_per_area_pa(built, sim),
                JobMetric::CoordinationNumberTimeAverage => {
                    window(series, "mean_coordination", average_from_s).map_or(f64::NAN, |w| mean(&w))
                }
                JobMetric::PressureDropMean => {
                    window(series, "column_pressure_drop_pa", average_from_s).map_or(f64::NAN, |w| mean(&w))
                }
                JobMetric::PressureDropStd => {
                    window(series, "column_pressure_drop_pa", average_from_s).map_or(f64::NAN, |w| std_dev(&w))
                }
                JobMetric::ProbePressureDropMean => {
                    window(series, "probe_pressure_drop_pa", average_from_s).map_or(f64::NAN, |w| mean(&w))
                }
                JobMetric::GranularBondNumber
                | JobMetric::GranularBondNumber22
                | JobMetric::GranularBondNumber12
                | JobMetric::GranularCapillaryNumber
                | JobMetric::GranularCapillaryNumber22
                | JobMetric::GranularCapillaryNumber12
                | JobMetric::WetPhaseMixed => wet_number(metric, job, built, sim),
                JobMetric::CoatingVariability => crate::engine::spray::coating_variability(&sim.coating_gain_m3()),
                JobMetric::CoatingVariabilityFitSlope => coating_fit().map_or(f64::NAN, |f| f.slope),
                JobMetric::CoatingVariabilityFitIntercept => coating_fit().map_or(f64::NAN, |f| f.intercept),
                JobMetric::CoatingVariabilityFitInterceptStdError => {
                    coating_fit().map_or(f64::NAN, |f| f.intercept_std_error)
                }
                JobMetric::CoatingVariabilityFitRSquared => coating_fit().map_or(f64::NAN, |f| f.r_squared),
                JobMetric::MeanCollisionDuration => sim.particles.channels.mean_collision_duration_s(),
                JobMetric::MeanWallContactDuration => sim.particles.channels.mean_wall_contact_duration_s(),
                JobMetric::WallContactTimeFraction => sim.particles.channels.wall_contact_time_fraction(sim.time_s),
                JobMetric::DefluidizationVelocity => cycle().map_or(f64::NAN, |c| c.velocities.defluidization_m_per_s),
                JobMetric::FluidizationVelocityTheoretical => {
                    cycle().map_or(f64::NAN, |c| c.velocities.fluidization_theoretical_m_per_s)
                }
                JobMetric::IncipientFluidizationVelocity => {
                    cycle().map_or(f64::NAN, |c| c.velocities.incipient_m_per_s)
                }
                JobMetric::PressureOvershootRatio => cycle().map_or(f64::NAN, |c| c.velocities.overshoot_ratio),
                JobMetric::OvershootFluidForcePerWeight => {
                    overshoot_net_force(NetForcePart::Fluid, cycle(), sim, series)
                }
                JobMetric::OvershootDistributorContactPerWeight => {
                    overshoot_net_force(NetForcePart::DistributorContact, cycle(), sim, series)
                }
                JobMetric::OvershootDistributorCohesionPerWeight => {
                    overshoot_net_force(NetForcePart::DistributorCohesion, cycle(), sim, series)
                }
                JobMetric::OvershootSidewallFrictionPerWeight => {
                    overshoot_net_force(NetForcePart::SidewallFriction, cycle(), sim, series)
                }
                JobMetric::OvershootSidewallNormalLoadPerWeight => {
                    overshoot_net_force(NetForcePart::SidewallNormalLoad, cycle(), sim, series)
                }
                JobMetric::SteppedFluidizationVelocity => stepped_onset_m_per_s(job, built, sim, series),
                JobMetric::MeanTemperature => {
                    let p = &sim.particles;
                    let mass: f64 = p.mass_kg.iter().sum();
                    p.mass_kg.iter().zip(&p.temperature_k).map(|(m, t)| m * t).sum::<f64>() / mass
                }
                JobMetric::WallHeatTransferCoefficient => core().map_or(f64::NAN, |(f, _)| f.coefficient_w_per_m2_k),
                JobMetric::WallHeatTransferCoefficientInnerCore => {
                    wall_heat(job, sim, series, "inner_core_temperature_k")
                        .map_or(f64::NAN, |(f, _)| f.coefficient_w_per_m2_k)
                }
                JobMetric::CoreHeatingSlope => core().map_or(f64::NAN, |(f, _)| f.slope_per_s),
                JobMetric::WallHeatTransferCoefficientBed => bed().map_or(f64::NAN, |(f, _)| f.coefficient_w_per_m2_k),
                JobMetric::BedHeatingSlope => bed().map_or(f64::NAN, |(f, _)| f.slope_per_s),
                JobMetric::DrumContactArc => core().map_or(f64::NAN, |(_, arc)| arc),
                JobMetric::DrumWallContactTime => core().map_or(f64::NAN, |(f, _)| f.contact_time_s),
                JobMetric::ConstantRateDryingRate => drying_curve()
                    .and_then(|(t, x)| analysis::drying_curve::constant_rate_period(&t, &x))
                    .map_or(f64::NAN, |p| p.rate_per_s),
                JobMetric::ConstantRatePeriod => drying_curve().map_or(f64::NAN, |(t, x)| {
                    analysis::drying_curve::constant_rate_period(&t, &x).map_or(0.0, |p| p.to_s - p.from_s)
                }),
                JobMetric::TimeTo50PctDried => drying_curve()
                    .and_then(|(t, x)| analysis::drying_curve::time_to_fraction_removed(&t, &x, 0.5))
                    .unwrap_or(f64::NAN),
                JobMetric::TimeTo90PctDried => drying_curve()
                    .and_then(|(t, x)| analysis::drying_curve::time_to_fraction_removed(&t, &x, 0.9))
                    .unwrap_or(f64::NAN),
                JobMetric::FinalMoistureContent => {
                    sim.gas.as_ref().and_then(|g| g.drying.as_ref()).map_or(f64::NAN, |d| {
                        sim.total_liquid_m3() * d.config.liquid_density_kg_per_m3
                            / sim.particles.mass_kg.iter().sum::<f64>()
                    })
                }
                JobMetric::MinMeanParticleTemperature => coldest().map_or(f64::NAN, |(_, t)| t),
                JobMetric::TimeOfMinMeanParticleTemperature => coldest().map_or(f64::NAN, |(at, _)| at),
                JobMetric::LiquidFractionEvaporated => drying_curve()
                    .and_then(|(_, x)| Some(1.0 - x.last()? / x.first()?))
                    .unwrap_or(f64::NAN),
                JobMetric::MoistureLargestRise => drying_curve()
                    .and_then(|(_, x)| {
                        let x0 = *x.first()?;
                        x.windows(2).map(|w| (w[1] - w[0]) / x0).reduce(f64::max)
                    })
                    .unwrap_or(f64::NAN),
                JobMetric::EvaporativeCooling => mean_temperatures()
                    .zip(coldest())
                    .map_or(f64::NAN, |(t, (_, min))| t[0] - min),
                JobMetric::TemperatureRiseAfterMinimum => mean_temperatures()
                    .zip(coldest())
                    .map_or(f64::NAN, |(t, (_, min))| t[t.len() - 1] - min),
                JobMetric::DryingLedgerClosure => largest_magnitude("drying_closure"),
                JobMetric::EnergyLedgerClosure => largest_magnitude("energy_closure"),
            };
            Metric {
                name: metric.name().to_string(),
                value,
                unit: metric.unit().to_string(),
            }
        })
        .collect()
}

/// The values of a series column from time `from_s` on (`None` if the column is missing or the window empty).
fn window(series: &Series, column: &str, from_s: f64) -> Option<Vec<f64>> {
    let t = series.column("time_s")?;
    let v = series.column(column)?;
    let w: Vec<f64> = t
        .iter()
        .zip(v)
        .filter(|(t, v)| **t >= from_s && v.is_finite())
        .map(|(_, v)| *v)
        .collect();
    (!w.is_empty()).then_some(w)
}

fn mean(v: &[f64]) -> f64 {
    v.iter().sum::<f64>() / v.len() as f64
}

/// Population standard deviation.
fn std_dev(v: &[f64]) -> f64 {
    let m = mean(v);
    (v.iter().map(|x| (x - m) * (x - m)).sum::<f64>() / v.len() as f64).sqrt()
}

/// The granular Bond and capillary numbers of the scenario's liquid and species (1 = the first species, 2 = the
/// second), and seed 000's phase rule; NaN where the scenario lacks what they need (checked before the run).
fn wet_number(metric: JobMetric, job: &JobSpec, built: &BuiltScenario, sim: &Simulation) -> f64 {
    use crate::analysis::dimensionless::{
        GasSlip, WetParticle, WetPhase, binary_granular_bond_number, binary_granular_capillary_number,
        granular_bond_number, granular_capillary_number, wet_phase,
    };
    let Some(CohesionModel::LiquidBridge(bridge)) = built.spec.cohesion else {
        return f64::NAN;
    };
    let gamma = bridge.surface_tension_n_per_m;
    let g = built.spec.gravity.vector_m_per_s2;
    let g = (g[0] * g[0] + g[1] * g[1] + g[2] * g[2]).sqrt();
    let kind = |k: usize| {
        built.config.species.species.get(k).map(|s| WetParticle {
            radius_m: s.radius_m,
            density_kg_per_m3: s.density_kg_per_m3,
            contact_angle_rad: s.contact_angle_rad,
        })
    };
    let (Some(a), b) = (kind(0), kind(1)) else {
        return f64::NAN;
    };
    let porosity = job.analysis.capillary_number_porosity.unwrap_or(0.55);
    let gas = built
        .spec
        .gas
        .as_ref()
        .zip(inlet_velocity_m_per_s(sim))
        .map(|(gas, u)| GasSlip {
            density_kg_per_m3: gas.density_kg_per_m3,
            viscosity_pa_s: gas.viscosity_pa_s,
            slip_speed_m_per_s: u / porosity,
            porosity,
        });
    let value = match (metric, b, gas) {
        (JobMetric::GranularBondNumber, _, _) => Some(granular_bond_number(&a, gamma, g)),
        (JobMetric::GranularBondNumber22, Some(b), _) => Some(granular_bond_number(&b, gamma, g)),
        (JobMetric::GranularBondNumber12, Some(b), _) => Some(binary_granular_bond_number(&a, &b, gamma, g)),
        (JobMetric::GranularCapillaryNumber, _, Some(gas)) => Some(granular_capillary_number(&a, gamma, &gas)),
        (JobMetric::GranularCapillaryNumber22, Some(b), Some(gas)) => Some(granular_capillary_number(&b, gamma, &gas)),
        (JobMetric::GranularCapillaryNumber12, Some(b), Some(gas)) => {
            Some(binary_granular_capillary_number(&a, &b, gamma, &gas, g))
        }
        (JobMetric::WetPhaseMixed, Some(b), Some(gas)) => {
            let phase = wet_phase(
                granular_capillary_number(&a, gamma, &gas),
                granular_capillary_number(&b, gamma, &gas),
                binary_granular_capillary_number(&a, &b, gamma, &gas, g),
            );
            Some(if phase == WetPhase::Mixed { 1.0 } else { 0.0 })
        }
        _ => None,
    };
    value.unwrap_or(f64::NAN)
}

/// The superficial velocity of the gas entering through the inlet side, m/s (the magnitude of the prescribed
/// inflow; `None` without a gas or an inlet side).
fn inlet_velocity_m_per_s(sim: &Simulation) -> Option<f64> {
    sim.gas.as_ref()?.superficial_inflow_m_per_s()
}

/// IS of a random mixture, √(P(1−P)/n): P the fraction of the mixing species (by number or volume, as
/// `analysis.mixing_concentration`; the final state's `fraction_a`), n the particles of one local sample (the
/// particle and its `mixing_neighbours` nearest neighbours). By volume with unequal sizes this is the equal-size
/// value at the same P.
fn random_mixture_intensity(fraction_a: f64, neighbours: usize) -> f64 {
    (fraction_a * (1.0 - fraction_a) / (neighbours + 1) as f64).sqrt()
}

/// One level of `gas.inflow_levels`: its velocity and the pressure drop's mean and standard deviation over the
/// second half of its hold (CHOICE: the first half lets the bed respond; seed 001 time-averages each 0.1 s level
/// at "statistical steady state"); the velocity is the inlet velocity times the level's factor (and the ramp's).
/// With `analysis.cycle_pressure: first_node` the pressure drop is seed 001's first-node reading and the weight its
/// W'/A, averaged over the same window (particles cross the node as the bed moves); otherwise the column's pressure
/// drop against W/A of the whole bed.
pub(crate) struct LevelStats {
    /// The level's time window (the second half of its hold), s.
    pub(crate) window_s: (f64, f64),
    pub(crate) velocity_m_per_s: f64,
    pub(crate) pressure_drop_mean_pa: f64,
    pub(crate) pressure_drop_std_pa: f64,
    pub(crate) weight_per_area_pa: f64,
}

pub(crate) fn level_stats(
    job: &JobSpec,
    built: &BuiltScenario,
    sim: &Simulation,
    series: &Series,
) -> Option<Vec<LevelStats>> {
    let gas = built.spec.gas.as_ref()?;
    let levels = gas.inflow_levels.as_ref()?;
    let u = inlet_velocity_m_per_s(sim)?;
    let t = series.column("time_s")?;
    let (dp, weight) = match job.analysis.cycle_pressure {
        CyclePressure::Column => (series.column("column_pressure_drop_pa")?, None),
        CyclePressure::FirstNode => (
            series.column("node_pressure_drop_pa")?,
            Some(series.column("node_weight_per_area_pa")?),
        ),
    };
    let whole_bed_pa = bed_weight_per_area_pa(built, sim);
    let stats = levels
        .factors
        .iter()
        .enumerate()
        .filter_map(|(k, factor)| {
            let (from, to) = (
                levels.start_s + (k as f64 + 0.5) * levels.hold_s,
                levels.start_s + (k as f64 + 1.0) * levels.hold_s,
            );
            let rows: Vec<usize> = (0..t.len())
                .filter(|&k| t[k] >= from && t[k] < to && dp[k].is_finite())
                .collect();
            let window: Vec<f64> = rows.iter().map(|&k| dp[k]).collect();
            let ramp = gas.inflow_ramp.map_or(1.0, |r| r.factor(from));
            (!window.is_empty()).then(|| LevelStats {
                window_s: (from, to),
                velocity_m_per_s: u * factor * ramp,
                pressure_drop_mean_pa: mean(&window),
                pressure_drop_std_pa: std_dev(&window),
                weight_per_area_pa: weight
                    .map_or(whole_bed_pa, |w| mean(&rows.iter().map(|&k| w[k]).collect::<Vec<_>>())),
            })
        })
        .collect();
    Some(stats)
}

/// Seed 001's cycle velocities and the levels they were read from.
pub(crate) struct Cycle {
    pub(crate) velocities: analysis::fluidization::CycleVelocities,
    pub(crate) levels: Vec<LevelStats>,
}

/// Seed 001's cycle velocities from the level means ([`level_stats`]), each level's pressure drop over its weight
/// per area (seed 001's ΔP* = ΔP/(W'/A_b)), so that the line meets 1.
pub(crate) fn cycle(job: &JobSpec, built: &BuiltScenario, sim: &Simulation, series: &Series) -> Option<Cycle> {
    let levels = level_stats(job, built, sim, series)?;
    let points: Vec<analysis::fluidization::CycleLevel> = levels
        .iter()
        .map(|l| analysis::fluidization::CycleLevel {
            velocity_m_per_s: l.velocity_m_per_s,
            pressure_drop_mean_pa: l.pressure_drop_mean_pa / l.weight_per_area_pa,
        })
        .collect();
    (points.len() >= 3).then(|| Cycle {
        velocities: analysis::fluidization::cycle_velocities(&points, 1.0),
        levels,
    })
}

/// Which mechanism of the net-force split (seed 001 Figs 8.8-8.16) an `overshoot_*_per_weight` metric reads.
#[derive(Clone, Copy)]
enum NetForcePart {
    Fluid,
    DistributorContact,
    DistributorCohesion,
    SidewallFriction,
    SidewallNormalLoad,
}

/// A net-force part over the weight, averaged over the second half of the cycle's overshoot peak level (the
/// climb's top): the series' `*_up_n` columns (the sidewalls' normal load: their `*_contact_across_n` columns)
/// over `weight_n`. The distributor is every plane wall whose normal points against gravity, the sidewalls every
/// plane wall parallel to it (normals checked at the bed's centroid).
fn overshoot_net_force(part: NetForcePart, cycle: Option<&Cycle>, sim: &Simulation, series: &Series) -> f64 {
    let Some(cycle) = cycle else {
        return f64::NAN;
    };
    let (Some(peak), Some(t), Some(weight)) = (
        cycle.velocities.peak_level,
        series.column("time_s"),
        series.column("weight_n"),
    ) else {
        return f64::NAN;
    };
    let Some(up) = (-sim.config.gravity.at(sim.time_s)).try_normalize(0.0) else {
        return f64::NAN;
    };
    let p = &sim.particles;
    let centroid = p.position_m.iter().fold(Vec3::zeros(), |s, x| s + x) / p.len().max(1) as f64;
    // Wall names whose columns make up this part, with the column suffix.
    let walls = |facing: &dyn Fn(f64) -> bool| -> Vec<String> {
        sim.config
            .walls
            .iter()
            .zip(&sim.wall_angle_rad)
            .filter(|(w, angle)| w.is_plane() && facing(w.proximity(&centroid, **angle).normal.dot(&up)))
            .map(|(w, _)| w.name.clone())
            .collect()
    };
    const PARALLEL: f64 = 1e-9;
    let columns: Vec<String> = match part {
        NetForcePart::Fluid => vec!["fluid_force_up_n".into()],
        NetForcePart::DistributorContact => walls(&|c| c > 1.0 - PARALLEL)
            .iter()
            .map(|w| format!("wall_{w}_contact_up_n"))
            .collect(),
        NetForcePart::DistributorCohesion => walls(&|c| c > 1.0 - PARALLEL)
            .iter()
            .map(|w| format!("wall_{w}_cohesion_up_n"))
            .collect(),
        NetForcePart::SidewallFriction => walls(&|c| c.abs() < PARALLEL)
            .iter()
            .flat_map(|w| [format!("wall_{w}_contact_up_n"), format!("wall_{w}_cohesion_up_n")])
            .collect(),
        NetForcePart::SidewallNormalLoad => walls(&|c| c.abs() < PARALLEL)
            .iter()
            .map(|w| format!("wall_{w}_contact_across_n"))
            .collect(),
    };
    let Some(columns) = columns
        .iter()
        .map(|c| series.column(c))
        .collect::<Option<Vec<&[f64]>>>()
    else {
        return f64::NAN;
    };
    let (from, to) = cycle.levels[peak].window_s;
    let ratios: Vec<f64> = (0..t.len())
        .filter(|&k| t[k] >= from && t[k] < to)
        .map(|k| columns.iter().map(|c| c[k]).sum::<f64>() / weight[k])
        .collect();
    if ratios.is_empty() { f64::NAN } else { mean(&ratios) }
}

/// u_mf of a run whose levels step the gas up: on the rising branch (from the slowest level on), the slowest level
/// from which the bed keeps moving at every faster level (σ(ΔP) ≥ 1 % of W/A; `minimum_fluidization`'s sustained
/// reading, applied to the levels of one run instead of to a sweep of runs). NaN when the levels do not bracket the
/// onset.
pub(crate) fn stepped_onset_m_per_s(job: &JobSpec, built: &BuiltScenario, sim: &Simulation, series: &Series) -> f64 {
    let Some(levels) = level_stats(job, built, sim, series) else {
        return f64::NAN;
    };
    let slowest = levels
        .iter()
        .enumerate()
        .rev()
        .min_by(|a, b| a.1.velocity_m_per_s.total_cmp(&b.1.velocity_m_per_s))
        .map_or(0, |(k, _)| k);
    let points: Vec<analysis::fluidization::SweepPoint> = levels[slowest..]
        .iter()
        .map(|l| analysis::fluidization::SweepPoint {
            velocity_m_per_s: l.velocity_m_per_s,
            pressure_drop_mean_pa: l.pressure_drop_mean_pa,
            pressure_drop_std_pa: l.pressure_drop_std_pa,
            bed_weight_per_area_pa: l.weight_per_area_pa,
        })
        .collect();
    analysis::fluidization::minimum_fluidization(&points).map_or(f64::NAN, |m| m.from_sustained_fluctuations_m_per_s)
}

/// h_w of the run's heated drum from the series column `core_column` (a core or the bed's mean temperature), fitted from
/// `analysis.heating_fit_from_s` (default: when the wall starts heating) to the end, with T_0 the core's temperature
/// at the first row from the wall's start, and the contact arc's mean over the fit window (returned beside the fit).
/// `None` without a heated drum, its columns or enough rows.
pub(crate) fn wall_heat(
    job: &JobSpec,
    sim: &Simulation,
    series: &Series,
    core_column: &str,
) -> Option<(analysis::wall_heat::WallHeatFit, f64)> {
    let drum = crate::heated_drum::heated_drum(&sim.config)?;
    let heat = sim.config.heat.as_ref()?;
    let (t, core, arc) = (
        series.column("time_s")?,
        series.column(core_column)?,
        series.column("drum_contact_arc_rad")?,
    );
    let start = (0..t.len()).find(|&k| t[k] >= drum.heated_from_s && core[k].is_finite())?;
    let from_s = job.analysis.heating_fit_from_s.unwrap_or(drum.heated_from_s);
    let rows: Vec<usize> = (0..t.len()).filter(|&k| t[k] >= from_s).collect();
    let arc_rad = mean(&rows.iter().map(|&k| arc[k]).collect::<Vec<_>>());
    let p = &sim.particles;
    let bed_mass_kg: f64 = p.mass_kg.iter().sum();
    let heat_j_per_k: f64 = (0..p.len())
        .map(|i| p.mass_kg[i] * heat.heat_capacity_j_per_kg_k[p.species[i].index()])
        .sum();
    let inputs = analysis::wall_heat::WallHeatInputs {
        wall_temperature_k: drum.temperature_k,
        initial_core_temperature_k: core[start],
        heat_capacity_j_per_kg_k: heat_j_per_k / bed_mass_kg,
        bed_mass_kg,
        drum_radius_m: drum.axis.radius_m,
        drum_length_m: drum.length_m,
        contact_arc_rad: arc_rad,
        angular_speed_rad_per_s: drum.angular_speed_rad_per_s,
    };
    let (t, core): (Vec<f64>, Vec<f64>) = rows.iter().map(|&k| (t[k], core[k])).unzip();
    analysis::wall_heat::wall_heat_transfer_coefficient(&t, &core, &inputs).map(|fit| (fit, arc_rad))
}

/// W/A: the particles' weight over the area of the inlet side (seed 000 eq 2.74).
fn bed_weight_per_area_pa(built: &BuiltScenario, sim: &Simulation) -> f64 {
    let Some(area_m2) = sim.gas.as_ref().and_then(|gas| gas.inlet_side_area_m2()) else {
        return f64::NAN;
    };
    let g = built.spec.gravity.vector_m_per_s2;
    let g = (g[0] * g[0] + g[1] * g[1] + g[2] * g[2]).sqrt();
    sim.particles.mass_kg.iter().sum::<f64>() * g / area_m2
}

/// Granular temperature (seed 000 eq 3.1) about the mean velocity of layers normal to gravity, each two particle
/// diameters thick (the seed's "local mean velocities in the shear layer"); with no gravity, about the bed's mean.
fn layered_granular_temperature(sim: &Simulation) -> f64 {
    let p = &sim.particles;
    if p.is_empty() {
        return f64::NAN;
    }
    let g = sim.config.gravity.at(sim.time_s);
    let axis = (0..3)
        .max_by(|&a, &b| g[a].abs().total_cmp(&g[b].abs()))
        .expect("three axes");
    let (bins, count) = if g.norm() == 0.0 {
        (vec![Some(0); p.len()], 1)
    } else {
        let lo = p.position_m.iter().map(|x| x[axis]).fold(f64::INFINITY, f64::min);
        let hi = p.position_m.iter().map(|x| x[axis]).fold(f64::NEG_INFINITY, f64::max);
        let layers = (((hi - lo) / (4.0 * p.max_radius_m())).ceil() as usize).max(1);
        (
            analysis::granular::layer_bins(&p.position_m, axis, lo, hi, layers),
            layers,
        )
    };
    analysis::granular_temperature(&p.velocity_m_per_s, &bins, count).mean_m2_per_s2
}
