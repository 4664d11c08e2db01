//! The per-job metrics a campaign can ask for (`metrics:` in a campaign file) as one closed set, [`JobMetric`],
//! declared by the table below: one row per metric with its name (as campaign files write it and the database
//! stores it), its SI unit, what it needs from the campaign and its scenario ([`Need`]), and what it is. `granflow
//! models` and the campaign file's JSON Schema list the metrics from this table, and the checks here refuse an
//! unknown name (with a did-you-mean) or a metric whose needs a job does not meet.
//!
//! What does not live here: computing the metrics (the worker's reducers, `crate::worker`'s `reduce.rs`, one
//! exhaustive `match` over [`JobMetric`], so a new row does not build until its reducer exists) and the
//! campaign-level metrics of several jobs ([`super::derived`]).

use std::borrow::Cow;

use serde::{Deserialize, Deserializer, Serialize, Serializer};

use super::JobSpec;
use super::spec::CampaignSpec;
use crate::engine::models::cohesion_law::{CohesionModel, LiquidBridge};
use crate::scenario::spec::WallSpec;

/// Declares [`JobMetric`] from its table: `Variant => "name", "unit", [needs], "description";`.
macro_rules! job_metrics {
    ($($variant:ident => $name:literal, $unit:literal, [$($need:ident),*], $description:literal;)*) => {
        /// A per-job metric: one number with a unit that a worker reduces from its finished job.
        #[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, PartialOrd, Ord)]
        pub enum JobMetric {
            $(#[doc = $description] $variant,)*
        }

        impl JobMetric {
            /// Every metric, in the table's order (the order `granflow models` and error messages list them in).
            pub const ALL: &'static [JobMetric] = &[$(JobMetric::$variant,)*];

            /// The name campaign files write, `result.json` and the database store.
            pub fn name(self) -> &'static str {
                match self {
                    $(JobMetric::$variant => $name,)*
                }
            }

            /// The SI unit of the value (`1` for a number without dimension).
            pub fn unit(self) -> &'static str {
                match self {
                    $(JobMetric::$variant => $unit,)*
                }
            }

            /// What the metric is, with the source of its definition.
            pub fn description(self) -> &'static str {
                match self {
                    $(JobMetric::$variant => $description,)*
                }
            }

            /// What it needs from the campaign and its scenario.
            pub fn needs(self) -> &'static [Need] {
                match self {
                    $(JobMetric::$variant => &[$(Need::$need),*],)*
                }
            }
        }
    };
}

job_metrics! {
    KineticEnergy => "kinetic_energy_j", "J", [],
        "total (translational + rotational) kinetic energy at the end";
    TranslationalKineticEnergy => "translational_kinetic_energy_j", "J", [],
        "translational kinetic energy at the end";
    BedTop => "bed_top_m", "m", [],
        "highest particle centre along -gravity at the end (bed or column height)";
    MeanHeight => "mean_height_m", "m", [],
        "mean particle centre height along -gravity at the end";
    CoordinationNumber => "coordination_number", "1", [],
        "mean particle-particle contacts per particle at the end";
    GranularTemperature => "granular_temperature_m2_per_s2", "m2/s2", [],
        "granular temperature at the end (seed 000 eq. 3.1)";
    IntensityOfSegregation => "intensity_of_segregation", "1", [MixingSpecies],
        "IS at the end: std. dev. of the local volume fraction of the mixing species (seed 000 eqs 2.77-2.78)";
    LaceyIndex => "lacey_index", "1", [MixingSpecies],
        "Lacey mixing index at the end (seed 000 eq. 2.80)";
    MixingRateConstant => "mixing_rate_constant_per_s", "1/s", [MixingSpecies],
        "k of an exponential fit to IS(t) (seed 000 §4.1.3)";
    MixingRateToRandom => "mixing_rate_to_random_per_s", "1/s", [MixingSpecies],
        "k of IS(t) = IS_R + b exp(-k t) with IS_R = sqrt(P(1-P)/n) the random mixture's IS (n particles per local sample): the approach to a random mixture";
    IntensityOfSegregationTimeAverage => "intensity_of_segregation_time_avg", "1", [MixingSpecies],
        "IS averaged over the mixing samples from analysis.average_from_s: the asymptotic state's segregation that seed 000 §4.2.2 compares wet against dry (Figs 52-53)";
    TimeTo90PctMaxLacey => "time_to_90pct_max_lacey_s", "s", [MixingSpecies],
        "first time the Lacey index reaches 90 % of its maximum (seed 000 Table 1)";
    ShearRate => "shear_rate_per_s", "1/s", [],
        "the steepest shear rate between neighbouring dense layers (one largest diameter thick) of the layer-averaged velocity along the flow, averaged over the series from analysis.average_from_s (seed 000 eq. 3.4, Figs 13 and 15c; also a series column); heights along the axis gravity is most along";
    CriticalFlipFrequency => "critical_flip_frequency_hz", "Hz", [TwoSpecies],
        "f_crit = 0.01 beta shear_rate (1 - rho_light/rho_heavy) (seed 000 eq. 3.5), beta = analysis.segregation_beta (default 0.1, the seed's fit)";
    FlipFrequencyRatio => "flip_frequency_ratio", "1", [TwoSpecies, GravityFlip],
        "the gravity flip frequency over f_crit (seed 000 Fig. 19's axis): above 1 the flips should outrun segregation";
    FlipRuleAgreement => "flip_rule_agreement", "1", [MixingSpecies, TwoSpecies, GravityFlip],
        "(IS - 0.25) sign(1 - f/f_crit) at the end: positive when the job lies on the side of seed 000 Fig. 19's rule its f/f_crit predicts (IS > 0.25 below f_crit, < 0.25 above), its size the margin";
    HeightMixingIndex => "height_mixing_index", "1", [],
        "seed 001's mixing index (§7.2.2) at the last series row: mean height of the particles that were at or above the bed's median height at analysis.height_families_at_s over that of the rest, heights from the domain's floor along -gravity; 3 segregated, 1 mixed (also a series column)";
    MeanHeightTimeAverage => "mean_height_time_avg_m", "m", [],
        "mean particle centre height along -gravity, averaged over the series from analysis.average_from_s (seed 002's mean particle height, 5-10 s)";
    CoordinationNumberTimeAverage => "coordination_number_time_avg", "1", [],
        "mean particle-particle contacts per particle, averaged over the series from analysis.average_from_s (seed 002 Fig. 5's bulk coordination number)";
    BedWeightPerArea => "bed_weight_per_area_pa", "Pa", [Gas],
        "weight of the particles over the inlet area, W/A (seed 000 eq. 2.74): what the pressure drop of a fluidized bed carries";
    PressureDropMean => "pressure_drop_mean_pa", "Pa", [Gas],
        "time-averaged pressure drop from the inlet face to the top layer of gas cells, from analysis.average_from_s";
    PressureDropStd => "pressure_drop_std_pa", "Pa", [Gas],
        "standard deviation of that pressure drop over the same window (its jump marks u_mf, seed 000 §4.1.2)";
    GranularBondNumber => "granular_bond_number", "1", [LiquidBridges],
        "Bo_g = F_c,max/W of the first species, F_c,max = 2πRγ cos θ (seed 000 §4.1.1)";
    GranularBondNumber22 => "granular_bond_number_22", "1", [LiquidBridges, TwoSpecies],
        "Bo_g of the second species";
    GranularBondNumber12 => "granular_bond_number_12", "1", [LiquidBridges, TwoSpecies],
        "Bo_g12: the 1-2 pair's F_c,max over the lighter particle's weight (seed 000 §4.2.1)";
    GranularCapillaryNumber => "granular_capillary_number", "1", [Gas, LiquidBridges],
        "Ca_g = F_c,max/F_d of the first species, Di Felice drag at slip U/ε (seed 000 eq. 4.3; analysis.capillary_number_porosity)";
    GranularCapillaryNumber22 => "granular_capillary_number_22", "1", [Gas, LiquidBridges, TwoSpecies],
        "Ca_g of the second species";
    GranularCapillaryNumber12 => "granular_capillary_number_12", "1", [Gas, LiquidBridges, TwoSpecies],
        "Ca_g12: the pair's F_c,max over the drag of the species with the larger F_d/W (seed 000 eqs. 4.4-4.5)";
    WetPhaseMixed => "wet_phase_mixed", "1", [Gas, LiquidBridges, TwoSpecies],
        "seed 000's phase rule on Ca_g11, Ca_g22, Ca_g12: 1 = more mixed than dry (M), 0 = more segregated (S)";
    DefluidizationVelocity => "defluidization_velocity_m_per_s", "m/s", [Gas, InflowLevels],
        "U_mf,df of a gas.inflow_levels cycle: the line through the falling branch's packed-bed level means meets W/A (seed 001 §6.4.2.1; with analysis.cycle_pressure: first_node, the first node's pressure drop against W'/A)";
    FluidizationVelocityTheoretical => "fluidization_velocity_theoretical_m_per_s", "m/s", [Gas, InflowLevels],
        "U_mf,th: the same on the rising branch";
    IncipientFluidizationVelocity => "incipient_fluidization_velocity_m_per_s", "m/s", [Gas, InflowLevels],
        "U_mf,in: the velocity of the overshoot peak, the rising branch's largest level-mean pressure drop before the first level whose mean falls (the bed gives way; seed 001: left of the bubbling region), when it exceeds W/A";
    PressureOvershootRatio => "pressure_overshoot_ratio", "1", [Gas, InflowLevels],
        "the overshoot peak (see incipient_fluidization_velocity_m_per_s) over W/A (above 1: an overshoot)";
    OvershootFluidForcePerWeight => "overshoot_fluid_force_per_weight", "1", [Gas, InflowLevels, NetForces],
        "the gas's force on all particles (its component against gravity) over their weight, averaged over the second half of the overshoot peak's level (see incipient_fluidization_velocity_m_per_s; the climb's top when there is no overshoot); seed 001 Figs 8.8-8.16";
    OvershootDistributorContactPerWeight => "overshoot_distributor_contact_per_weight", "1", [Gas, InflowLevels, NetForces],
        "the same for the contact force of the distributor (the plane walls facing against gravity)";
    OvershootDistributorCohesionPerWeight => "overshoot_distributor_cohesion_per_weight", "1", [Gas, InflowLevels, NetForces],
        "the same for the distributor's cohesion (negative: it holds the bed down)";
    OvershootSidewallFrictionPerWeight => "overshoot_sidewall_friction_per_weight", "1", [Gas, InflowLevels, NetForces],
        "the same for the sidewalls (plane walls parallel to gravity): their friction, with any tangential force of their cohesion (negative: they hold the bed down)";
    OvershootSidewallNormalLoadPerWeight => "overshoot_sidewall_normal_load_per_weight", "1", [Gas, InflowLevels, NetForces],
        "the same for the sidewalls' normal load: the size of their contact forces across gravity, summed over the sidewalls (in a pseudo-2-D bed exactly their normal load; in 3-D it also holds their horizontal friction); with μ, the friction they could give (the thesis: cohesion with the sidewalls only raises this load)";
    SteppedFluidizationVelocity => "stepped_fluidization_velocity_m_per_s", "m/s", [Gas, InflowLevels],
        "u_mf of a gas.inflow_levels run stepping the gas up: the slowest level of the rising branch from which the bed keeps moving (σ(ΔP) over the second half of each hold ≥ 1 % of W/A) at every faster level; NaN when the levels do not bracket the onset";
    CoatingVariability => "coating_variability", "1", [Spray],
        "CV_m = σ/μ of the particles' coating mass gain (seed 000 eq. 6.45): the liquid each holds (film, half of each particle bridge, its wall bridges) less its start, so liquid the bridges carried inward counts (§6.3.2)";
    CoatingVariabilityFitSlope => "coating_variability_fit_slope_sqrt_s", "s^1/2", [Spray],
        "slope of the least-squares line of CV_m against 1/√t, t the coating time since spray.start_s, over the series rows from analysis.coating_fit_from_s of coating time (seed 000 §6.3.2, eq. 6.46: CV_m ∝ 1/√t)";
    CoatingVariabilityFitIntercept => "coating_variability_fit_intercept", "1", [Spray],
        "that line's intercept (seed 000 Figs 85-86: through the origin for Bo_g < 1, positive for Bo_g > 1)";
    CoatingVariabilityFitInterceptStdError => "coating_variability_fit_intercept_std_error", "1", [Spray],
        "the intercept's standard error, s·√(1/n + x̄²/S_xx), with the series rows as the samples (they are correlated in time, so it is a lower bound)";
    CoatingVariabilityFitRSquared => "coating_variability_fit_r_squared", "1", [Spray],
        "R² of that line (seed 000 Fig. 85: 'a linear correlation' beyond 1 s)";
    MeanCollisionDuration => "mean_collision_duration_s", "s", [ContactStatistics],
        "mean duration of the particle-particle contacts that ended during the run (Hertz: t_c = 2.87 (m*^2/(R* E*^2 v))^(1/5))";
    MeanWallContactDuration => "mean_wall_contact_duration_s", "s", [ContactStatistics],
        "mean duration of the particle-wall contacts that ended during the run";
    WallContactTimeFraction => "wall_contact_time_fraction", "1", [ContactStatistics],
        "fraction of the run a particle spends touching a wall, mean over the particles";
    ProbePressureDropMean => "probe_pressure_drop_mean_pa", "Pa", [Gas, PressureProbe],
        "time-averaged pressure drop from the inlet to gas.pressure_probe_height_m";
    MeanTemperature => "mean_temperature_k", "K", [Heat],
        "the particles' mass-weighted mean temperature at the end";
    WallHeatTransferCoefficient => "wall_heat_transfer_coefficient_w_per_m2_k", "W/(m2 K)", [HeatedDrum],
        "h_w = c_p w (1 - exp(slope t_c))/(A t_c) (seed 000 eq. 5.21): slope of ln((T_w - <T_c>)/(T_w - T_0)) fitted from analysis.heating_fit_from_s (default: when the wall starts heating), <T_c> the core's temperature (heat.bed_core_radius_fraction), w the bed's mass, t_c = arc/omega and A = arc R L from the mean contact arc";
    WallHeatTransferCoefficientInnerCore => "wall_heat_transfer_coefficient_inner_core_w_per_m2_k", "W/(m2 K)", [HeatedDrum],
        "the same from the inner core (half the core's radius): seed 000 Fig. 69, the core region changes h_w";
    CoreHeatingSlope => "core_heating_slope_per_s", "1/s", [HeatedDrum],
        "the fitted slope of ln((T_w - <T_c>)/(T_w - T_0)) against t (seed 000 eq. 5.19, Fig. 70)";
    WallHeatTransferCoefficientBed => "wall_heat_transfer_coefficient_bed_w_per_m2_k", "W/(m2 K)", [HeatedDrum],
        "the same with the whole bed as the core: <T_c> the particles' mass-weighted mean temperature, so the fit is the bed's own energy balance w c_p dT/dt = h_w A (T_w - T) (seed 000 eq. 5.20); free of the lag with which heat reaches a core by mixing";
    BedHeatingSlope => "bed_heating_slope_per_s", "1/s", [HeatedDrum],
        "the fitted slope of ln((T_w - <T>)/(T_w - T_0)) against t with <T> the particles' mean temperature";
    DrumContactArc => "drum_contact_arc_rad", "rad", [HeatedDrum],
        "the angle of drum wall the bed touches, mean over the fit window";
    DrumWallContactTime => "drum_wall_contact_time_s", "s", [HeatedDrum],
        "t_c = arc/omega: how long a point of the wall stays under the bed (seed 000 eq. 5.18 read with the arc in rad and the speed in rev/s)";
    ConstantRateDryingRate => "constant_rate_drying_rate_per_s", "1/s", [Drying],
        "the drying rate -dX/dt of the constant-rate period (X the bed's moisture content, kg of liquid per kg of dry solid; seed 000 Figs. 91, 94): the fall of X over the longest stretch of series rows whose row-to-row rates stay positive and within 1.3x of each other, if it lasts at least a fifth of the drying time; NaN when there is none";
    ConstantRatePeriod => "constant_rate_period_s", "s", [Drying],
        "how long that constant-rate period lasts; 0 when the drying curve has none";
    TimeTo50PctDried => "time_to_50pct_dried_s", "s", [Drying],
        "when half of the start's liquid (on particles and in bridges) has gone, from the series; NaN if it has not by the end";
    TimeTo90PctDried => "time_to_90pct_dried_s", "s", [Drying],
        "when 90 % of the start's liquid has gone; NaN if it has not by the end";
    FinalMoistureContent => "final_moisture_content", "1", [Drying],
        "X at the end: the liquid on the particles and in bridges over the particles' dry mass, kg/kg";
    MinMeanParticleTemperature => "min_mean_particle_temperature_k", "K", [Drying],
        "the lowest mass-weighted mean particle temperature over the series rows (evaporative cooling, seed 000 Fig. 89c)";
    TimeOfMinMeanParticleTemperature => "time_of_min_mean_particle_temperature_s", "s", [Drying],
        "when that lowest mean temperature occurs";
    LiquidFractionEvaporated => "liquid_fraction_evaporated", "1", [Drying],
        "1 - X_end/X_0: the fraction of the start's liquid gone by the end (seed 000 Figs. 90, 93)";
    MoistureLargestRise => "moisture_largest_rise", "1", [Drying],
        "the largest rise of X from one series row to the next over X_0 (negative: the drying curve falls at every row; positive: vapour condensed back onto the bed somewhere in the run)";
    EvaporativeCooling => "evaporative_cooling_k", "K", [Drying],
        "the first row's mean particle temperature minus the lowest: how far evaporation cooled the bed before heat caught up (seed 000 Fig. 89c; 0 when it never fell)";
    TemperatureRiseAfterMinimum => "temperature_rise_after_minimum_k", "K", [Drying],
        "the last row's mean particle temperature minus the lowest: how far the bed warmed after its coldest moment";
    DryingLedgerClosure => "drying_ledger_closure_max", "1", [Drying],
        "the largest |(liquid + vapour in the gas + vapour gone out - vapour come in)/(start's liquid and vapour + sprayed) - 1| over the series rows: the mass balance of drying, a check (about 1e-13)";
    EnergyLedgerClosure => "energy_ledger_closure_max", "1", [Heat],
        "the largest |E_held/(E_start + heat in from walls and across the gas's boundary) - 1| over the series rows, E_held the particles' and gas's thermal energy plus the latent heat of the liquid evaporated (engine/heat_ledger.rs): the energy balance, a check";
}

impl JobMetric {
    /// The metric named `name`, as written by [`JobMetric::name`].
    pub fn from_name(name: &str) -> Option<JobMetric> {
        JobMetric::ALL.iter().copied().find(|m| m.name() == name)
    }
}

impl Serialize for JobMetric {
    fn serialize<S: Serializer>(&self, serializer: S) -> Result<S::Ok, S::Error> {
        serializer.serialize_str(self.name())
    }
}

impl<'de> Deserialize<'de> for JobMetric {
    fn deserialize<D: Deserializer<'de>>(deserializer: D) -> Result<Self, D::Error> {
        let name = Cow::<str>::deserialize(deserializer)?;
        JobMetric::from_name(&name).ok_or_else(|| serde::de::Error::custom(format!("unknown metric `{name}`")))
    }
}

impl schemars::JsonSchema for JobMetric {
    fn schema_name() -> Cow<'static, str> {
        "JobMetric".into()
    }

    fn json_schema(_: &mut schemars::SchemaGenerator) -> schemars::Schema {
        let names: Vec<&str> = JobMetric::ALL.iter().map(|m| m.name()).collect();
        schemars::json_schema!({
            "description": "A per-job metric by name (`granflow models` lists them with their units).",
            "type": "string",
            "enum": names,
        })
    }
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
    /// `output.contact_statistics` (contact durations and wall contact times).
    ContactStatistics,
    /// A `heat` section (particle temperatures).
    Heat,
    /// A `heat` section and one drum wall held at a temperature (a kiln).
    HeatedDrum,
    /// A `drying` section.
    Drying,
    /// Gravity with a flipping component (`gravity.flip`).
    GravityFlip,
}

impl Need {
    /// What the need asks for, as `granflow models` lists it.
    pub fn label(self) -> &'static str {
        match self {
            Need::MixingSpecies => "analysis.mixing_species",
            Need::Gas => "a gas",
            Need::PressureProbe => "gas.pressure_probe_height_m",
            Need::LiquidBridges => "liquid bridges",
            Need::TwoSpecies => "two species",
            Need::InflowLevels => "gas.inflow_levels",
            Need::Spray => "a spray",
            Need::NetForces => "output.net_forces",
            Need::ContactStatistics => "output.contact_statistics",
            Need::Heat => "heat transfer",
            Need::HeatedDrum => "a heated drum",
            Need::Drying => "drying",
            Need::GravityFlip => "gravity.flip",
        }
    }

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
            Need::ContactStatistics => unless(
                scenario.output.contact_statistics,
                format!("`{name}` needs `output.contact_statistics: true` (contact durations and wall contact times)"),
            ),
            Need::Heat => unless(
                scenario.heat.is_some(),
                format!("`{name}` needs heat transfer (a `heat:` section in the scenario)"),
            ),
            Need::Drying => unless(
                scenario.drying.is_some(),
                format!("`{name}` needs drying (a `drying:` section in the scenario)"),
            ),
            Need::GravityFlip => unless(
                scenario.gravity.flip.is_some(),
                format!("`{name}` needs a flipping gravity (`gravity: {{ ..., flip: {{ axis, frequency_hz }} }}`)"),
            ),
            Need::HeatedDrum => {
                let heated = scenario.heat.as_ref().map_or(0, |heat| {
                    scenario
                        .walls
                        .iter()
                        .filter(|w| match w {
                            WallSpec::Drum(d) => heat.walls.get(&d.name).is_some_and(|h| h.temperature_k.is_some()),
                            _ => false,
                        })
                        .count()
                });
                unless(
                    heated == 1,
                    format!(
                        "`{name}` needs one drum wall held at a temperature (`heat.walls.<drum>.temperature_k`); the \
                         scenario has {heated}"
                    ),
                )
            }
        }
    }
}

/// Checks the metric names and the analysis settings they need, and returns the metrics in the order listed;
/// errors are (key path, message).
pub fn check(spec: &CampaignSpec) -> Result<Vec<JobMetric>, (String, String)> {
    if spec.metrics.is_empty() {
        return Err(("metrics".into(), "expected at least one metric".into()));
    }
    let names: Vec<&str> = JobMetric::ALL.iter().map(|m| m.name()).collect();
    let mut metrics = Vec::with_capacity(spec.metrics.len());
    for (k, name) in spec.metrics.iter().enumerate() {
        let Some(m) = JobMetric::from_name(name) else {
            let hint = crate::util::did_you_mean(name, &names)
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
        if m.needs().contains(&Need::MixingSpecies) && spec.analysis.mixing_species.is_none() {
            return Err((
                format!("metrics[{k}]"),
                format!("`{name}` needs `analysis.mixing_species` (which species is A in the binary mixture)"),
            ));
        }
        metrics.push(m);
    }
    // Times inside the run at which an analysis starts or takes something.
    let a = &spec.analysis;
    for (key, time_s) in [
        ("average_from_s", a.average_from_s),
        ("mixing_fit_from_s", a.mixing_fit_from_s),
        ("heating_fit_from_s", a.heating_fit_from_s),
        ("height_families_at_s", a.height_families_at_s),
        ("coating_fit_from_s", a.coating_fit_from_s),
    ] {
        if let Some(t) = time_s
            && !(t.is_finite() && t >= 0.0 && t < spec.base.time.end_time_s)
        {
            return Err((
                format!("analysis.{key}"),
                format!(
                    "expected 0 <= value < the end time ({} s), got {t}",
                    spec.base.time.end_time_s
                ),
            ));
        }
    }
    if let Some(beta) = a.segregation_beta
        && !(beta.is_finite() && beta > 0.0)
    {
        return Err((
            "analysis.segregation_beta".into(),
            format!("expected a finite value > 0, got {beta}"),
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
    Ok(metrics)
}

/// Checks what depends on the resolved scenario (the mixing species must exist in it).
pub fn check_job(job: &JobSpec) -> Result<(), (String, String)> {
    for (k, metric) in job.metrics.iter().enumerate() {
        if let Some(message) = metric.needs().iter().find_map(|need| need.unmet(metric.name(), job)) {
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

#[cfg(test)]
mod tests {
    use super::JobMetric;

    /// Every metric round-trips through its name, in Rust, JSON (`job.json`, whose text makes the job id) and the
    /// schema; names are unique.
    #[test]
    fn every_metric_round_trips_through_its_name() {
        let mut seen = std::collections::HashSet::new();
        for &metric in JobMetric::ALL {
            assert!(seen.insert(metric.name()), "`{}` twice", metric.name());
            assert_eq!(JobMetric::from_name(metric.name()), Some(metric));
            let json = serde_json::to_string(&metric).unwrap();
            assert_eq!(json, format!("\"{}\"", metric.name()));
            assert_eq!(serde_json::from_str::<JobMetric>(&json).unwrap(), metric);
            assert!(!metric.unit().is_empty(), "{}", metric.name());
            assert!(!metric.description().is_empty(), "{}", metric.name());
        }
        assert_eq!(JobMetric::from_name("kinetic_energi_j"), None);
        let err = serde_json::from_str::<JobMetric>("\"kinetic_energi_j\"").unwrap_err();
        assert!(err.to_string().contains("unknown metric `kinetic_energi_j`"), "{err}");
    }

    #[test]
    fn the_schema_lists_every_name_in_order() {
        let schema = serde_json::to_value(schemars::schema_for!(JobMetric)).unwrap();
        let names: Vec<&str> = JobMetric::ALL.iter().map(|m| m.name()).collect();
        assert_eq!(schema["enum"], serde_json::json!(names), "{schema}");
    }
}
