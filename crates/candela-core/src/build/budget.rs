//! Memory budget of a render, checked at build time before the large
//! allocations are made.
//!
//! Each structure whose size the settings decide is estimated from them and
//! claimed against one limit: `--memory-limit`, else 75 % of the physical
//! memory (`MemTotal` of `/proc/meminfo`; 8 GiB where that cannot be read).
//! A claim that takes the total past the limit is an error naming the
//! structure, its estimate, the total and the parameter to change. The
//! estimates are the dominant terms of each structure (bytes per element
//! times the element count the settings imply), not exact sizes.

use std::fmt;

/// Share of physical memory a render may use by default.
pub const DEFAULT_SHARE: f64 = 0.75;

/// Limit used where the physical memory cannot be read.
const FALLBACK_LIMIT: u64 = 8 << 30;

/// Bytes as a short decimal quantity (`1.5 GB`).
pub struct Bytes(pub u64);

impl fmt::Display for Bytes {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        let b = self.0 as f64;
        for (unit, scale) in [("TB", 1e12), ("GB", 1e9), ("MB", 1e6), ("kB", 1e3)] {
            if b >= scale {
                return write!(f, "{:.1} {unit}", b / scale);
            }
        }
        write!(f, "{} bytes", self.0)
    }
}

/// Parses a memory size: a number with an optional unit (`k`, `M`, `G`, `T`
/// for powers of 1000, `Ki`, `Mi`, `Gi`, `Ti` for powers of 1024, optionally
/// followed by `B`), or a share of physical memory (`50%`).
pub fn parse_memory(s: &str) -> Result<u64, String> {
    let t = s.trim();
    let bad = || format!("expected a size such as 4G, 512MiB or 50%, found {s:?}");
    if let Some(pct) = t.strip_suffix('%') {
        let p: f64 = pct.trim().parse().map_err(|_| bad())?;
        if !(p > 0.0 && p <= 100.0) {
            return Err(format!(
                "a share of memory must lie in (0, 100] %, found {s:?}"
            ));
        }
        return Ok((physical_memory().unwrap_or(FALLBACK_LIMIT) as f64 * p / 100.0) as u64);
    }
    let t = t.strip_suffix(['B', 'b']).unwrap_or(t);
    let split = t
        .find(|c: char| !(c.is_ascii_digit() || c == '.'))
        .unwrap_or(t.len());
    let (num, unit) = t.split_at(split);
    let x: f64 = num.parse().map_err(|_| bad())?;
    let scale = match unit.trim() {
        "" => 1.0,
        "k" | "K" => 1e3,
        "M" | "m" => 1e6,
        "G" | "g" => 1e9,
        "T" | "t" => 1e12,
        "Ki" => 1024.0,
        "Mi" => 1024.0 * 1024.0,
        "Gi" => 1024.0 * 1024.0 * 1024.0,
        "Ti" => 1024.0f64.powi(4),
        _ => return Err(bad()),
    };
    let bytes = x * scale;
    if !(1.0..1e18).contains(&bytes) {
        return Err(bad());
    }
    Ok(bytes as u64)
}

/// `MemTotal` of `/proc/meminfo` in bytes.
pub fn physical_memory() -> Option<u64> {
    let text = std::fs::read_to_string("/proc/meminfo").ok()?;
    let line = text.lines().find(|l| l.starts_with("MemTotal:"))?;
    let kb: u64 = line.split_whitespace().nth(1)?.parse().ok()?;
    Some(kb * 1024)
}

/// Running total of the claims against a limit.
#[derive(Clone, Debug)]
pub struct Budget {
    limit: u64,
    /// `--memory-limit` gave the limit (else the default share).
    from_flag: bool,
    used: u64,
    /// Each claim: what and bytes, for `candela info`.
    claims: Vec<(String, u64)>,
}

impl Budget {
    /// The budget of `--memory-limit`, or the default share of memory.
    pub fn new(limit: Option<u64>) -> Self {
        Budget {
            limit: limit.unwrap_or_else(|| {
                (physical_memory().unwrap_or(FALLBACK_LIMIT) as f64 * DEFAULT_SHARE) as u64
            }),
            from_flag: limit.is_some(),
            used: 0,
            claims: Vec::new(),
        }
    }

    /// The limit in bytes.
    pub fn limit(&self) -> u64 {
        self.limit
    }

    /// Bytes claimed so far.
    pub fn used(&self) -> u64 {
        self.used
    }

    /// The claims so far.
    pub fn claims(&self) -> &[(String, u64)] {
        &self.claims
    }

    /// Adds `bytes` for `what`; past the limit, the message names `what`
    /// and says to change `fix`.
    pub fn claim(&mut self, bytes: u64, what: &str, fix: &str) -> Result<(), String> {
        let total = self.used.saturating_add(bytes);
        if total > self.limit {
            let limit = if self.from_flag {
                format!("the --memory-limit of {}", Bytes(self.limit))
            } else {
                format!(
                    "the memory limit of {} ({:.0}% of physical memory; set --memory-limit to change it)",
                    Bytes(self.limit),
                    DEFAULT_SHARE * 100.0
                )
            };
            let before = if self.used > 0 {
                format!(" ({} in all)", Bytes(total))
            } else {
                String::new()
            };
            return Err(format!(
                "needs about {} for {what}{before}, over {limit}: {fix}",
                Bytes(bytes)
            ));
        }
        self.used = total;
        self.claims.push((what.to_string(), bytes));
        Ok(())
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn sizes_parse_with_units() {
        assert_eq!(parse_memory("1500"), Ok(1500));
        assert_eq!(parse_memory("4G"), Ok(4_000_000_000));
        assert_eq!(parse_memory("4GB"), Ok(4_000_000_000));
        assert_eq!(parse_memory("512MiB"), Ok(512 << 20));
        assert_eq!(parse_memory("1.5k"), Ok(1500));
        assert!(parse_memory("50%").is_ok_and(|b| b > 0));
        for bad in ["", "G", "-1G", "4X", "0", "nan", "inf", "150%", "0%"] {
            assert!(parse_memory(bad).is_err(), "{bad}");
        }
    }

    #[test]
    fn a_claim_past_the_limit_names_the_structure_and_the_fix() {
        let mut b = Budget::new(Some(1000));
        assert!(b.claim(600, "the film", "lower the resolution").is_ok());
        let err = b
            .claim(500, "the photon map", "lower \"photons\"")
            .unwrap_err();
        assert!(
            err.contains("500 bytes for the photon map (1.1 kB in all)"),
            "{err}"
        );
        assert!(
            err.contains("--memory-limit of 1.0 kB: lower \"photons\""),
            "{err}"
        );
        assert_eq!(b.used(), 600);
    }
}
