//! The settings text stored in a [`super::RenderState`]: the overrides that
//! decide a render's passes (`--spp`, `--integrator`, `--seed`,
//! `--cropwindow`, `--aov`, `--units`) as `key=value` lines, so that whoever merges or resumes
//! the state rebuilds the same render. The format is the command line's
//! (`candela render` writes it, `candela merge` reads it): a state made by
//! the library, the Python module or a cluster merges with the CLI's.

use crate::build::Overrides;
use crate::film::Aov;

/// The settings of `ov` that decide a render's passes, as `key=value` lines
/// (the output path is not one of them).
pub fn settings_text(ov: &Overrides) -> String {
    let mut s = String::new();
    if let Some(v) = ov.spp {
        s.push_str(&format!("spp={v}\n"));
    }
    if let Some(v) = &ov.integrator {
        s.push_str(&format!("integrator={v}\n"));
    }
    if let Some(v) = ov.seed {
        s.push_str(&format!("seed={v}\n"));
    }
    if let Some([a, b, c, d]) = ov.cropwindow {
        s.push_str(&format!("cropwindow={a:?},{b:?},{c:?},{d:?}\n"));
    }
    if !ov.aovs.is_empty() {
        s.push_str(&format!("aov={}\n", Aov::list_text(&ov.aovs)));
    }
    if ov.photometric {
        s.push_str("units=photometric\n");
    }
    s
}

/// The overrides that [`settings_text`] wrote, or what is wrong with `text`.
pub fn overrides_from_settings(text: &str) -> Result<Overrides, String> {
    let mut ov = Overrides::default();
    for line in text.lines() {
        let (k, v) = line
            .split_once('=')
            .ok_or_else(|| format!("malformed setting {line:?}"))?;
        let bad = |e: &dyn std::fmt::Display| format!("setting {k}={v:?}: {e}");
        match k {
            "spp" => ov.spp = Some(v.parse().map_err(|e| bad(&e))?),
            "integrator" => ov.integrator = Some(v.to_string()),
            "seed" => ov.seed = Some(v.parse().map_err(|e| bad(&e))?),
            "cropwindow" => ov.cropwindow = Some(parse_cropwindow(v).map_err(|e| bad(&e))?),
            "aov" => ov.aovs = Aov::parse_list(v).map_err(|e| bad(&e))?,
            "units" if v == "photometric" => ov.photometric = true,
            _ => return Err(format!("unknown setting {k:?}")),
        }
    }
    Ok(ov)
}

/// Parses "x0,x1,y0,y1" with 0 ≤ x0 < x1 ≤ 1 and 0 ≤ y0 < y1 ≤ 1.
pub fn parse_cropwindow(s: &str) -> Result<[f32; 4], String> {
    let v: Vec<f32> = s
        .split(',')
        .map(|t| t.trim().parse::<f32>().map_err(|e| format!("{t:?}: {e}")))
        .collect::<Result<_, _>>()?;
    let unit = |a: f32, b: f32| (0.0..=1.0).contains(&a) && (0.0..=1.0).contains(&b) && a < b;
    match v[..] {
        [x0, x1, y0, y1] if unit(x0, x1) && unit(y0, y1) => Ok([x0, x1, y0, y1]),
        _ => Err("expected x0,x1,y0,y1 in [0, 1] with x0 < x1 and y0 < y1".into()),
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn settings_round_trip_and_bad_text_is_refused() {
        let ov = Overrides {
            spp: Some(12),
            integrator: Some("ppm".into()),
            seed: Some(7),
            cropwindow: Some([0.25, 0.5, 0.0, 1.0]),
            outfile: Some("ignored.exr".into()),
            aovs: vec![Aov::Surface(crate::film::SurfaceAov::Albedo), Aov::Variance],
            memory_limit: Some(1 << 30),
            photometric: true,
        };
        let text = settings_text(&ov);
        assert_eq!(
            text,
            "spp=12\nintegrator=ppm\nseed=7\ncropwindow=0.25,0.5,0.0,1.0\naov=albedo,variance\nunits=photometric\n"
        );
        let back = overrides_from_settings(&text).expect("round trip");
        assert_eq!(settings_text(&back), text);
        assert_eq!(back.outfile, None);
        assert_eq!(
            back.memory_limit, None,
            "the memory limit is not a render's identity"
        );
        assert_eq!(settings_text(&Overrides::default()), "");
        for bad in [
            "spp",
            "spp=x\n",
            "colour=red\n",
            "cropwindow=0.5,0.2,0,1\n",
            "units=sensor\n",
        ] {
            assert!(overrides_from_settings(bad).is_err(), "{bad:?}");
        }
    }
}
