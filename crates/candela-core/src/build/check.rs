//! Parameter domains, checked at build time before anything is allocated.
//!
//! Two layers:
//! 1. [`finite_scene`] runs first over the whole description: every number
//!    of every parameter (floats, points, vectors, normals, RGB, blackbody
//!    temperatures, sampled spectra) and every transformation matrix, as the
//!    renderer will use it in single precision, must be finite. NaN and ±∞
//!    have no meaning anywhere in pbrt-v4's format; the only exception is
//!    the film's `maxcomponentvalue`, whose default *is* +∞.
//! 2. Each builder then reads its parameters through [`Check`], which names
//!    the entity and the parameter and places the error at the parameter's
//!    file:line:col (at the directive when the parameter was not written and
//!    its default is what fails). The domains are pbrt-v4's where it states
//!    one and otherwise the values for which the quantity means something
//!    (a radius is positive, an angle lies in its range).

use super::BuildError;
use candela_scene::{Loc, Mat4d, ParamSet, ParamType, ParamValue, SceneDescription, SpectrumValue};
use std::fmt;

/// The values a numeric parameter may take.
#[derive(Clone, Copy, Debug)]
pub enum Domain {
    /// x > 0.
    Positive,
    /// x ≥ 0.
    NonNegative,
    /// x ≥ the bound.
    AtLeast(f32),
    /// lo ≤ x ≤ hi.
    Closed(f32, f32),
    /// lo < x ≤ hi.
    LeftOpen(f32, f32),
    /// lo < x < hi.
    Open(f32, f32),
}

impl Domain {
    /// Whether `x` lies in the domain (NaN never does).
    pub fn contains(self, x: f32) -> bool {
        match self {
            Domain::Positive => x > 0.0,
            Domain::NonNegative => x >= 0.0,
            Domain::AtLeast(lo) => x >= lo,
            Domain::Closed(lo, hi) => x >= lo && x <= hi,
            Domain::LeftOpen(lo, hi) => x > lo && x <= hi,
            Domain::Open(lo, hi) => x > lo && x < hi,
        }
    }
}

impl fmt::Display for Domain {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            Domain::Positive => write!(f, "a positive number"),
            Domain::NonNegative => write!(f, "a number ≥ 0"),
            Domain::AtLeast(lo) => write!(f, "a number ≥ {lo}"),
            Domain::Closed(lo, hi) => write!(f, "a number in [{lo}, {hi}]"),
            Domain::LeftOpen(lo, hi) => write!(f, "a number in ({lo}, {hi}]"),
            Domain::Open(lo, hi) => write!(f, "a number in ({lo}, {hi})"),
        }
    }
}

/// One entity's parameters with the entity's name and place, for located
/// domain errors.
#[derive(Clone, Copy)]
pub struct Check<'a> {
    /// The parameters.
    pub params: &'a ParamSet,
    /// The directive's location (for parameters not written).
    pub loc: &'a Loc,
    /// `Shape "sphere"`, `Film "rgb"`, …
    pub what: &'a str,
}

impl<'a> Check<'a> {
    /// Checks of `params` of the entity `what` written at `loc`.
    pub fn new(params: &'a ParamSet, loc: &'a Loc, what: &'a str) -> Self {
        Check { params, loc, what }
    }

    /// Where parameter `name` was written, else the directive.
    pub fn loc_of(&self, name: &str) -> &'a Loc {
        self.params.param_loc(name).unwrap_or(self.loc)
    }

    /// An error about parameter `name`, at its location.
    pub fn error(&self, name: &str, msg: impl fmt::Display) -> BuildError {
        BuildError::at(self.loc_of(name), format!("{} \"{name}\" {msg}", self.what))
    }

    /// Fails unless `x`, the value of `name`, lies in `d`.
    pub fn domain(&self, name: &str, x: f32, d: Domain) -> Result<f32, BuildError> {
        if d.contains(x) {
            Ok(x)
        } else {
            Err(self.error(name, format!("must be {d}, found {x}")))
        }
    }

    /// Float `name` (or `default`), which must lie in `d`.
    pub fn float(&self, name: &str, default: f32, d: Domain) -> Result<f32, BuildError> {
        let x = self.params.get_float(name, default)?;
        self.domain(name, x, d)
    }

    /// Integer `name` (or `default`), which must be at least `min`.
    pub fn int(&self, name: &str, default: i32, min: i32) -> Result<i32, BuildError> {
        let x = self.params.get_int(name, default)?;
        if x < min {
            return Err(self.error(name, format!("must be at least {min}, found {x}")));
        }
        Ok(x)
    }

    /// Integer `name` (or `default`) in `min..=max`.
    pub fn int_in(&self, name: &str, default: i32, min: i32, max: i32) -> Result<i32, BuildError> {
        let x = self.int(name, default, min)?;
        if x > max {
            return Err(self.error(name, format!("must be at most {max}, found {x}")));
        }
        Ok(x)
    }

    /// Optional single float `name` in `d`.
    pub fn float_opt(&self, name: &str, d: Domain) -> Result<Option<f32>, BuildError> {
        match self.params.get_floats(name)? {
            None => Ok(None),
            Some(v) if v.len() == 1 => self.domain(name, v[0], d).map(Some),
            Some(v) => Err(self.error(name, format!("needs one value, found {}", v.len()))),
        }
    }
}

/// Whether parameter `name` may be +∞ (the film's `maxcomponentvalue`, whose
/// pbrt-v4 default is +∞).
fn may_be_infinite(name: &str, x: f32) -> bool {
    name == "maxcomponentvalue" && x == f32::INFINITY
}

/// The first non-finite number of `params`, as an error naming `what`.
fn finite_params(params: &ParamSet, what: &str) -> Result<(), BuildError> {
    for p in &params.params {
        let bad = match &p.value {
            ParamValue::Floats(v) => v
                .iter()
                .copied()
                .find(|x| !x.is_finite() && !may_be_infinite(&p.name, *x)),
            ParamValue::Spectrum(SpectrumValue::Sampled(v)) => v
                .iter()
                .flat_map(|(l, x)| [*l, *x])
                .find(|x| !x.is_finite()),
            ParamValue::Spectrum(SpectrumValue::Blackbody(t)) => {
                Some(*t).filter(|t| !t.is_finite())
            }
            _ => None,
        };
        if let Some(x) = bad {
            let ty = if p.ty == ParamType::Float {
                String::new()
            } else {
                format!(" ({})", p.ty)
            };
            return Err(BuildError::at(
                &p.loc,
                format!(
                    "{what} \"{}\"{ty} has the value {x}: parameters must be finite numbers",
                    p.name
                ),
            ));
        }
    }
    Ok(())
}

/// Whether every entry of `m` is finite in single precision (as the
/// renderer stores transformations).
pub fn finite_matrix(m: &Mat4d) -> bool {
    m.m.iter().flatten().all(|x| (*x as f32).is_finite())
}

/// Fails unless transformation `m` of `what` at `loc` is finite in single
/// precision.
fn check_matrix(m: &Mat4d, loc: &Loc, what: &str) -> Result<(), BuildError> {
    if finite_matrix(m) {
        return Ok(());
    }
    Err(BuildError::at(
        loc,
        format!(
            "the transformation of {what} is not finite in single precision (an entry overflows ±3.4e38 or is NaN): check the Translate, Scale, Rotate, Transform and ConcatTransform values before it"
        ),
    ))
}

/// Checks that every parameter value and transformation of the scene is
/// finite (module docs).
pub fn finite_scene(desc: &SceneDescription) -> Result<(), BuildError> {
    for (e, what) in [
        (&desc.film, "Film"),
        (&desc.sampler, "Sampler"),
        (&desc.integrator, "Integrator"),
        (&desc.filter, "PixelFilter"),
    ] {
        if let Some(e) = e {
            finite_params(&e.params, &format!("{what} \"{}\"", e.name))?;
        }
    }
    if let Some(c) = &desc.camera {
        let what = format!("Camera \"{}\"", c.name);
        finite_params(&c.params, &what)?;
        check_matrix(&c.camera_from_world, &c.loc, &what)?;
    }
    for t in &desc.textures {
        let what = format!("Texture \"{}\"", t.name);
        finite_params(&t.params, &what)?;
        check_matrix(&t.render_from_texture, &t.loc, &what)?;
    }
    for m in desc
        .materials
        .iter()
        .chain(desc.named_materials.iter().map(|(_, m)| m))
    {
        finite_params(&m.params, &format!("Material \"{}\"", m.ty))?;
    }
    for l in &desc.lights {
        let what = format!("LightSource \"{}\"", l.name);
        finite_params(&l.params, &what)?;
        check_matrix(&l.render_from_light, &l.loc, &what)?;
    }
    let defined = desc.instance_definitions.iter().flat_map(|d| &d.shapes);
    for s in desc.shapes.iter().chain(defined) {
        let what = format!("Shape \"{}\"", s.name);
        finite_params(&s.params, &what)?;
        check_matrix(&s.render_from_object, &s.loc, &what)?;
        if let Some(m) = &s.render_from_object_end {
            check_matrix(m, &s.loc, &what)?;
        }
        if let Some(a) = &s.area_light {
            finite_params(&a.params, &format!("AreaLightSource \"{}\"", a.name))?;
        }
    }
    for i in &desc.instances {
        let what = format!("ObjectInstance \"{}\"", i.name);
        check_matrix(&i.render_from_instance, &i.loc, &what)?;
        if let Some(m) = &i.render_from_instance_end {
            check_matrix(m, &i.loc, &what)?;
        }
    }
    Ok(())
}
