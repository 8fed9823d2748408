//! pbrt-v3 materials → pbrt-v4 materials, as `pbrt --upgrade` maps them
//! (pbrt-v4 `FormattingParserTarget::upgradeMaterial`):
//!
//! | pbrt-v3 | pbrt-v4 | parameters |
//! |---|---|---|
//! | `matte` | `diffuse` | `Kd` → `reflectance`; `sigma` dropped (v4's diffuse is Lambertian) |
//! | `plastic` | `coateddiffuse` (`diffuse` if `Ks` is 0) | `Kd` → `reflectance`; `Ks` dropped |
//! | `substrate` | `coateddiffuse` | `Kd` → `reflectance`; `Ks` dropped |
//! | `uber` | `coateddiffuse` (`diffuse` if `Ks` is 0) | `Kd` → `reflectance`, `index` → `eta`; `Ks`, `Kr`, `Kt` dropped; only an opaque `opacity` |
//! | `metal` | `conductor` | `eta`, `k`, roughness kept; `Kr` dropped |
//! | `mirror` | `conductor` | silver (`metal-Ag-eta`, `metal-Ag-k`), roughness 0; `Kr` dropped |
//! | `glass` | `dielectric` | `index` → `eta`; `Kr`, `Kt` dropped |
//! | `disney` | `diffuse` | `color` → `reflectance` |
//! | `mix` (with `namedmaterial1/2`) | `mix` | `"string materials" [m2 m1]` (v4's order is reversed); rgb `amount` → float |
//!
//! Every material's `bumpmap` becomes `displacement`. A dropped colour is
//! listed in the warning unless it is the value that makes dropping it
//! exact (`Kr` = 1 for metal and mirror, `Kr` = `Kt` = 1 for glass, `Ks` = 1
//! for substrate, `Kr` = `Kt` = 0 for uber). pbrt-v4's upgrade compares a
//! mirror's `Kr` with 0, which would flag every ordinary mirror; candela
//! uses 1, the pbrt-v3 default. Materials candela cannot render either way
//! (`translucent`, `kdsubsurface`, `fourier`, ...) are left as written, so
//! the error names the type in the file.

use super::{headline, Edit};
use crate::error::{Loc, SceneError};
use crate::param::{ParamSet, ParamType, ParamValue};
use crate::SpectrumValue;

type Result<T> = std::result::Result<T, SceneError>;

/// Upgrades material type `ty` and its parameters in place; returns the
/// warning if anything changed.
pub(crate) fn material(
    ty: &mut String,
    params: &mut ParamSet,
    loc: &Loc,
) -> Result<Option<String>> {
    let old = ty.clone();
    let mut e = Edit::new(params, loc);
    e.rename("bumpmap", "displacement");
    let new = match old.as_str() {
        "matte" => {
            e.rename("Kd", "reflectance");
            e.drop_unless("sigma", 0.0);
            "diffuse"
        }
        "plastic" => coated_or_diffuse(&mut e, "Ks", &[]),
        "substrate" => {
            e.drop_unless("Ks", 1.0);
            e.rename("Kd", "reflectance");
            "coateddiffuse"
        }
        "uber" => uber(&mut e)?,
        "metal" => {
            e.drop_unless("Kr", 1.0);
            "conductor"
        }
        "mirror" => {
            e.drop_unless("Kr", 1.0);
            e.set("roughness", ParamType::Float, ParamValue::Floats(vec![0.0]));
            for (name, spectrum) in [("eta", "metal-Ag-eta"), ("k", "metal-Ag-k")] {
                let v = ParamValue::Spectrum(SpectrumValue::Named(spectrum.into()));
                e.set(name, ParamType::Spectrum, v);
            }
            "conductor"
        }
        "glass" => {
            index_to_eta(&mut e, &old)?;
            e.drop_unless("Kr", 1.0);
            e.drop_unless("Kt", 1.0);
            "dielectric"
        }
        "disney" => {
            e.rename("color", "reflectance");
            "diffuse"
        }
        "mix" if e.has("namedmaterial1") || e.has("namedmaterial2") => {
            mix(&mut e)?;
            "mix"
        }
        _ => old.as_str(),
    }
    .to_string();
    let renamed = new != old;
    *ty = new;
    Ok(e.finish(headline("Material", &old, ty), renamed))
}

/// `plastic`/`uber`: `coateddiffuse`, or `diffuse` when the specular colour
/// `ks` is exactly 0 (then the coating's parameters go too).
fn coated_or_diffuse(e: &mut Edit, ks: &str, also: &[&str]) -> &'static str {
    let black = e.drop_unless(ks, 0.0);
    for name in also {
        e.drop_unless(name, 0.0);
    }
    e.rename("Kd", "reflectance");
    if !black {
        return "coateddiffuse";
    }
    for name in [
        "eta",
        "roughness",
        "uroughness",
        "vroughness",
        "remaproughness",
    ] {
        e.drop(name);
    }
    "diffuse"
}

/// `uber`: `index` → `eta`, `Kr`/`Kt` dropped, and only an opaque `opacity`.
fn uber(e: &mut Edit) -> Result<&'static str> {
    index_to_eta(e, "uber")?;
    if let Some(p) = e.get("opacity") {
        let opaque = p.ty == ParamType::Rgb && p.value == ParamValue::Floats(vec![1.0; 3]);
        if !opaque {
            return Err(SceneError::unsupported(
                &p.loc,
                "a non-opaque \"opacity\" in a pbrt-v3 \"uber\" material has no pbrt-v4 counterpart",
            ));
        }
        e.take("opacity");
    }
    Ok(coated_or_diffuse(e, "Ks", &["Kr", "Kt"]))
}

/// pbrt-v3's `index` (a float or a float texture) is pbrt-v4's `eta`.
fn index_to_eta(e: &mut Edit, ty: &str) -> Result<()> {
    if !e.has("index") {
        return Ok(());
    }
    if let Some(p) = e.get("eta") {
        return Err(SceneError::at(
            &p.loc,
            format!("material \"{ty}\" has both \"index\" and \"eta\""),
        ));
    }
    e.rename("index", "eta");
    Ok(())
}

/// The single string of pbrt-v3's `namedmaterial1`/`namedmaterial2`.
fn named(e: &mut Edit, name: &str) -> Result<String> {
    match e.take(name) {
        Some(p) => match &p.value {
            ParamValue::Strings(v) if p.ty == ParamType::String && v.len() == 1 => Ok(v[0].clone()),
            _ => Err(SceneError::at(
                &p.loc,
                format!("expected one string for '{name}'"),
            )),
        },
        None => Err(SceneError::at(
            e.loc,
            format!("pbrt-v3 \"mix\" material needs \"string {name}\""),
        )),
    }
}

/// pbrt-v3 `mix`: the amount weights `namedmaterial1`, pbrt-v4's weights
/// `materials[1]`, so the pair is written in reverse; an rgb `amount`
/// becomes its (average) float.
fn mix(e: &mut Edit) -> Result<()> {
    let (m1, m2) = (named(e, "namedmaterial1")?, named(e, "namedmaterial2")?);
    if let Some(p) = e
        .get("amount")
        .filter(|p| p.ty != ParamType::Float && p.ty != ParamType::Texture)
    {
        let v = match (&p.ty, &p.value) {
            (ParamType::Rgb, ParamValue::Floats(v)) if v.len() == 3 => (v[0] + v[1] + v[2]) / 3.0,
            _ => {
                return Err(SceneError::at(
                    &p.loc,
                    "a pbrt-v3 mix \"amount\" must be an rgb or a texture to be upgraded",
                ))
            }
        };
        let grey = super::grey(p).is_some();
        e.take("amount");
        if !grey {
            e.note("rgb \"amount\" averaged");
        }
        e.set("amount", ParamType::Float, ParamValue::Floats(vec![v]));
    }
    e.note(format!(
        "\"namedmaterial1\" \"{m1}\", \"namedmaterial2\" \"{m2}\" → \"materials\" [\"{m2}\" \"{m1}\"]"
    ));
    e.params.params.push(crate::param::Param {
        name: "materials".into(),
        ty: ParamType::String,
        value: ParamValue::Strings(vec![m2, m1]),
        loc: e.loc.clone(),
        used: Default::default(),
        may_be_unused: false,
    });
    Ok(())
}
