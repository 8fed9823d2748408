//! Writing a developed film: the EXR (every layer, the number of passes in
//! the header), a tone-mapped PNG beside it (for photometric films instead
//! false-colour PNGs of luminance and illuminance with legends), BDPT's
//! strategy images, all through temporary files renamed into place.

use anyhow::{bail, Context, Result};
use candela_core::film::Developed;
use candela_core::image::falsecolor::{self, FalseColorScale};
use candela_core::image::{write_exr_layers, ExrAttributes};
use candela_core::render;
use std::path::{Path, PathBuf};

/// The EXR path for `outfile` (`.exr`, or `.png` meaning an EXR beside it);
/// any other extension is an error naming the flag or the scene parameter.
pub fn exr_path(outfile: &Path) -> Result<PathBuf> {
    let ext = outfile.extension().map(|e| e.to_ascii_lowercase());
    match ext.as_ref().and_then(|e| e.to_str()) {
        Some("exr") => Ok(outfile.to_path_buf()),
        Some("png") => Ok(outfile.with_extension("exr")),
        _ => bail!(
            "output file {} must end in .exr (a .png is written beside it)",
            outfile.display()
        ),
    }
}

/// Checks before rendering that `exr` can be written: its directory exists
/// (or is created) and accepts a file.
pub fn check_writable(exr: &Path) -> Result<()> {
    let dir = exr
        .parent()
        .filter(|d| !d.as_os_str().is_empty())
        .unwrap_or(Path::new("."));
    if dir.exists() && !dir.is_dir() {
        bail!(
            "cannot write {}: {} is not a directory",
            exr.display(),
            dir.display()
        );
    }
    std::fs::create_dir_all(dir).with_context(|| format!("creating {}", dir.display()))?;
    let probe = dir.join(format!(".candela-write-test-{}", std::process::id()));
    std::fs::write(&probe, b"")
        .with_context(|| format!("cannot write output files in {}", dir.display()))?;
    let _ = std::fs::remove_file(&probe);
    Ok(())
}

/// The EXR path for `outfile`, checked before rendering ([`exr_path`],
/// [`check_writable`]); errors start with `origin`, where the path came
/// from (`--outfile`, or the place of the Film's `"filename"`).
pub fn checked_exr(outfile: &Path, origin: &str) -> Result<PathBuf> {
    let exr = exr_path(outfile).with_context(|| origin.to_string())?;
    check_writable(&exr).with_context(|| origin.to_string())?;
    Ok(exr)
}

/// How the false-colour PNGs of photometric films are drawn.
#[derive(Clone, Copy, Debug)]
pub struct FalseColor {
    /// Log or linear.
    pub scale: FalseColorScale,
    /// Top of the scale (default: automatic per picture).
    pub max: Option<f64>,
}

/// Writes `OUTFILE.<layer>.png` for the luminance and illuminance layers.
fn write_falsecolor(dev: &Developed, exr: &Path, fc: &FalseColor) -> Result<()> {
    for (layer, unit) in [("luminance", "cd/m²"), ("illuminance", "lx")] {
        let Some(values) = dev.channel(&format!("{layer}.Y")) else {
            continue;
        };
        let max = fc.max.unwrap_or_else(|| falsecolor::auto_max(values));
        let pic = falsecolor::render(values, dev.width, dev.height, unit, fc.scale, max);
        falsecolor::write_png(&pic, &exr.with_extension(format!("{layer}.png")))?;
    }
    Ok(())
}

/// Writes the developed image as `exr` (every layer) and a PNG beside it
/// (false-colour PNGs for photometric films), and the strategy images
/// (`names[k]`) in the same directory.
pub fn write(
    dev: &Developed,
    exr: &Path,
    attrs: &ExrAttributes,
    strategy_names: &[Option<String>],
    fc: &FalseColor,
) -> Result<()> {
    write_exr_layers(exr, dev.width, dev.height, &render::exr_layers(dev), attrs)?;
    if dev.units.is_empty() {
        dev.rgb().write_png(&exr.with_extension("png"), 0.0)?;
    } else {
        write_falsecolor(dev, exr, fc)?;
    }
    let dir = exr.parent().unwrap_or(Path::new(""));
    for (img, name) in dev.strategies.iter().zip(strategy_names) {
        if let Some(name) = name {
            img.write_exr(&dir.join(name))?;
        }
    }
    Ok(())
}
