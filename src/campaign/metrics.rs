//! The per-job metrics a campaign can ask for: names, units, what they need.

use super::JobSpec;
use super::spec::CampaignSpec;
use crate::engine::models::cohesion_law::{CohesionModel, LiquidBridge};

/// A metric a worker can reduce from its job.
#[derive(Debug, Clone, Copy)]
pub struct MetricInfo {
    pub name: &'static str,
    pub unit: &'static str,
    pub description: &'static str,
    /// What it needs from the campaign and its scenario.
    pub needs: &'static [Need],
}

/// What a metric needs.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Need {
    /// `analysis.mixing_species` (which species is A in a binary mixture).
    MixingSpecies,
    /// A gas in the scenario.
    Gas,
    /// `gas.pressure_probe_height_m`.
    PressureProbe,
    /// Liquid-bridge cohesion (`cohesion: liquid_bridge`).
    LiquidBridges,
    /// Exactly two species (1 = the first, 2 = the second).
    TwoSpecies,
    /// A gas with `inflow_levels` (a cycle, or levels stepping the gas up).
    InflowLevels,
    /// A spray (`liquid_bridge.spray`).
    Spray,
    /// `output.net_forces` (the net force by mechanism in the series).
    NetForces,
}

impl Need {
    /// Why `job` does not meet this need (`None`: it does). `MixingSpecies` is checked on the campaign
    /// ([`check`]), where the key lives.
    fn unmet(self, name: &str, job: &JobSpec) -> Option<String> {
        let scenario = &job.scenario;
        let gas = scenario.gas.as_ref();
        let unless = |met: bool, message: String| (!met).then_some(message);
        match self {
            Need::MixingSpecies => None,
            Need::Gas => unless(
                gas.is_some(),
                format!("`{name}` needs a gas (a `gas:` section in the scenario)"),
            ),
            Need::PressureProbe => unless(
                gas.is_none_or(|g| g.pressure_probe_height_m.is_some()),
                format!("`{name}` needs gas.pressure_probe_height_m"),
            ),
            Need::LiquidBridges => unless(
                matches!(scenario.cohesion, Some(CohesionModel::LiquidBridge(_))),
                format!("`{name}` needs liquid bridges (`cohesion: {{ liquid_bridge: ... }}` in the scenario)"),
            ),
            Need::TwoSpecies => unless(
                scenario.species.len() == 2,
                format!(
                    "`{name}` needs exactly two species (1 = the first, 2 = the second); the scenario has {}",
                    scenario.species.len()
                ),
            ),
            Need::InflowLevels => unless(
                gas.is_some_and(|g| g.inflow_levels.is_some()),
                format!("`{name}` needs a gas with `inflow_levels` (a defluidization/fluidization cycle or steps)"),
            ),
            Need::Spray => unless(
                matches!(
                    scenario.cohesion,
                    Some(CohesionModel::LiquidBridge(LiquidBridge { spray: Some(_), .. }))
                ),
                format!("`{name}` needs a spray (`cohesion: {{ liquid_bridge: {{ spray: ... }} }}`)"),
            ),
            Need::NetForces => unless(
                scenario.output.net_forces,
                format!("`{name}` needs `output.net_forces: true` (the net force by mechanism in the series)"),
            ),
        }
    }
}

pub const METRICS: &[MetricInfo] = &[
    MetricInfo {
        name: "kinetic_energy_j",
        unit: "J",
        description: "total (translational + rotational) kinetic energy at the end",
        needs: &[],
    },
    MetricInfo {
        name: "translational_kinetic_energy_j",
        unit: "J",
        description: "translational kinetic energy at the end",
        needs: &[],
    },
    MetricInfo {
        name: "bed_top_m",
        unit: "m",
        description: "highest particle centre along -gravity at the end (bed or column height)",
        needs: &[],
    },
    MetricInfo {
        name: "mean_height_m",
        unit: "m",
        description: "mean particle centre height along -gravity at the end",
        needs: &[],
    },
    MetricInfo {
        name: "coordination_number",
        unit: "1",
        description: "mean particle-particle contacts per particle at the end",
        needs: &[],
    },
    MetricInfo {
        name: "granular_temperature_m2_per_s2",
        unit: "m2/s2",
        description: "granular temperature at the end (seed 000 eq. 3.1)",
        needs: &[],
    },
    MetricInfo {
        name: "intensity_of_segregation",
        unit: "1",
        description: "IS at the end: std. dev. of the local volume fraction of the mixing species (seed 000 eqs 2.77-2.78)",
        needs: &[Need::MixingSpecies],
    },
    MetricInfo {
        name: "lacey_index",
        unit: "1",
        description: "Lacey mixing index at the end (seed 000 eq. 2.80)",
        needs: &[Need::MixingSpecies],
    },
    MetricInfo {
        name: "mixing_rate_constant_per_s",
        unit: "1/s",
        description: "k of an exponential fit to IS(t) (seed 000 §4.1.3)",
        needs: &[Need::MixingSpecies],
    },
    MetricInfo {
        name: "mixing_rate_to_random_per_s",
        unit: "1/s",
        description: "k of IS(t) = IS_R + b exp(-k t) with IS_R = sqrt(P(1-P)/n) the random mixture's IS (n particles per local sample): the approach to a random mixture",
        needs: &[Need::MixingSpecies],
    },
    MetricInfo {
        name: "time_to_90pct_max_lacey_s",
        unit: "s",
        description: "first time the Lacey index reaches 90 % of its maximum (seed 000 Table 1)",
        needs: &[Need::MixingSpecies],
    },
    MetricInfo {
        name: "mean_height_time_avg_m",
        unit: "m",
        description: "mean particle centre height along -gravity, averaged over the series from analysis.average_from_s (seed 002's mean particle height, 5-10 s)",
        needs: &[],
    },
    MetricInfo {
        name: "coordination_number_time_avg",
        unit: "1",
        description: "mean particle-particle contacts per particle, averaged over the series from analysis.average_from_s (seed 002 Fig. 5's bulk coordination number)",
        needs: &[],
    },
    MetricInfo {
        name: "bed_weight_per_area_pa",
        unit: "Pa",
        description: "weight of the particles over the inlet area, W/A (seed 000 eq. 2.74): what the pressure drop of a fluidized bed carries",
        needs: &[Need::Gas],
    },
    MetricInfo {
        name: "pressure_drop_mean_pa",
        unit: "Pa",
        description: "time-averaged pressure drop from the inlet face to the top layer of gas cells, from analysis.average_from_s",
        needs: &[Need::Gas],
    },
    MetricInfo {
        name: "pressure_drop_std_pa",
        unit: "Pa",
        description: "standard deviation of that pressure drop over the same window (its jump marks u_mf, seed 000 §4.1.2)",
        needs: &[Need::Gas],
    },
    MetricInfo {
        name: "granular_bond_number",
        unit: "1",
        description: "Bo_g = F_c,max/W of the first species, F_c,max = 2πRγ cos θ (seed 000 §4.1.1)",
        needs: &[Need::LiquidBridges],
    },
    MetricInfo {
        name: "granular_bond_number_22",
        unit: "1",
        description: "Bo_g of the second species",
        needs: &[Need::LiquidBridges, Need::TwoSpecies],
    },
    MetricInfo {
        name: "granular_bond_number_12",
        unit: "1",
        description: "Bo_g12: the 1-2 pair's F_c,max over the lighter particle's weight (seed 000 §4.2.1)",
        needs: &[Need::LiquidBridges, Need::TwoSpecies],
    },
    MetricInfo {
        name: "granular_capillary_number",
        unit: "1",
        description: "Ca_g = F_c,max/F_d of the first species, Di Felice drag at slip U/ε (seed 000 eq. 4.3; analysis.capillary_number_porosity)",
        needs: &[Need::Gas, Need::LiquidBridges],
    },
    MetricInfo {
        name: "granular_capillary_number_22",
        unit: "1",
        description: "Ca_g of the second species",
        needs: &[Need::Gas, Need::LiquidBridges, Need::TwoSpecies],
    },
    MetricInfo {
        name: "granular_capillary_number_12",
        unit: "1",
        description: "Ca_g12: the pair's F_c,max over the drag of the species with the larger F_d/W (seed 000 eqs. 4.4-4.5)",
        needs: &[Need::Gas, Need::LiquidBridges, Need::TwoSpecies],
    },
    MetricInfo {
        name: "wet_phase_mixed",
        unit: "1",
        description: "seed 000's phase rule on Ca_g11, Ca_g22, Ca_g12: 1 = more mixed than dry (M), 0 = more segregated (S)",
        needs: &[Need::Gas, Need::LiquidBridges, Need::TwoSpecies],
    },
    MetricInfo {
        name: "defluidization_velocity_m_per_s",
        unit: "m/s",
        description: "U_mf,df of a gas.inflow_levels cycle: the line through the falling branch's packed-bed level means meets W/A (seed 001 §6.4.2.1; with analysis.cycle_pressure: first_node, the first node's pressure drop against W'/A)",
        needs: &[Need::Gas, Need::InflowLevels],
    },
    MetricInfo {
        name: "fluidization_velocity_theoretical_m_per_s",
        unit: "m/s",
        description: "U_mf,th: the same on the rising branch",
        needs: &[Need::Gas, Need::InflowLevels],
    },
    MetricInfo {
        name: "incipient_fluidization_velocity_m_per_s",
        unit: "m/s",
        description: "U_mf,in: the velocity of the overshoot peak, the rising branch's largest level-mean pressure drop before the first level whose mean falls (the bed gives way; seed 001: left of the bubbling region), when it exceeds W/A",
        needs: &[Need::Gas, Need::InflowLevels],
    },
    MetricInfo {
        name: "pressure_overshoot_ratio",
        unit: "1",
        description: "the overshoot peak (see incipient_fluidization_velocity_m_per_s) over W/A (above 1: an overshoot)",
        needs: &[Need::Gas, Need::InflowLevels],
    },
    MetricInfo {
        name: "overshoot_fluid_force_per_weight",
        unit: "1",
        description: "the gas's force on all particles (its component against gravity) over their weight, averaged over the second half of the overshoot peak's level (see incipient_fluidization_velocity_m_per_s; the climb's top when there is no overshoot); seed 001 Figs 8.8-8.16",
        needs: &[Need::Gas, Need::InflowLevels, Need::NetForces],
    },
    MetricInfo {
        name: "overshoot_distributor_contact_per_weight",
        unit: "1",
        description: "the same for the contact force of the distributor (the plane walls facing against gravity)",
        needs: &[Need::Gas, Need::InflowLevels, Need::NetForces],
    },
    MetricInfo {
        name: "overshoot_distributor_cohesion_per_weight",
        unit: "1",
        description: "the same for the distributor's cohesion (negative: it holds the bed down)",
        needs: &[Need::Gas, Need::InflowLevels, Need::NetForces],
    },
    MetricInfo {
        name: "overshoot_sidewall_friction_per_weight",
        unit: "1",
        description: "the same for the sidewalls (plane walls parallel to gravity): their friction, with any tangential force of their cohesion (negative: they hold the bed down)",
        needs: &[Need::Gas, Need::InflowLevels, Need::NetForces],
    },
    MetricInfo {
        name: "overshoot_sidewall_normal_load_per_weight",
        unit: "1",
        description: "the same for the sidewalls' normal load: the size of their contact forces across gravity, summed over the sidewalls (in a pseudo-2-D bed exactly their normal load; in 3-D it also holds their horizontal friction); with μ, the friction they could give (the thesis: cohesion with the sidewalls only raises this load)",
        needs: &[Need::Gas, Need::InflowLevels, Need::NetForces],
    },
    MetricInfo {
        name: "stepped_fluidization_velocity_m_per_s",
        unit: "m/s",
        description: "u_mf of a gas.inflow_levels run stepping the gas up: the slowest level of the rising branch from which the bed keeps moving (σ(ΔP) over the second half of each hold ≥ 1 % of W/A) at every faster level; NaN when the levels do not bracket the onset",
        needs: &[Need::Gas, Need::InflowLevels],
    },
    MetricInfo {
        name: "coating_variability",
        unit: "1",
        description: "CV_m = σ/μ of the liquid each particle received from the spray (seed 000 eq. 6.45)",
        needs: &[Need::Spray],
    },
    MetricInfo {
        name: "probe_pressure_drop_mean_pa",
        unit: "Pa",
        description: "time-averaged pressure drop from the inlet to gas.pressure_probe_height_m",
        needs: &[Need::Gas, Need::PressureProbe],
    },
];

pub fn info(name: &str) -> Option<&'static MetricInfo> {
    METRICS.iter().find(|m| m.name == name)
}

/// Checks the metric names and the analysis settings they need; errors are (key path, message).
pub fn check(spec: &CampaignSpec) -> Result<(), (String, String)> {
    if spec.metrics.is_empty() {
        return Err(("metrics".into(), "expected at least one metric".into()));
    }
    let names: Vec<&str> = METRICS.iter().map(|m| m.name).collect();
    for (k, name) in spec.metrics.iter().enumerate() {
        let Some(m) = info(name) else {
            let hint = super::sweep::did_you_mean(name, &names)
                .map(|s| format!("did you mean `{s}`? "))
                .unwrap_or_default();
            return Err((
                format!("metrics[{k}]"),
                format!("unknown metric `{name}`; {hint}known: {}", names.join(", ")),
            ));
        };
        if spec.metrics[..k].contains(name) {
            return Err((format!("metrics[{k}]"), format!("metric `{name}` is listed twice")));
        }
        if m.needs.contains(&Need::MixingSpecies) && spec.analysis.mixing_species.is_none() {
            return Err((
                format!("metrics[{k}]"),
                format!("`{name}` needs `analysis.mixing_species` (which species is A in the binary mixture)"),
            ));
        }
    }
    if let Some(t) = spec.analysis.average_from_s
        && !(t.is_finite() && t >= 0.0 && t < spec.base.time.end_time_s)
    {
        return Err((
            "analysis.average_from_s".into(),
            format!(
                "expected 0 <= value < the end time ({} s), got {t}",
                spec.base.time.end_time_s
            ),
        ));
    }
    if let Some(t) = spec.analysis.mixing_fit_from_s
        && !(t.is_finite() && t >= 0.0 && t < spec.base.time.end_time_s)
    {
        return Err((
            "analysis.mixing_fit_from_s".into(),
            format!(
                "expected 0 <= value < the end time ({} s), got {t}",
                spec.base.time.end_time_s
            ),
        ));
    }
    if spec.analysis.mixing_neighbours == 0 {
        return Err(("analysis.mixing_neighbours".into(), "expected at least 1".into()));
    }
    if let Some(every) = spec.analysis.mixing_every_steps
        && (every == 0 || every % spec.base.output.series_every_steps != 0)
    {
        return Err((
            "analysis.mixing_every_steps".into(),
            format!(
                "expected a positive multiple of base.output.series_every_steps ({})",
                spec.base.output.series_every_steps
            ),
        ));
    }
    Ok(())
}

/// Checks what depends on the resolved scenario (the mixing species must exist in it).
pub fn check_job(job: &JobSpec) -> Result<(), (String, String)> {
    for (k, name) in job.metrics.iter().enumerate() {
        if let Some(message) = info(name)
            .into_iter()
            .flat_map(|m| m.needs)
            .find_map(|need| need.unmet(name, job))
        {
            return Err((format!("metrics[{k}]"), message));
        }
    }
    if let Some(eps) = job.analysis.capillary_number_porosity
        && !(eps.is_finite() && eps > 0.0 && eps <= 1.0)
    {
        return Err((
            "analysis.capillary_number_porosity".into(),
            format!("expected 0 < value <= 1, got {eps}"),
        ));
    }
    if let Some(a) = &job.analysis.mixing_species
        && !job.scenario.species.iter().any(|s| &s.name == a)
    {
        let known: Vec<&str> = job.scenario.species.iter().map(|s| s.name.as_str()).collect();
        return Err((
            "analysis.mixing_species".into(),
            format!("unknown species `{a}`; the scenario defines {}", known.join(", ")),
        ));
    }
    Ok(())
}
