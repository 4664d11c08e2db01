//! Named sets of values: a campaign's `named:` section gives names to bundles of parameter values (a baffle layout,
//! a material), and a sweep takes those names as the values of the parameter `named.<set>`, so that one campaign
//! compares layouts × particle pairs × speeds without copying the base per layout.
//!
//! ```yaml
//! named:
//!   layout:
//!     unbaffled: { walls.0.drum.baffles: [] }
//!     one_axial:
//!       walls[0].drum.baffles: [ { axial: { count: 1, length_m: 0.05, half_thickness_m: 0.001 } } ]
//! sweep:
//!   grid:
//!     - { param: named.layout, values: [unbaffled, one_axial] }
//!     - { param: walls.0.drum.rotation_rpm, values: [6, 12] }
//! ```
//!
//! A job that takes a name gets exactly the scenario (and the seed) it would get with the member's values written
//! out in the sweep: the name is stored as the job's parameter (`layout = one_axial`, the set's name being the
//! axis name unless `name:` says otherwise), the member's values are what the scenario receives.

use std::collections::BTreeMap;

use serde_json::Value;

use super::sweep::{self, Point};
use crate::util::did_you_mean::did_you_mean;

/// The `named:` section: set name → member name → (parameter path → value).
pub type NamedSets = BTreeMap<String, BTreeMap<String, serde_json::Map<String, Value>>>;

/// The prefix of a sweep parameter that takes a set's member names.
pub const PREFIX: &str = "named.";

/// The set a sweep parameter takes its names from (`named.layout` → `layout`), or `None` for a scenario path.
pub fn set_of(param: &str) -> Option<&str> {
    param.strip_prefix(PREFIX)
}

/// One value a job's scenario receives: the parameter path, the value, the key of the campaign file that writes it
/// (for messages) and, for a member's value, the `named.<set>` parameter that brought it.
#[derive(Debug, Clone, PartialEq)]
pub struct Assignment {
    pub path: String,
    pub value: Value,
    pub key: String,
    pub via: Option<String>,
}

/// Checks the section as written: names of letters, digits and `_` (a member name may also hold `-`), at least one
/// member per set and one value per member, each path a parameter path of the scenario's form (whether it fits the
/// base is checked when the jobs are resolved) and none naming a set itself. Errors: (key, message).
pub fn check(named: &NamedSets) -> Result<(), (String, String)> {
    let word = |s: &str, extra: &[char]| {
        !s.is_empty()
            && s.chars()
                .all(|c| c.is_ascii_alphanumeric() || c == '_' || extra.contains(&c))
    };
    for (set, members) in named {
        let key = format!("named.{set}");
        if !word(set, &[]) {
            return Err((
                key,
                format!("expected a set name of letters, digits and `_`, got `{set}`"),
            ));
        }
        if members.is_empty() {
            return Err((
                key,
                "expected at least one named member (`name: { path: value }`)".into(),
            ));
        }
        for (member, values) in members {
            let key = format!("{key}.{member}");
            if !word(member, &['-']) {
                return Err((
                    key,
                    format!("expected a member name of letters, digits, `_` and `-`, got `{member}`"),
                ));
            }
            if values.is_empty() {
                return Err((key, "expected at least one parameter path and its value".into()));
            }
            for path in values.keys() {
                sweep::canonical_path(path).map_err(|m| (key.clone(), format!("`{path}`: {m}")))?;
                if set_of(path).is_some() {
                    return Err((
                        key,
                        format!("`{path}`: a named set's member cannot take another set's names"),
                    ));
                }
            }
        }
    }
    Ok(())
}

/// The values `point` gives a job's scenario: its own parameters, with each `named.<set>` parameter replaced by
/// the paths and values of the member it names, in the point's order. `param_keys` gives the key of the campaign
/// file that sets each of the point's parameters. Errors (key, message): a set the file does not define, a value
/// that is not one of its member names.
pub fn assignments(
    named: &NamedSets,
    point: &Point,
    param_keys: &std::collections::HashMap<String, String>,
) -> Result<Vec<Assignment>, (String, String)> {
    let mut out = Vec::with_capacity(point.len());
    for (param, value) in point {
        let key = param_keys.get(param).cloned().unwrap_or_else(|| "sweep".to_string());
        let Some(set) = set_of(param) else {
            out.push(Assignment {
                path: param.clone(),
                value: value.clone(),
                key,
                via: None,
            });
            continue;
        };
        let Some(members) = named.get(set) else {
            let known: Vec<&str> = named.keys().map(String::as_str).collect();
            let hint = did_you_mean(set, &known).map_or_else(
                || {
                    if known.is_empty() {
                        "the file has no `named:` section".to_string()
                    } else {
                        format!("the file defines {}", known.join(", "))
                    }
                },
                |k| format!("did you mean `{PREFIX}{k}`?"),
            );
            return Err((key, format!("parameter `{param}`: no named set `{set}`; {hint}")));
        };
        // The message belongs where the names are written: the axis's `values` (or the list point).
        let values_key = key
            .strip_suffix(".param")
            .map_or(key.clone(), |axis| format!("{axis}.values"));
        let known: Vec<&str> = members.keys().map(String::as_str).collect();
        let Some(name) = value.as_str() else {
            return Err((
                values_key,
                format!(
                    "parameter `{param}`: expected one of the names {}, got {value}",
                    known.join(", ")
                ),
            ));
        };
        let Some(member) = members.get(name) else {
            let hint = did_you_mean(name, &known).map_or_else(
                || format!("its members are {}", known.join(", ")),
                |k| format!("did you mean `{k}`?"),
            );
            return Err((
                values_key,
                format!("`{name}` is not a member of the named set `{set}`; {hint}"),
            ));
        };
        for (path, value) in member {
            out.push(Assignment {
                // As the sweep's own points spell paths, so that a member seeds as its values written out would.
                path: sweep::canonical_path(path).unwrap_or_else(|_| path.clone()),
                value: value.clone(),
                key: format!("named.{set}.{name}"),
                via: Some(param.clone()),
            });
        }
    }
    Ok(out)
}

#[cfg(test)]
mod tests {
    use super::*;
    use std::collections::HashMap;

    fn sets(yaml: &str) -> NamedSets {
        serde_norway::from_str(yaml).unwrap()
    }

    #[test]
    fn a_name_becomes_its_members_values_in_the_points_order() {
        let named = sets(
            "layout:\n  straight:\n    walls[0].drum.baffles: [1]\n    fill.0.lattice.spacing_m: 0.003\n  none: { walls.0.drum.baffles: [] }\n",
        );
        let point: Point = vec![("seed".into(), 3.into()), ("named.layout".into(), "straight".into())];
        let keys = HashMap::from([("named.layout".to_string(), "sweep.grid[0].param".to_string())]);
        let got = assignments(&named, &point, &keys).unwrap();
        let paths: Vec<(&str, Option<&str>)> = got.iter().map(|a| (a.path.as_str(), a.via.as_deref())).collect();
        // BTreeMap order inside the member (paths sorted), after the point's own parameters before it.
        assert_eq!(
            paths,
            [
                ("seed", None),
                ("fill[0].lattice.spacing_m", Some("named.layout")),
                ("walls[0].drum.baffles", Some("named.layout"))
            ]
        );
        assert_eq!(got[2].key, "named.layout.straight");
    }

    #[test]
    fn unknown_sets_and_members_are_named_where_they_are_written() {
        let named = sets("layout:\n  straight: { walls.0.drum.baffles: [1] }\n");
        let keys = HashMap::from([("named.layout".to_string(), "sweep.grid[0].param".to_string())]);
        let (key, message) = assignments(&named, &vec![("named.layout".into(), "straigt".into())], &keys).unwrap_err();
        assert_eq!(key, "sweep.grid[0].values");
        assert!(message.contains("did you mean `straight`"), "{message}");
        let (key, message) = assignments(
            &named,
            &vec![("named.layuot".into(), "straight".into())],
            &HashMap::new(),
        )
        .unwrap_err();
        assert_eq!(key, "sweep");
        assert!(message.contains("did you mean `named.layout`"), "{message}");
        let (_, message) = assignments(&named, &vec![("named.layout".into(), 2.into())], &keys).unwrap_err();
        assert!(message.contains("expected one of the names straight"), "{message}");
    }

    #[test]
    fn the_section_is_checked_as_written() {
        assert!(check(&sets("layout:\n  a-1: { walls.0.drum.baffles: [] }\n")).is_ok());
        let bad = [
            ("lay out:\n  a: { x: 1 }\n", "named.lay out"),
            ("layout: {}\n", "named.layout"),
            ("layout:\n  a b: { x: 1 }\n", "named.layout.a b"),
            ("layout:\n  a: {}\n", "named.layout.a"),
            ("layout:\n  a: { 'walls[x]': 1 }\n", "named.layout.a"),
            ("layout:\n  a: { named.other: b }\n", "named.layout.a"),
        ];
        for (yaml, at) in bad {
            assert_eq!(check(&sets(yaml)).unwrap_err().0, at, "{yaml}");
        }
    }
}
