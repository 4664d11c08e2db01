//! The closest known name to a misspelt one (Levenshtein distance), for the "did you mean `x`?" of error messages
//! about unknown keys, sweep paths and metric names.
//!
//! What does not live here: the messages themselves, which their modules word (`crate::scenario`'s YAML errors,
//! `crate::campaign::sweep`'s paths, `crate::campaign::metrics`' names).

/// The closest of `known` to `word` when it is close enough to be a likely typo: at most 2 edits, or a quarter of
/// the known name's length for long names.
pub fn did_you_mean<'a>(word: &str, known: &[&'a str]) -> Option<&'a str> {
    known
        .iter()
        .map(|k| (levenshtein(word, k), *k))
        .filter(|(d, k)| *d <= 2.max(k.len() / 4))
        .min()
        .map(|(_, k)| k)
}

/// The number of single-character insertions, deletions and substitutions that turn `a` into `b`.
fn levenshtein(a: &str, b: &str) -> usize {
    let b: Vec<char> = b.chars().collect();
    let mut prev: Vec<usize> = (0..=b.len()).collect();
    for (i, ca) in a.chars().enumerate() {
        let mut cur = vec![i + 1; b.len() + 1];
        for (j, cb) in b.iter().enumerate() {
            cur[j + 1] = (prev[j] + usize::from(ca != *cb)).min(prev[j + 1] + 1).min(cur[j] + 1);
        }
        prev = cur;
    }
    prev[b.len()]
}

#[cfg(test)]
mod tests {
    use super::{did_you_mean, levenshtein};

    #[test]
    fn levenshtein_counts_edits() {
        assert_eq!(levenshtein("", ""), 0);
        assert_eq!(levenshtein("seed", "sede"), 2);
        assert_eq!(levenshtein("kinetic_energi_j", "kinetic_energy_j"), 1);
        assert_eq!(levenshtein("abc", ""), 3);
        assert_eq!(levenshtein("γ", "g"), 1);
    }

    #[test]
    fn suggests_only_close_names() {
        let known = ["seed", "sweep", "metrics"];
        assert_eq!(did_you_mean("sede", &known), Some("seed"));
        assert_eq!(did_you_mean("metric", &known), Some("metrics"));
        assert_eq!(did_you_mean("executor", &known), None);
        assert_eq!(did_you_mean("x", &[]), None);
    }
}
