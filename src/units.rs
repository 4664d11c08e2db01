//! A quantity's unit, read from the SI suffix its name carries by the project's naming rule (`radius_m`,
//! `wall_temperature_k`, `superficial_velocity_m_per_s`): the pictures' axis captions and the `units` attribute of
//! `series.h5`'s columns.

/// Suffixes and their units, longest first so that `_m_per_s` wins over `_s`.
const SUFFIXES: &[(&str, &str)] = &[
    ("_kg_per_m3", "kg/m³"),
    ("_n_per_m", "N/m"),
    ("_m_per_s2", "m/s²"),
    ("_m_per_s", "m/s"),
    ("_w_per_m_k", "W/(m K)"),
    ("_w_per_m2_k", "W/(m² K)"),
    ("_j_per_kg_k", "J/(kg K)"),
    ("_j_per_kg", "J/kg"),
    ("_kg_per_s", "kg/s"),
    ("_per_s", "1/s"),
    ("_pa_s", "Pa s"),
    ("_rpm", "rpm"),
    ("_deg", "°"),
    ("_rad", "rad"),
    ("_kg", "kg"),
    ("_m3", "m³"),
    ("_m2", "m²"),
    ("_pa", "Pa"),
    ("_hz", "Hz"),
    ("_k", "K"),
    ("_sqrt_s", "s^1/2"),
    ("_s", "s"),
    ("_m", "m"),
    ("_n", "N"),
    ("_j", "J"),
    ("_w", "W"),
];

/// The unit of a parameter named `name` (its last path segment's suffix), `None` when it carries none
/// (dimensionless or a name such as `material`).
pub fn parameter_unit(name: &str) -> Option<&'static str> {
    let last = name.rsplit(['.', ']']).next().unwrap_or(name).to_ascii_lowercase();
    SUFFIXES
        .iter()
        .find(|(suffix, _)| last.ends_with(suffix))
        .map(|&(_, unit)| unit)
}

/// `name [unit]`, or the name alone without a unit.
pub fn caption(name: &str, unit: Option<&str>) -> String {
    match unit.filter(|u| !u.is_empty() && *u != "1") {
        Some(unit) => format!("{name} [{unit}]"),
        None => name.to_string(),
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn units_come_from_the_si_suffix() {
        assert_eq!(parameter_unit("radius_j_m"), Some("m"));
        assert_eq!(parameter_unit("heat.walls.drum.temperature_k"), Some("K"));
        assert_eq!(parameter_unit("walls[0].drum.rotation_rpm"), Some("rpm"));
        assert_eq!(parameter_unit("gas.inlet_velocity_m_per_s"), Some("m/s"));
        assert_eq!(parameter_unit("species[1].contact_angle_deg"), Some("°"));
        assert_eq!(parameter_unit("material"), None);
        assert_eq!(caption("radius_j_m", Some("m")), "radius_j_m [m]");
        assert_eq!(caption("mixing_index", Some("1")), "mixing_index");
    }
}
