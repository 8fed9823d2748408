//! `candela info`: what a built scene contains, as text.

use candela_core::build::{Counts, SceneSummary};
use std::fmt::Write;

/// `total: a 1, b 2` (or `0`).
fn counts_line(c: &Counts) -> String {
    let total: usize = c.values().sum();
    if total == 0 {
        return "0".to_string();
    }
    let parts: Vec<String> = c.iter().map(|(k, v)| format!("{k} {v}")).collect();
    format!("{total} ({})", parts.join(", "))
}

/// The summary as `candela info` prints it.
pub fn format_summary(s: &SceneSummary) -> String {
    let mut f = String::new();
    write_summary(&mut f, s).unwrap_or_default();
    f
}

fn write_summary(f: &mut String, s: &SceneSummary) -> std::fmt::Result {
    writeln!(f, "camera      {}", s.camera)?;
    writeln!(f, "film        {}", s.film)?;
    writeln!(f, "sampler     {}", s.sampler)?;
    writeln!(f, "integrator  {}", s.integrator)?;
    writeln!(f, "shapes      {}", counts_line(&s.shapes))?;
    if s.instances > 0 {
        writeln!(f, "instances   {}", s.instances)?;
    }
    writeln!(f, "primitives  {}", counts_line(&s.primitives))?;
    writeln!(f, "triangles   {}", s.triangles)?;
    writeln!(f, "lights      {}", counts_line(&s.lights))?;
    let (mut watts, mut lumens) = (0.0, 0.0);
    for (kind, flux) in &s.light_flux {
        writeln!(
            f,
            "  flux      {kind}: {:.6} W, {:.6} lm",
            flux.watts, flux.lumens
        )?;
        watts += flux.watts;
        lumens += flux.lumens;
    }
    if !s.light_flux.is_empty() {
        writeln!(f, "  flux      total: {watts:.6} W, {lumens:.6} lm")?;
    }
    writeln!(f, "materials   {}", counts_line(&s.materials))?;
    writeln!(f, "textures    {}", counts_line(&s.textures))?;
    if let Some((lo, hi)) = s.bounds {
        writeln!(f, "bounds      {lo:?} – {hi:?}")?;
    }
    writeln!(f, "warnings    {}", s.warnings.len())?;
    for w in &s.warnings {
        writeln!(f, "  {w}")?;
    }
    Ok(())
}
