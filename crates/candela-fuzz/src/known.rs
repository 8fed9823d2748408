//! Findings already reported and not yet fixed, so that the short fuzz run
//! in the test suite fails only on new ones.
//!
//! `findings/known.txt` holds one entry a line: an outcome name (`panic`,
//! `abort`, `hang`), a space, and a substring of the failure signature
//! (for panics `panicked at <file>:<line>:<col>: <message>`, so the file
//! alone is a stable key). `#` starts a comment. Each entry should point
//! at a minimal scene in `findings/` and be deleted once fixed.

use crate::run::Outcome;

/// The list shipped with the crate.
pub const KNOWN: &str = include_str!("../findings/known.txt");

/// One allow-list entry.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct Known {
    /// The outcome it covers.
    pub outcome: Outcome,
    /// A substring of the signature.
    pub pattern: String,
}

/// Parses an allow-list; unknown outcome names are errors.
pub fn parse(text: &str) -> Result<Vec<Known>, String> {
    let mut out = Vec::new();
    for (n, line) in text.lines().enumerate() {
        let line = line.split('#').next().unwrap_or("").trim();
        if line.is_empty() {
            continue;
        }
        let (name, pattern) = line.split_once(' ').unwrap_or((line, ""));
        let outcome = Outcome::ALL
            .into_iter()
            .find(|o| o.name() == name)
            .ok_or_else(|| format!("known.txt:{}: unknown outcome '{name}'", n + 1))?;
        let pattern = pattern.trim();
        if pattern.is_empty() {
            return Err(format!("known.txt:{}: empty pattern", n + 1));
        }
        out.push(Known {
            outcome,
            pattern: pattern.to_string(),
        });
    }
    Ok(out)
}

/// Whether a failure is on the list.
pub fn is_known(list: &[Known], outcome: Outcome, signature: &str) -> bool {
    list.iter()
        .any(|k| k.outcome == outcome && signature.contains(&k.pattern))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_shipped_list_parses_and_matches_by_substring() {
        let list = parse(KNOWN).unwrap();
        let l = parse("# c\npanic src/shape/sphere.rs  # radius < 0\n\nhang time limit\n").unwrap();
        assert_eq!(l.len(), 2);
        assert!(is_known(
            &l,
            Outcome::Panic,
            "panicked at crates/x/src/shape/sphere.rs:3:1: m"
        ));
        assert!(!is_known(&l, Outcome::Abort, "src/shape/sphere.rs"));
        assert!(parse("crash x").is_err() && parse("panic").is_err());
        drop(list);
    }
}
