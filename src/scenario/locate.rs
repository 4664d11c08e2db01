//! Where a key path (`base.species[0].radius_m`) stands in a YAML text: the line and column of its value, so that
//! a value that parses but is not valid is reported at its line, as a syntax error is.
//!
//! The YAML parser is serde_norway's own: a visitor walks down the path, skipping every other value, and fails on
//! purpose at the node the path names; serde_norway marks that failure with the node's position.

use serde::de::{self, DeserializeSeed, Deserializer, IgnoredAny, MapAccess, SeqAccess, Visitor};

/// One step of a key path: a mapping key or a sequence index.
#[derive(Debug, Clone, PartialEq)]
enum Segment<'a> {
    Key(&'a str),
    Index(usize),
}

/// Splits `a.b[2].c` into `a`, `b`, `[2]`, `c`; `None` for a path that is not of that form.
fn segments(key: &str) -> Option<Vec<Segment<'_>>> {
    let mut out = Vec::new();
    for part in key.split('.') {
        let (name, mut rest) = part.split_at(part.find('[').unwrap_or(part.len()));
        if name.is_empty() && (out.is_empty() || !rest.starts_with('[')) {
            return None;
        }
        if !name.is_empty() {
            out.push(Segment::Key(name));
        }
        while let Some(inner) = rest.strip_prefix('[') {
            let end = inner.find(']')?;
            out.push(Segment::Index(inner[..end].parse().ok()?));
            rest = &inner[end + 1..];
        }
        if !rest.is_empty() {
            return None;
        }
    }
    Some(out)
}

/// The failure the walk raises at the node it looks for (never shown to anyone).
const FOUND: &str = "granflow: located";

/// The 1-based line and column of the value at `key` in `yaml`. A key that is not written in the text (a default,
/// or a value set by a sweep) is located at its nearest written parent; `None` if not even the first step is
/// written. Meant for text that has parsed: in broken text the answer is the walk's best effort.
pub fn locate(yaml: &str, key: &str) -> Option<(usize, usize)> {
    let path = segments(key)?;
    (1..=path.len()).rev().find_map(|n| locate_exact(yaml, &path[..n]))
}

fn locate_exact(yaml: &str, path: &[Segment<'_>]) -> Option<(usize, usize)> {
    let error = Seek(path)
        .deserialize(serde_norway::Deserializer::from_str(yaml))
        .err()?;
    if !error.to_string().contains(FOUND) {
        return None;
    }
    error.location().map(|l| (l.line(), l.column()))
}

/// Walks down `self.0` from the node it is given.
struct Seek<'p, 'a>(&'p [Segment<'a>]);

impl<'de> DeserializeSeed<'de> for Seek<'_, '_> {
    type Value = ();

    fn deserialize<D: Deserializer<'de>>(self, deserializer: D) -> Result<(), D::Error> {
        deserializer.deserialize_any(self)
    }
}

impl Seek<'_, '_> {
    /// At a scalar: found if the path ends here; a path that goes on into a scalar is not in the text.
    fn scalar<E: de::Error>(&self) -> Result<(), E> {
        if self.0.is_empty() {
            Err(E::custom(FOUND))
        } else {
            Ok(())
        }
    }
}

impl<'de> Visitor<'de> for Seek<'_, '_> {
    type Value = ();

    fn expecting(&self, f: &mut std::fmt::Formatter) -> std::fmt::Result {
        f.write_str("any YAML value")
    }

    fn visit_bool<E: de::Error>(self, _: bool) -> Result<(), E> {
        self.scalar()
    }
    fn visit_i64<E: de::Error>(self, _: i64) -> Result<(), E> {
        self.scalar()
    }
    fn visit_u64<E: de::Error>(self, _: u64) -> Result<(), E> {
        self.scalar()
    }
    fn visit_f64<E: de::Error>(self, _: f64) -> Result<(), E> {
        self.scalar()
    }
    fn visit_str<E: de::Error>(self, _: &str) -> Result<(), E> {
        self.scalar()
    }
    fn visit_unit<E: de::Error>(self) -> Result<(), E> {
        self.scalar()
    }
    fn visit_none<E: de::Error>(self) -> Result<(), E> {
        self.scalar()
    }

    fn visit_map<A: MapAccess<'de>>(self, mut map: A) -> Result<(), A::Error> {
        let (wanted, rest) = match self.0.split_first() {
            None => return Err(de::Error::custom(FOUND)),
            Some((Segment::Key(k), rest)) => (Some(*k), rest),
            Some((Segment::Index(_), rest)) => (None, rest),
        };
        while let Some(name) = map.next_key::<serde_norway::Value>()? {
            if wanted.is_some() && name.as_str() == wanted {
                map.next_value_seed(Seek(rest))?;
            } else {
                map.next_value::<IgnoredAny>()?;
            }
        }
        Ok(())
    }

    fn visit_seq<A: SeqAccess<'de>>(self, mut seq: A) -> Result<(), A::Error> {
        let (wanted, rest) = match self.0.split_first() {
            None => return Err(de::Error::custom(FOUND)),
            Some((Segment::Index(i), rest)) => (Some(*i), rest),
            Some((Segment::Key(_), rest)) => (None, rest),
        };
        let mut index = 0;
        loop {
            let more = if Some(index) == wanted {
                seq.next_element_seed(Seek(rest))?
            } else {
                seq.next_element::<IgnoredAny>()?.map(|_| ())
            };
            if more.is_none() {
                return Ok(());
            }
            index += 1;
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    const TEXT: &str = "\
name: demo
base:
  species:
    - { name: a, radius_m: 0.001 }
    - name: b
      radius_m: -0.0015
  time: { end_time_s: 1.0 }
sweep:
  grid:
    - param: walls[0].drum.rotation_rpm
      values: [15, 30]
metrics: [lacey_index]
";

    #[test]
    fn finds_values_in_block_and_flow_style() {
        assert_eq!(locate(TEXT, "name"), Some((1, 7)));
        assert_eq!(locate(TEXT, "base.species[1].radius_m"), Some((6, 17)));
        assert_eq!(locate(TEXT, "base.species[0].radius_m"), Some((4, 28)));
        assert_eq!(locate(TEXT, "base.time.end_time_s"), Some((7, 23)));
        assert_eq!(locate(TEXT, "sweep.grid[0].param"), Some((10, 14)));
        assert_eq!(locate(TEXT, "metrics[0]"), Some((12, 11)));
    }

    #[test]
    fn a_key_not_written_is_located_at_its_nearest_written_parent() {
        // `poisson_ratio` is a default: the species it belongs to is where to look.
        assert_eq!(
            locate(TEXT, "base.species[1].poisson_ratio"),
            locate(TEXT, "base.species[1]")
        );
        assert_eq!(locate(TEXT, "base.species[7].radius_m"), locate(TEXT, "base.species"));
        assert_eq!(locate(TEXT, "executor.local.max_parallel"), None);
        assert_eq!(locate("", "a"), None);
        assert_eq!(locate(TEXT, "base..x"), None);
    }

    #[test]
    fn splits_key_paths() {
        assert_eq!(
            segments("a.b[2][3].c"),
            Some(vec![
                Segment::Key("a"),
                Segment::Key("b"),
                Segment::Index(2),
                Segment::Index(3),
                Segment::Key("c")
            ])
        );
        assert_eq!(
            segments("derived[0]"),
            Some(vec![Segment::Key("derived"), Segment::Index(0)])
        );
        assert_eq!(segments("a[x]"), None);
        assert_eq!(segments("[0]"), None);
    }
}
