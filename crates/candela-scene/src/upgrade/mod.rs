//! pbrt-v3 syntax, read as pbrt-v4's `pbrt --upgrade` would rewrite it.
//!
//! pbrt-v4 does not read pbrt-v3 files; it offers `--upgrade` to rewrite
//! them (pbrt-v4 `src/pbrt/parser.cpp`, `FormattingParserTarget`). candela
//! applies the same rewrites while parsing, so the description — and the
//! rendering core — only ever see pbrt-v4 names. Every directive that
//! changes produces one warning at its `file:line:col` listing what was
//! renamed, dropped or added, so a user knows the file is being translated.
//!
//! The rewrites are pbrt-v4's: a v3 parameter whose v4 default differs is
//! not filled in with the v3 default (`--upgrade` does not either), so the
//! result renders like the upgraded file in pbrt-v4. Where a v3 feature has
//! no v4 counterpart (a non-opaque `uber`, a non-grey light `scale`) the
//! rewrite is an error at the parameter, as in pbrt-v4. Materials are in
//! [`material`]; the other directives here.

mod material;

pub(crate) use material::material;

use crate::builder::OptionEntity;
use crate::error::{Loc, SceneError};
use crate::param::{Param, ParamSet, ParamType, ParamValue};

type Result<T> = std::result::Result<T, SceneError>;

/// Edits one directive's parameters and records what changed.
pub(crate) struct Edit<'a> {
    params: &'a mut ParamSet,
    loc: &'a Loc,
    notes: Vec<String>,
}

impl<'a> Edit<'a> {
    fn new(params: &'a mut ParamSet, loc: &'a Loc) -> Self {
        Edit {
            params,
            loc,
            notes: Vec::new(),
        }
    }

    /// The last parameter called `name`.
    fn get(&self, name: &str) -> Option<&Param> {
        self.params.get(name)
    }

    fn has(&self, name: &str) -> bool {
        self.get(name).is_some()
    }

    fn note(&mut self, s: impl Into<String>) {
        self.notes.push(s.into());
    }

    /// Renames every parameter called `from`.
    fn rename(&mut self, from: &str, to: &str) {
        let mut any = false;
        for p in self.params.params.iter_mut().filter(|p| p.name == from) {
            p.name = to.to_string();
            any = true;
        }
        if any {
            self.note(format!("\"{from}\" → \"{to}\""));
        }
    }

    /// Removes every parameter called `name`; returns the last one.
    fn take(&mut self, name: &str) -> Option<Param> {
        let last = self.params.params.iter().rposition(|p| p.name == name)?;
        let p = self.params.params.remove(last);
        self.params.params.retain(|q| q.name != name);
        Some(p)
    }

    /// Removes `name`, noting it.
    fn drop(&mut self, name: &str) {
        if let Some(p) = self.take(name) {
            self.note(format!("dropped {}", describe(&p)));
        }
    }

    /// Removes `name`; silent when it is the grey `value` (an rgb with three
    /// equal components, or a float), noted otherwise. True if it was.
    fn drop_unless(&mut self, name: &str, value: f32) -> bool {
        let Some(p) = self.take(name) else {
            return false;
        };
        let is = grey(&p) == Some(value);
        if !is {
            self.note(format!("dropped {}", describe(&p)));
        }
        is
    }

    /// Adds (or replaces) a parameter, located at the directive.
    fn set(&mut self, name: &str, ty: ParamType, value: ParamValue) {
        self.params.params.retain(|p| p.name != name);
        let p = Param {
            name: name.to_string(),
            ty,
            value,
            loc: self.loc.clone(),
            used: Default::default(),
            may_be_unused: false,
        };
        self.note(format!("set {}", describe(&p)));
        self.params.params.push(p);
    }

    /// The warning: `what` followed by the notes, if anything changed.
    fn finish(self, what: String, renamed: bool) -> Option<String> {
        if self.notes.is_empty() && !renamed {
            return None;
        }
        if self.notes.is_empty() {
            return Some(format!("{what} (pbrt-v3 syntax, as pbrt-v4 --upgrade)"));
        }
        Some(format!(
            "{what} (pbrt-v3 syntax, as pbrt-v4 --upgrade): {}",
            self.notes.join("; ")
        ))
    }
}

/// The value of a float, or of an rgb whose three components are equal.
fn grey(p: &Param) -> Option<f32> {
    match (&p.ty, &p.value) {
        (ParamType::Float, ParamValue::Floats(v)) if v.len() == 1 => Some(v[0]),
        (ParamType::Rgb, ParamValue::Floats(v)) if v.len() == 3 && v[0] == v[1] && v[1] == v[2] => {
            Some(v[0])
        }
        _ => None,
    }
}

/// `"type name" value` as written (long lists abbreviated).
fn describe(p: &Param) -> String {
    let value = match &p.value {
        ParamValue::Floats(v) if v.len() <= 4 => format!("{v:?}"),
        ParamValue::Ints(v) if v.len() <= 4 => format!("{v:?}"),
        ParamValue::Bools(v) if v.len() <= 4 => format!("{v:?}"),
        ParamValue::Strings(v) if v.len() == 1 => format!("\"{}\"", v[0]),
        ParamValue::Strings(v) if v.len() <= 4 => format!("{v:?}"),
        ParamValue::Spectrum(crate::SpectrumValue::Named(n)) => format!("\"{n}\""),
        _ => "[…]".to_string(),
    };
    format!("\"{} {}\" {value}", p.ty, p.name)
}

/// The warning for a directive `kind "name"` that became `kind "new"`.
fn headline(kind: &str, old: &str, new: &str) -> String {
    if old == new {
        format!("{kind} \"{old}\" upgraded")
    } else {
        format!("{kind} \"{old}\" upgraded to \"{new}\"")
    }
}

/// Rewrites `name` to `new`, returning whether it changed.
fn rename_entity(name: &mut String, new: &str) -> bool {
    let changed = name != new;
    *name = new.to_string();
    changed
}

/// `Film`, `Sampler`, `Integrator`, `PixelFilter` (and `Accelerator`, unchanged).
pub(crate) fn option_entity(
    which: OptionEntity,
    name: &mut String,
    params: &mut ParamSet,
    loc: &Loc,
) -> Option<String> {
    let old = name.clone();
    let mut e = Edit::new(params, loc);
    let renamed = match (which, old.as_str()) {
        (OptionEntity::Film, _) => film(&mut e, name),
        (OptionEntity::Sampler, "lowdiscrepancy" | "02sequence") => {
            rename_entity(name, "paddedsobol")
        }
        (OptionEntity::Sampler, "maxmindist") => rename_entity(name, "pmj02bn"),
        // pbrt-v3's "random" is pbrt-v4's "independent" (pbrt-v4's upgrade
        // leaves the name, which pbrt-v4 then rejects).
        (OptionEntity::Sampler, "random") => rename_entity(name, "independent"),
        (OptionEntity::Integrator, _) => integrator(&mut e, name),
        (OptionEntity::PixelFilter, _) => {
            e.rename("xwidth", "xradius");
            e.rename("ywidth", "yradius");
            if let (true, Some(a)) = (old == "gaussian", e.get("alpha").and_then(grey)) {
                e.take("alpha");
                // [pbrt-v4 --upgrade: sigma = 1/√(2α)]
                let sigma = 1.0 / (2.0 * a).sqrt();
                e.set("sigma", ParamType::Float, ParamValue::Floats(vec![sigma]));
            }
            false
        }
        _ => false,
    };
    e.finish(headline(&format!("{which:?}"), &old, name), renamed)
}

/// `Film "image"` → `"rgb"`; `maxsampleluminance` → `maxcomponentvalue`; `scale` s → `iso` 100·s.
fn film(e: &mut Edit, name: &mut String) -> bool {
    e.rename("maxsampleluminance", "maxcomponentvalue");
    if let Some(s) = e
        .get("scale")
        .filter(|p| p.ty == ParamType::Float)
        .and_then(grey)
    {
        e.take("scale");
        e.set("iso", ParamType::Float, ParamValue::Floats(vec![100.0 * s]));
    }
    name == "image" && rename_entity(name, "rgb")
}

/// `directlighting` → `path` with `maxdepth` 1; `rrthreshold` dropped;
/// `lightsamplestrategy` → `lightsampler` (`spatial` → `bvh`).
fn integrator(e: &mut Edit, name: &mut String) -> bool {
    e.drop("rrthreshold");
    if e.has("lightsamplestrategy") {
        e.rename("lightsamplestrategy", "lightsampler");
        for p in e
            .params
            .params
            .iter_mut()
            .filter(|p| p.name == "lightsampler")
        {
            if let ParamValue::Strings(v) = &mut p.value {
                v.iter_mut()
                    .filter(|s| *s == "spatial")
                    .for_each(|s| *s = "bvh".into());
            }
        }
    }
    if name != "directlighting" {
        return false;
    }
    e.set("maxdepth", ParamType::Integer, ParamValue::Ints(vec![1]));
    rename_entity(name, "path")
}

/// Folds an rgb (or float) `scale` and a two-value pbrt-v3 `blackbody`
/// `[kelvin scale]` into one float `scale`, as pbrt-v4's upgrade does for
/// lights. A non-grey rgb scale is an error.
fn light_scale(e: &mut Edit, radiance: &str) -> Result<()> {
    let mut scale = 1.0;
    let mut changed = false;
    if let Some(p) = e.get("scale").filter(|p| p.ty != ParamType::Float) {
        let Some(s) = grey(p) else {
            return Err(SceneError::at(
                &p.loc,
                "in pbrt-v4, \"scale\" of a light is a float; a coloured pbrt-v3 scale cannot be upgraded",
            ));
        };
        scale *= s;
        changed = true;
        e.take("scale");
    }
    let bb = e
        .params
        .params
        .iter_mut()
        .rev()
        .find(|p| p.name == radiance);
    if let Some(p) = bb.filter(|p| p.ty == ParamType::Blackbody) {
        if let ParamValue::Floats(v) = &mut p.value {
            if v.len() == 2 {
                scale *= v[1];
                v.truncate(1);
                changed = true;
            }
        }
    }
    if changed {
        let s = scale * e.get("scale").and_then(grey).unwrap_or(1.0);
        e.set("scale", ParamType::Float, ParamValue::Floats(vec![s]));
    }
    Ok(())
}

/// `LightSource`: `scale`/blackbody folding, `mapname` → `filename`, `samples` dropped.
pub(crate) fn light(name: &str, params: &mut ParamSet, loc: &Loc) -> Result<Option<String>> {
    let mut e = Edit::new(params, loc);
    let radiance = if matches!(name, "point" | "spot" | "goniometric" | "projection") {
        "I"
    } else {
        "L"
    };
    light_scale(&mut e, radiance)?;
    e.drop("samples");
    e.rename("mapname", "filename");
    Ok(e.finish(headline("LightSource", name, name), false))
}

/// `AreaLightSource "area"` → `"diffuse"`; `nsamples` dropped; scale folding.
pub(crate) fn area_light(
    name: &mut String,
    params: &mut ParamSet,
    loc: &Loc,
) -> Result<Option<String>> {
    let old = name.clone();
    let mut e = Edit::new(params, loc);
    light_scale(&mut e, "L")?;
    e.drop("nsamples");
    let renamed = old == "area" && rename_entity(name, "diffuse");
    Ok(e.finish(headline("AreaLightSource", &old, name), renamed))
}

/// `Shape`: loopsubdiv `nlevels` → `levels`; a triangle mesh's float
/// `uv`/`st` or `point2 st` → `point2 uv`; `discarddegenerateUVs` and
/// `shadowalpha` dropped.
pub(crate) fn shape(name: &str, params: &mut ParamSet, loc: &Loc) -> Option<String> {
    let mut e = Edit::new(params, loc);
    if name == "loopsubdiv" {
        e.rename("nlevels", "levels");
    }
    if matches!(name, "trianglemesh" | "plymesh") {
        e.drop("discarddegenerateUVs");
        e.drop("shadowalpha");
    }
    if name == "trianglemesh" {
        for uv in ["st", "uv"] {
            let is_v3 = e.get(uv).is_some_and(|p| {
                p.ty == ParamType::Float || (uv == "st" && p.ty == ParamType::Point2)
            });
            if let Some(p) = is_v3.then(|| e.take(uv)).flatten() {
                e.note(format!("\"{} {uv}\" → \"point2 uv\"", p.ty));
                let mut p = p;
                p.name = "uv".into();
                p.ty = ParamType::Point2;
                e.params.params.push(p);
            }
        }
    }
    e.finish(headline("Shape", name, name), false)
}

/// `Texture`: `scale`'s `tex1`/`tex2` → `tex`/`scale`; imagemap `trilinear`
/// → `filter`, boolean `gamma` → `encoding`.
pub(crate) fn texture(
    class: &str,
    float: bool,
    params: &mut ParamSet,
    loc: &Loc,
) -> Result<Option<String>> {
    let mut e = Edit::new(params, loc);
    if class == "scale" && (e.has("tex1") || e.has("tex2")) {
        scale_texture(&mut e, float)?;
    }
    if class == "imagemap" {
        if let Some(ParamValue::Bools(v)) = e.get("trilinear").map(|p| p.value.clone()) {
            e.take("trilinear");
            let f = if v.first() == Some(&true) {
                "trilinear"
            } else {
                "bilinear"
            };
            e.set(
                "filter",
                ParamType::String,
                ParamValue::Strings(vec![f.into()]),
            );
        }
        if let Some(ParamValue::Bools(v)) = e.get("gamma").map(|p| p.value.clone()) {
            e.take("gamma");
            let enc = if v.first() == Some(&true) {
                "sRGB"
            } else {
                "linear"
            };
            e.set(
                "encoding",
                ParamType::String,
                ParamValue::Strings(vec![enc.into()]),
            );
        }
    }
    Ok(e.finish(headline("Texture", class, class), false))
}

/// pbrt-v3's `scale` texture multiplies `tex1` by `tex2`; pbrt-v4's takes a
/// texture `tex` and a float `scale`. For spectrum textures the constant
/// one must be a grey rgb, which becomes the float.
fn scale_texture(e: &mut Edit, float: bool) -> Result<()> {
    if float {
        e.rename("tex1", "tex");
        e.rename("tex2", "scale");
        return Ok(());
    }
    // Prefer a grey rgb (it becomes the float); else report the first rgb.
    let is_rgb = |e: &Edit, n: &str| e.get(n).is_some_and(|p| p.ty == ParamType::Rgb);
    let slots = ["tex1", "tex2"];
    let rgb = slots
        .into_iter()
        .find(|n| is_rgb(e, n) && e.get(n).and_then(grey).is_some())
        .or_else(|| slots.into_iter().find(|n| is_rgb(e, n)));
    let Some(rgb) = rgb else {
        return Err(SceneError::at(
            e.loc,
            "pbrt-v3 \"scale\" texture of two spectrum textures cannot be upgraded (one must be a grey rgb)",
        ));
    };
    let p = e
        .take(rgb)
        .ok_or_else(|| SceneError::at(e.loc, "scale texture"))?;
    let Some(s) = grey(&p) else {
        return Err(SceneError::at(
            &p.loc,
            "a non-grey \"rgb\" in a pbrt-v3 \"scale\" texture cannot be upgraded to pbrt-v4's float scale",
        ));
    };
    let other = if rgb == "tex1" { "tex2" } else { "tex1" };
    e.rename(other, "tex");
    e.set("scale", ParamType::Float, ParamValue::Floats(vec![s]));
    Ok(())
}
