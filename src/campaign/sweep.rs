//! Expansion of a sweep tree into points: each point is an ordered list of (parameter path, value).
//!
//! Parameter paths address the base scenario as written: map keys separated by dots, list elements by index, e.g.
//! `walls[0].drum.rotation_rpm` (`walls.0.drum.rotation_rpm` is accepted too). Model variants are single-key maps,
//! so `contact.normal.hertz.restitution` reaches the Hertz restitution.

use serde_json::Value;

use super::spec::{Range, SweepNode};
use crate::util::did_you_mean;

/// One sweep point: the parameters it sets, in the order the sweep names them.
pub type Point = Vec<(String, Value)>;

/// A sweep error: the key path inside the campaign file and what is wrong there.
#[derive(Debug, Clone, PartialEq)]
pub struct SweepError {
    pub key: String,
    pub message: String,
}

fn fail(key: &str, message: impl Into<String>) -> SweepError {
    SweepError {
        key: key.to_string(),
        message: message.into(),
    }
}

/// How many points a sweep makes, counted from the tree without expanding anything.
#[derive(Debug, Clone, PartialEq)]
pub struct SweepSize {
    /// The number of points (saturating: a count beyond `u128::MAX` reads as `u128::MAX`).
    pub points: u128,
    /// The axis (a `param` or a `list`) with the most points, the first of equals: the key in the campaign file
    /// that sets its length (`sweep.grid[1].linspace.num`, `sweep.grid[0].values`, `sweep.list`) and that length.
    pub largest_axis: Option<(String, u128)>,
}

/// Counts the points of `node` (found at `key`) without materialising any: the product of a grid's children, the
/// length of a zip (its longest child: in a valid file all are equal) or a list, the number of values or `num` of
/// an axis. A malformed node (no kind, several kinds) counts as one point: [`expand`] reports it before it expands
/// anything.
pub fn count(node: &SweepNode, key: &str) -> SweepSize {
    let mut largest: Option<(String, u128)> = None;
    let points = count_node(node, key, &mut largest);
    SweepSize {
        points,
        largest_axis: largest,
    }
}

fn count_node(node: &SweepNode, key: &str, largest: &mut Option<(String, u128)>) -> u128 {
    let mut note = |at: String, n: u128| {
        if largest.as_ref().is_none_or(|(_, m)| n > *m) {
            *largest = Some((at, n));
        }
        n
    };
    match (&node.param, &node.grid, &node.zip, &node.list) {
        (Some(_), None, None, None) => match (&node.values, &node.linspace, &node.logspace) {
            (Some(v), None, None) => note(format!("{key}.values"), v.len() as u128),
            (None, Some(r), None) => note(format!("{key}.linspace.num"), r.num as u128),
            (None, None, Some(r)) => note(format!("{key}.logspace.num"), r.num as u128),
            _ => 1,
        },
        (None, Some(children), None, None) => children.iter().enumerate().fold(1u128, |n, (c, child)| {
            n.saturating_mul(count_node(child, &format!("{key}.grid[{c}]"), largest))
        }),
        (None, None, Some(children), None) => children
            .iter()
            .enumerate()
            .map(|(c, child)| count_node(child, &format!("{key}.zip[{c}]"), largest))
            .max()
            .unwrap_or(1),
        (None, None, None, Some(points)) => note(format!("{key}.list"), points.len() as u128),
        _ => 1,
    }
}

/// Expands `node` (found at `key` in the campaign file) into its points. A range of more than `max_points` points
/// is refused before anything is allocated (the caller checks the whole sweep's [`count`] first).
pub fn expand(node: &SweepNode, key: &str, max_points: usize) -> Result<Vec<Point>, SweepError> {
    expand_node(node, key, false, max_points)
}

/// As [`expand`]; `in_zip`: the node is a direct child of a zip, whose axes may repeat a value (the zipped
/// tuples must still differ, which the campaign checks as duplicate jobs).
fn expand_node(node: &SweepNode, key: &str, in_zip: bool, max_points: usize) -> Result<Vec<Point>, SweepError> {
    let kinds: Vec<&str> = [
        ("param", node.param.is_some()),
        ("grid", node.grid.is_some()),
        ("zip", node.zip.is_some()),
        ("list", node.list.is_some()),
    ]
    .iter()
    .filter(|(_, set)| *set)
    .map(|(name, _)| *name)
    .collect();
    if node.name.is_some() && node.param.is_none() {
        return Err(fail(
            &format!("{key}.name"),
            "`name` names a `param` axis; this node has no `param`",
        ));
    }
    if let Some(name) = &node.name
        && (name.is_empty() || !name.chars().all(|c| c.is_ascii_alphanumeric() || c == '_'))
    {
        return Err(fail(
            &format!("{key}.name"),
            format!("expected letters, digits and `_`, got `{name}`"),
        ));
    }
    match kinds.as_slice() {
        ["param"] => axis(node, key, in_zip, max_points),
        ["grid"] => grid(
            node.grid.as_deref().unwrap_or_default(),
            &format!("{key}.grid"),
            max_points,
        ),
        ["zip"] => zip(
            node.zip.as_deref().unwrap_or_default(),
            &format!("{key}.zip"),
            max_points,
        ),
        ["list"] => list(node.list.as_deref().unwrap_or_default(), &format!("{key}.list")),
        [] => Err(fail(
            key,
            "expected one of `param` (with `values`, `linspace` or `logspace`), `grid`, `zip` or `list`",
        )),
        several => Err(fail(
            key,
            format!(
                "expected exactly one of `param`, `grid`, `zip`, `list`; found {}",
                several.join(", ")
            ),
        )),
    }
}

/// The names given to axes (`name:` next to `param:`; an axis over a named set's members is named after the set
/// unless it says otherwise), as (canonical path, name).
pub fn axis_names(node: &SweepNode) -> Vec<(String, String)> {
    let mut out = Vec::new();
    if let Some(p) = &node.param
        && let Ok(p) = canonical_path(p)
    {
        let name = node
            .name
            .clone()
            .or_else(|| super::named::set_of(&p).map(str::to_string));
        if let Some(n) = name {
            out.push((p, n));
        }
    }
    for child in node.grid.iter().chain(&node.zip).flatten() {
        out.extend(axis_names(child));
    }
    out
}

/// Where each parameter path is set in the campaign file, as (canonical path, key of its `param` or of the `list`
/// point that sets it); the first place wins. Used to name the key when a path does not fit the base scenario.
pub fn param_keys(node: &SweepNode, key: &str) -> Vec<(String, String)> {
    let mut out = Vec::new();
    if let Some(p) = &node.param
        && let Ok(p) = canonical_path(p)
    {
        out.push((p, format!("{key}.param")));
    }
    for (c, child) in node.grid.iter().flatten().enumerate() {
        out.extend(param_keys(child, &format!("{key}.grid[{c}]")));
    }
    for (c, child) in node.zip.iter().flatten().enumerate() {
        out.extend(param_keys(child, &format!("{key}.zip[{c}]")));
    }
    for (k, point) in node.list.iter().flatten().enumerate() {
        for path in point.keys() {
            if let Ok(p) = canonical_path(path) {
                out.push((p, format!("{key}.list[{k}]")));
            }
        }
    }
    out
}

fn axis(node: &SweepNode, key: &str, allow_repeats: bool, max_points: usize) -> Result<Vec<Point>, SweepError> {
    let param = node.param.as_deref().unwrap_or_default();
    let param_key = format!("{key}.param");
    canonical_path(param).map_err(|m| fail(&param_key, m))?;
    let given: Vec<&str> = [
        ("values", node.values.is_some()),
        ("linspace", node.linspace.is_some()),
        ("logspace", node.logspace.is_some()),
    ]
    .iter()
    .filter(|(_, set)| *set)
    .map(|(name, _)| *name)
    .collect();
    if given.len() != 1 {
        return Err(fail(
            key,
            format!(
                "parameter `{param}`: expected exactly one of `values`, `linspace`, `logspace`, found {}",
                if given.is_empty() {
                    "none".to_string()
                } else {
                    given.join(", ")
                }
            ),
        ));
    }
    let values: Vec<Value> = if let Some(values) = &node.values {
        if values.is_empty() {
            return Err(fail(
                &format!("{key}.values"),
                "expected at least one value, got an empty list",
            ));
        }
        for (k, v) in values.iter().enumerate().filter(|_| !allow_repeats) {
            if let Some(first) = values[..k].iter().position(|w| w == v) {
                return Err(fail(
                    &format!("{key}.values[{k}]"),
                    format!("expected distinct values, got {v} twice (also at values[{first}]); remove the duplicate"),
                ));
            }
        }
        values.clone()
    } else if let Some(r) = &node.linspace {
        spaced(r, &format!("{key}.linspace"), false, max_points)?
    } else {
        let r = node.logspace.as_ref().expect("one of the three is set");
        spaced(r, &format!("{key}.logspace"), true, max_points)?
    };
    let path = canonical_path(param).expect("checked above");
    Ok(values.into_iter().map(|v| vec![(path.clone(), v)]).collect())
}

fn spaced(r: &Range, key: &str, geometric: bool, max_points: usize) -> Result<Vec<Value>, SweepError> {
    if !(r.start.is_finite() && r.stop.is_finite()) {
        return Err(fail(
            key,
            format!("expected finite start and stop, got {} and {}", r.start, r.stop),
        ));
    }
    if r.num == 0 {
        return Err(fail(&format!("{key}.num"), "expected at least one point, got 0"));
    }
    if r.num > max_points {
        return Err(fail(
            &format!("{key}.num"),
            format!("expected at most {max_points} points (max_jobs), got {}", r.num),
        ));
    }
    if geometric && !(r.start > 0.0 && r.stop > 0.0) {
        return Err(fail(
            key,
            format!(
                "expected start and stop > 0 for a geometric range, got {} and {}",
                r.start, r.stop
            ),
        ));
    }
    let n = r.num;
    let at = |k: usize| -> f64 {
        if n == 1 {
            return r.start;
        }
        if k == n - 1 {
            return r.stop;
        }
        let f = k as f64 / (n - 1) as f64;
        if geometric {
            r.start * (r.stop / r.start).powf(f)
        } else {
            r.start + (r.stop - r.start) * f
        }
    };
    (0..n)
        .map(|k| {
            serde_json::Number::from_f64(at(k))
                .map(Value::Number)
                .ok_or_else(|| fail(key, "the range produced a non-finite value"))
        })
        .collect()
}

fn grid(children: &[SweepNode], key: &str, max_points: usize) -> Result<Vec<Point>, SweepError> {
    if children.is_empty() {
        return Err(fail(key, "expected at least one sweep, got an empty list"));
    }
    let mut points: Vec<Point> = vec![Vec::new()];
    for (c, child) in children.iter().enumerate() {
        let child_points = expand(child, &format!("{key}[{c}]"), max_points)?;
        if points.len().saturating_mul(child_points.len()) > max_points {
            return Err(fail(
                key,
                format!("expands into more than {max_points} points (max_jobs)"),
            ));
        }
        let mut next = Vec::with_capacity(points.len() * child_points.len());
        for p in &points {
            for q in &child_points {
                let mut joined = p.clone();
                joined.extend(q.iter().cloned());
                next.push(joined);
            }
        }
        points = next;
    }
    Ok(points)
}

fn zip(children: &[SweepNode], key: &str, max_points: usize) -> Result<Vec<Point>, SweepError> {
    if children.is_empty() {
        return Err(fail(key, "expected at least one sweep, got an empty list"));
    }
    let expanded: Vec<Vec<Point>> = children
        .iter()
        .enumerate()
        .map(|(c, child)| expand_node(child, &format!("{key}[{c}]"), true, max_points))
        .collect::<Result<_, _>>()?;
    let len = expanded[0].len();
    if let Some((c, other)) = expanded.iter().enumerate().find(|(_, e)| e.len() != len) {
        return Err(fail(
            &format!("{key}[{c}]"),
            format!(
                "zip expects sweeps of equal length: {key}[0] has {len} points, this one {}",
                other.len()
            ),
        ));
    }
    Ok((0..len)
        .map(|k| expanded.iter().flat_map(|e| e[k].iter().cloned()).collect())
        .collect())
}

fn list(points: &[serde_json::Map<String, Value>], key: &str) -> Result<Vec<Point>, SweepError> {
    if points.is_empty() {
        return Err(fail(key, "expected at least one point, got an empty list"));
    }
    points
        .iter()
        .enumerate()
        .map(|(k, map)| {
            if map.is_empty() {
                return Err(fail(
                    &format!("{key}[{k}]"),
                    "expected a map of parameter paths to values, got {}",
                ));
            }
            map.iter()
                .map(|(path, v)| {
                    canonical_path(path)
                        .map(|p| (p, v.clone()))
                        .map_err(|m| fail(&format!("{key}[{k}]"), m))
                })
                .collect()
        })
        .collect()
}

/// One step of a parameter path.
#[derive(Debug, Clone, PartialEq, Eq)]
pub enum Segment {
    Key(String),
    Index(usize),
}

/// Parses `a.b[2].c` or `a.b.2.c` into segments.
pub fn parse_path(path: &str) -> Result<Vec<Segment>, String> {
    if path.trim().is_empty() {
        return Err("expected a parameter path such as `walls[0].drum.rotation_rpm`, got an empty string".into());
    }
    let mut out = Vec::new();
    for part in path.split('.') {
        let (name, mut rest) = match part.find('[') {
            Some(b) => (&part[..b], &part[b..]),
            None => (part, ""),
        };
        if name.is_empty() && rest.is_empty() {
            return Err(format!("parameter path `{path}` has an empty segment"));
        }
        if !name.is_empty() {
            match name.parse::<usize>() {
                Ok(i) => out.push(Segment::Index(i)),
                Err(_) => {
                    if !name.chars().all(|c| c.is_ascii_alphanumeric() || c == '_') {
                        return Err(format!("parameter path `{path}`: `{name}` is not a key"));
                    }
                    out.push(Segment::Key(name.to_string()));
                }
            }
        }
        while !rest.is_empty() {
            let close = rest
                .find(']')
                .ok_or_else(|| format!("parameter path `{path}`: missing `]`"))?;
            let index = rest[1..close]
                .parse::<usize>()
                .map_err(|_| format!("parameter path `{path}`: `{}` is not a list index", &rest[1..close]))?;
            out.push(Segment::Index(index));
            rest = &rest[close + 1..];
            if !rest.is_empty() && !rest.starts_with('[') {
                return Err(format!("parameter path `{path}`: expected `.` or `[` after `]`"));
            }
        }
    }
    Ok(out)
}

/// The canonical spelling of a path: keys joined by dots, indices in brackets.
pub fn canonical_path(path: &str) -> Result<String, String> {
    let mut s = String::new();
    for seg in parse_path(path)? {
        match seg {
            Segment::Key(k) => {
                if !s.is_empty() {
                    s.push('.');
                }
                s.push_str(&k);
            }
            Segment::Index(i) => s.push_str(&format!("[{i}]")),
        }
    }
    Ok(s)
}

/// Sets `path` in `doc` to `value`. Every segment must already exist (the base scenario, re-serialised, holds every
/// field including defaults), so a typo is an error listing what exists there instead of a silently ignored key.
pub fn set_path(doc: &mut Value, path: &str, value: Value) -> Result<(), String> {
    set_path_with_sections(doc, path, value, &[], false).map(|_| ())
}

/// As [`set_path`]; `optional_sections`: top-level keys a scenario may have that `doc` leaves out (they are listed
/// and suggested when a top-level key is unknown). With `insert_missing_last`, a last key that its (existing) map
/// lacks is added: a field left at its default, which the re-serialised base leaves out (`gas.vacuum`,
/// `heat.walls.drum.from_s`); the caller's deserialisation of the scenario then refuses a key it does not know.
/// Returns, when the key was added, the message for a key the scenario turns out not to know (what exists there,
/// with a did-you-mean).
pub fn set_path_with_sections(
    doc: &mut Value,
    path: &str,
    value: Value,
    optional_sections: &[String],
    insert_missing_last: bool,
) -> Result<Option<String>, String> {
    let segments = parse_path(path)?;
    let last = segments.len() - 1;
    let mut here = doc;
    let mut walked = String::new();
    for (depth, seg) in segments.into_iter().enumerate() {
        here = match seg {
            Segment::Key(k) => {
                let Value::Object(map) = here else {
                    return Err(format!(
                        "`{}` is {}, not a map with key `{k}`",
                        if walked.is_empty() { "the scenario" } else { &walked },
                        kind(here)
                    ));
                };
                if !map.contains_key(&k) {
                    let mut known: Vec<&str> = map.keys().map(|s| s.as_str()).collect();
                    if walked.is_empty() {
                        known.extend(
                            optional_sections
                                .iter()
                                .map(String::as_str)
                                .filter(|o| !map.contains_key(*o)),
                        );
                        known.sort_unstable();
                    }
                    let hint = did_you_mean(&k, &known)
                        .map(|s| format!("; did you mean `{s}`?"))
                        .unwrap_or_default();
                    let message = format!(
                        "the scenario has no `{k}` {} (there: {}){hint}",
                        if walked.is_empty() {
                            "at the top level".to_string()
                        } else {
                            format!("at `{walked}`")
                        },
                        known.join(", ")
                    );
                    if insert_missing_last && depth == last && !walked.is_empty() {
                        map.insert(k, value);
                        return Ok(Some(message));
                    }
                    return Err(message);
                }
                if !walked.is_empty() {
                    walked.push('.');
                }
                walked.push_str(&k);
                map.get_mut(&k).expect("checked")
            }
            Segment::Index(i) => {
                let Value::Array(items) = here else {
                    return Err(format!("`{walked}` is {}, not a list", kind(here)));
                };
                let len = items.len();
                if i >= len {
                    return Err(format!("`{walked}` has {len} element(s); index {i} is out of range"));
                }
                walked.push_str(&format!("[{i}]"));
                &mut items[i]
            }
        };
    }
    *here = value;
    Ok(None)
}

/// The value at `path` in `doc`, if there is one.
pub fn get_path<'a>(doc: &'a Value, path: &str) -> Option<&'a Value> {
    parse_path(path).ok()?.into_iter().try_fold(doc, |here, seg| match seg {
        Segment::Key(k) => here.get(k.as_str()),
        Segment::Index(i) => here.get(i),
    })
}

fn kind(v: &Value) -> &'static str {
    match v {
        Value::Null => "empty",
        Value::Bool(_) => "a boolean",
        Value::Number(_) => "a number",
        Value::String(_) => "a string",
        Value::Array(_) => "a list",
        Value::Object(_) => "a map",
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use serde_json::json;

    fn axis_node(param: &str, values: Vec<Value>) -> SweepNode {
        SweepNode {
            param: Some(param.into()),
            values: Some(values),
            ..Default::default()
        }
    }

    #[test]
    fn grid_is_the_cartesian_product_with_the_last_axis_fastest() {
        let node = SweepNode {
            grid: Some(vec![
                axis_node("a", vec![json!(1), json!(2)]),
                axis_node("b", vec![json!("x"), json!("y"), json!("z")]),
            ]),
            ..Default::default()
        };
        let points = expand(&node, "sweep", 100).unwrap();
        assert_eq!(points.len(), 6);
        assert_eq!(points[0], vec![("a".into(), json!(1)), ("b".into(), json!("x"))]);
        assert_eq!(points[1], vec![("a".into(), json!(1)), ("b".into(), json!("y"))]);
        assert_eq!(points[5], vec![("a".into(), json!(2)), ("b".into(), json!("z"))]);
    }

    #[test]
    fn zip_pairs_and_rejects_unequal_lengths() {
        let ok = SweepNode {
            zip: Some(vec![
                axis_node("a", vec![json!(1), json!(2)]),
                axis_node("b", vec![json!(3), json!(4)]),
            ]),
            ..Default::default()
        };
        assert_eq!(
            expand(&ok, "sweep", 100).unwrap()[1],
            vec![("a".into(), json!(2)), ("b".into(), json!(4))]
        );
        let bad = SweepNode {
            zip: Some(vec![
                axis_node("a", vec![json!(1), json!(2)]),
                axis_node("b", vec![json!(3)]),
            ]),
            ..Default::default()
        };
        let e = expand(&bad, "sweep", 100).unwrap_err();
        assert_eq!(e.key, "sweep.zip[1]");
    }

    #[test]
    fn linspace_and_logspace_hit_their_ends_exactly() {
        let lin = spaced(
            &Range {
                start: 1.0,
                stop: 2.0,
                num: 3,
            },
            "k",
            false,
            100,
        )
        .unwrap();
        assert_eq!(lin, vec![json!(1.0), json!(1.5), json!(2.0)]);
        let log = spaced(
            &Range {
                start: 0.01,
                stop: 1.0,
                num: 3,
            },
            "k",
            true,
            100,
        )
        .unwrap();
        assert_eq!(log[0], json!(0.01));
        assert!((log[1].as_f64().unwrap() - 0.1).abs() < 1e-15);
        assert_eq!(log[2], json!(1.0));
        assert!(
            spaced(
                &Range {
                    start: 0.0,
                    stop: 1.0,
                    num: 3
                },
                "k",
                true,
                100
            )
            .is_err()
        );
        assert_eq!(
            spaced(
                &Range {
                    start: 0.0,
                    stop: 1.0,
                    num: 0
                },
                "k",
                false,
                100
            )
            .unwrap_err()
            .key,
            "k.num"
        );
    }

    #[test]
    fn paths_parse_in_both_spellings() {
        assert_eq!(
            canonical_path("walls.0.drum.rotation_rpm").unwrap(),
            "walls[0].drum.rotation_rpm"
        );
        assert_eq!(
            canonical_path("fill[1].random.lo_m[2]").unwrap(),
            "fill[1].random.lo_m[2]"
        );
        assert!(canonical_path("a..b").is_err());
        assert!(canonical_path("a[x]").is_err());
        assert!(canonical_path("").is_err());
    }

    #[test]
    fn set_path_reports_missing_keys_with_a_suggestion() {
        let mut doc = json!({"walls": [{"drum": {"rotation_rpm": 1.0}}]});
        set_path(&mut doc, "walls[0].drum.rotation_rpm", json!(5.0)).unwrap();
        assert_eq!(doc["walls"][0]["drum"]["rotation_rpm"], json!(5.0));
        let e = set_path(&mut doc, "walls[0].drum.rotaton_rpm", json!(5.0)).unwrap_err();
        assert!(e.contains("did you mean `rotation_rpm`"), "{e}");
        let e = set_path(&mut doc, "walls[3].drum", json!(5.0)).unwrap_err();
        assert!(e.contains("out of range"), "{e}");
    }

    #[test]
    fn empty_and_ambiguous_nodes_are_rejected() {
        assert!(expand(&SweepNode::default(), "sweep", 100).is_err());
        let both = SweepNode {
            param: Some("a".into()),
            values: Some(vec![json!(1)]),
            grid: Some(vec![]),
            ..Default::default()
        };
        assert!(expand(&both, "sweep", 100).unwrap_err().message.contains("exactly one"));
        let empty = axis_node("a", vec![]);
        assert_eq!(expand(&empty, "sweep", 100).unwrap_err().key, "sweep.values");
    }
}
