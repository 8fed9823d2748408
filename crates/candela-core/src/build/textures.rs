//! `Texture` directives and texture-valued parameters → texture trees.
//!
//! A parameter that pbrt-v4 reads as a texture (`GetFloatTexture`,
//! `GetSpectrumTexture`) may be written as a value (`"float roughness" 0.1`,
//! `"rgb reflectance" [...]`) or as a reference to a named texture
//! (`"texture reflectance" "checks"`). References are resolved here, building
//! each named texture on first use and memoising it; a texture's own
//! texture parameters resolve the same way, so textures nest. As in pbrt-v4
//! a texture may only name textures declared before it (which also rules out
//! cycles), while materials may name any texture.
//!
//! Spectrum textures are built once per meaning of their RGB values
//! (pbrt-v4's `SpectrumType`): a texture used as a reflectance lifts its RGB
//! constants to bounded reflectance spectra, one used for η or k to
//! unbounded ones. Nested textures inherit the meaning of their user.
//! Parameter names and defaults are pbrt-v4's (`textures.cpp`, `Create`).

use super::image_textures::ImageCache;
use super::spectra::{spectrum_param, SpectrumKind};
use super::BuildError;
use crate::math::{Transform, Vec3};
use crate::spectrum::{ColorSpace, Spectrum};
use crate::texture::{
    Bilerp, CheckerMap, Checkerboard, DirectionMix, Dots, FloatTexture, Marble, Mix, NoiseSum,
    Scale, SpectrumImageTexture, SpectrumTexture, TextureMapping2D, TextureMapping3D,
};
use candela_scene::{Loc, ParamSet, TextureDesc, TextureKind};
use std::collections::HashMap;
use std::sync::Arc;

/// Who reads texture parameters: a material or a texture.
pub struct Source<'b> {
    /// The parameters.
    pub params: &'b ParamSet,
    /// The directive's location (for errors about absent parameters).
    pub loc: &'b Loc,
    /// The colour space for RGB values.
    pub cs: &'static ColorSpace,
    /// Textures with an index below this may be named.
    pub visible: usize,
    /// The entity, for domain errors: `Material "conductor"`.
    pub what: &'b str,
}

impl<'b> Source<'b> {
    /// A material's parameters (every texture is visible).
    pub fn new(params: &'b ParamSet, loc: &'b Loc, color_space: &str) -> Result<Self, BuildError> {
        let cs = ColorSpace::by_name(color_space)
            .ok_or_else(|| BuildError::at(loc, format!("unknown color space \"{color_space}\"")))?;
        Ok(Self {
            params,
            loc,
            cs,
            visible: usize::MAX,
            what: "Material",
        })
    }

    fn loc_of(&self, name: &str) -> &Loc {
        self.params.param_loc(name).unwrap_or(self.loc)
    }
}

/// Builds and memoises named textures.
pub struct Textures<'a> {
    descs: &'a [TextureDesc],
    float_names: HashMap<&'a str, usize>,
    spectrum_names: HashMap<&'a str, usize>,
    floats: HashMap<usize, FloatTexture>,
    spectra: HashMap<(usize, SpectrumKind), SpectrumTexture>,
    used: Vec<bool>,
    /// Texture lookups so far (cached ones included): a material whose
    /// building made none reads no texture.
    lookups: usize,
    images: ImageCache,
}

const FLOAT_CLASSES: &str =
    "constant, scale, mix, directionmix, checkerboard, bilerp, dots, fbm, wrinkled, windy, imagemap";
const SPECTRUM_CLASSES: &str =
    "constant, scale, mix, directionmix, checkerboard, bilerp, dots, marble, imagemap";

impl<'a> Textures<'a> {
    /// Indexes the scene's `Texture` directives by name and kind.
    pub fn new(descs: &'a [TextureDesc]) -> Self {
        let mut float_names = HashMap::new();
        let mut spectrum_names = HashMap::new();
        for (i, d) in descs.iter().enumerate() {
            match d.kind {
                TextureKind::Float => float_names.insert(d.name.as_str(), i),
                TextureKind::Spectrum => spectrum_names.insert(d.name.as_str(), i),
            };
        }
        Self {
            descs,
            float_names,
            spectrum_names,
            floats: HashMap::new(),
            spectra: HashMap::new(),
            used: vec![false; descs.len()],
            lookups: 0,
            images: ImageCache::default(),
        }
    }

    /// Non-fatal problems met while building (image filters, colour spaces).
    pub fn warnings(&self) -> &[String] {
        &self.images.warnings
    }

    /// The normal map image at `path`, loaded once.
    pub fn normal_map(
        &mut self,
        path: std::path::PathBuf,
        loc: &candela_scene::Loc,
    ) -> Result<Arc<crate::image::MapImage>, BuildError> {
        self.images.normal_map(path, loc)
    }

    /// Lookups of `Texture` directives so far (by a material's parameters
    /// or another texture's, cached or not).
    pub fn lookups(&self) -> usize {
        self.lookups
    }

    /// Which textures were referenced (directly or through other textures).
    pub fn used(&self) -> &[bool] {
        &self.used
    }

    /// A float-texture parameter: a named texture, a float, or `default`.
    pub fn float(
        &mut self,
        src: &Source,
        name: &str,
        default: f32,
    ) -> Result<FloatTexture, BuildError> {
        Ok(self
            .float_opt(src, name)?
            .unwrap_or(FloatTexture::Constant(default)))
    }

    /// A float-texture parameter, if given.
    pub fn float_opt(
        &mut self,
        src: &Source,
        name: &str,
    ) -> Result<Option<FloatTexture>, BuildError> {
        if let Some(tex) = src.params.get_texture(name) {
            let i = self.lookup(src, name, &tex, TextureKind::Float)?;
            return self.build_float(i).map(Some);
        }
        Ok(src
            .params
            .get_floats(name)?
            .and_then(|v| v.first().copied())
            .map(FloatTexture::Constant))
    }

    /// A spectrum-texture parameter with RGB meaning `kind`, if given.
    pub fn spectrum_opt(
        &mut self,
        src: &Source,
        name: &str,
        kind: SpectrumKind,
    ) -> Result<Option<SpectrumTexture>, BuildError> {
        if let Some(tex) = src.params.get_texture(name) {
            let i = self.lookup(src, name, &tex, TextureKind::Spectrum)?;
            return self.build_spectrum(i, kind).map(Some);
        }
        Ok(spectrum_param(src.params, name, kind, src.cs)?.map(SpectrumTexture::Constant))
    }

    /// A spectrum-texture parameter, or the constant `default`.
    pub fn spectrum(
        &mut self,
        src: &Source,
        name: &str,
        kind: SpectrumKind,
        default: f32,
    ) -> Result<SpectrumTexture, BuildError> {
        Ok(self
            .spectrum_opt(src, name, kind)?
            .unwrap_or(SpectrumTexture::Constant(Spectrum::Constant(default))))
    }

    /// Index of the texture `tex` named by parameter `param`, checked for kind and order.
    fn lookup(
        &self,
        src: &Source,
        param: &str,
        tex: &str,
        kind: TextureKind,
    ) -> Result<usize, BuildError> {
        let (names, other, what, other_what) = match kind {
            TextureKind::Float => (&self.float_names, &self.spectrum_names, "float", "spectrum"),
            TextureKind::Spectrum => (&self.spectrum_names, &self.float_names, "spectrum", "float"),
        };
        let loc = src.loc_of(param);
        let Some(&i) = names.get(tex) else {
            let msg = if other.contains_key(tex) {
                format!(
                    "\"{param}\" needs a {what} texture, but \"{tex}\" is a {other_what} texture"
                )
            } else {
                format!("unknown {what} texture \"{tex}\" for \"{param}\"")
            };
            return Err(BuildError::at(loc, msg));
        };
        if i >= src.visible {
            return Err(BuildError::at(
                loc,
                format!(
                    "texture \"{tex}\" (declared at {}) is used before its declaration; a texture may only use textures declared before it",
                    self.descs[i].loc
                ),
            ));
        }
        Ok(i)
    }

    /// The source for texture `i`'s own parameters.
    fn source(&self, i: usize) -> Result<Source<'a>, BuildError> {
        let descs: &'a [TextureDesc] = self.descs;
        let d = &descs[i];
        Ok(Source {
            visible: i,
            what: "Texture",
            ..Source::new(&d.params, &d.loc, &d.color_space)?
        })
    }

    /// The float texture declared at index `i`.
    fn build_float(&mut self, i: usize) -> Result<FloatTexture, BuildError> {
        self.lookups += 1;
        if let Some(t) = self.floats.get(&i) {
            return Ok(t.clone());
        }
        self.used[i] = true;
        let descs: &'a [TextureDesc] = self.descs;
        let d = &descs[i];
        let src = self.source(i)?;
        let p = &d.params;
        let t = match d.class.as_str() {
            "constant" => FloatTexture::Constant(p.get_float("value", 1.0)?),
            "scale" => {
                let tex = self.float(&src, "tex", 1.0)?;
                let scale = self.float(&src, "scale", 1.0)?;
                // pbrt-v4 drops a constant factor of 1 on either side.
                match (tex.as_constant(), scale.as_constant()) {
                    (_, Some(1.0)) => tex,
                    (Some(1.0), _) => scale,
                    _ => FloatTexture::Scale(Arc::new(Scale { tex, scale })),
                }
            }
            "mix" => FloatTexture::Mix(Arc::new(Mix {
                tex1: self.float(&src, "tex1", 0.0)?,
                tex2: self.float(&src, "tex2", 1.0)?,
                amount: self.float(&src, "amount", 0.5)?,
            })),
            "directionmix" => FloatTexture::DirectionMix(Arc::new(DirectionMix {
                tex1: self.float(&src, "tex1", 0.0)?,
                tex2: self.float(&src, "tex2", 1.0)?,
                dir: direction(d)?,
            })),
            "checkerboard" => FloatTexture::Checkerboard(Arc::new(Checkerboard {
                map: checker_map(d)?,
                tex1: self.float(&src, "tex1", 1.0)?,
                tex2: self.float(&src, "tex2", 0.0)?,
            })),
            "bilerp" => {
                let v = |n: &str, dv: f32| p.get_float(n, dv);
                FloatTexture::Bilerp(Arc::new(Bilerp {
                    map: mapping_2d(d)?,
                    v: [
                        v("v00", 0.0)?,
                        v("v01", 1.0)?,
                        v("v10", 0.0)?,
                        v("v11", 1.0)?,
                    ],
                }))
            }
            // "inside" lands in the outside slot and vice versa, as in pbrt-v4.
            "dots" => FloatTexture::Dots(Arc::new(Dots {
                map: mapping_2d(d)?,
                outside: self.float(&src, "inside", 1.0)?,
                inside: self.float(&src, "outside", 0.0)?,
            })),
            "fbm" => FloatTexture::Fbm(Arc::new(noise_sum(d)?)),
            "wrinkled" => FloatTexture::Wrinkled(Arc::new(noise_sum(d)?)),
            "windy" => FloatTexture::Windy(Arc::new(mapping_3d(d)?)),
            "imagemap" => FloatTexture::Image(Arc::new(self.images.texture(d)?)),
            other => return Err(unsupported(d, other, "float", FLOAT_CLASSES)),
        };
        self.floats.insert(i, t.clone());
        Ok(t)
    }

    /// The spectrum texture declared at index `i`, RGB values lifted as `kind`.
    fn build_spectrum(
        &mut self,
        i: usize,
        kind: SpectrumKind,
    ) -> Result<SpectrumTexture, BuildError> {
        self.lookups += 1;
        if let Some(t) = self.spectra.get(&(i, kind)) {
            return Ok(t.clone());
        }
        self.used[i] = true;
        let descs: &'a [TextureDesc] = self.descs;
        let d = &descs[i];
        let src = self.source(i)?;
        let p = &d.params;
        let t = match d.class.as_str() {
            "constant" => SpectrumTexture::Constant(
                spectrum_param(p, "value", kind, src.cs)?.unwrap_or(Spectrum::Constant(1.0)),
            ),
            "scale" => {
                let tex = self.spectrum(&src, "tex", kind, 1.0)?;
                match self.float(&src, "scale", 1.0)? {
                    s if s.as_constant() == Some(1.0) => tex,
                    scale => SpectrumTexture::Scale(Arc::new(Scale { tex, scale })),
                }
            }
            "mix" => SpectrumTexture::Mix(Arc::new(Mix {
                tex1: self.spectrum(&src, "tex1", kind, 0.0)?,
                tex2: self.spectrum(&src, "tex2", kind, 1.0)?,
                amount: self.float(&src, "amount", 0.5)?,
            })),
            "directionmix" => SpectrumTexture::DirectionMix(Arc::new(DirectionMix {
                tex1: self.spectrum(&src, "tex1", kind, 0.0)?,
                tex2: self.spectrum(&src, "tex2", kind, 1.0)?,
                dir: direction(d)?,
            })),
            "checkerboard" => SpectrumTexture::Checkerboard(Arc::new(Checkerboard {
                map: checker_map(d)?,
                tex1: self.spectrum(&src, "tex1", kind, 1.0)?,
                tex2: self.spectrum(&src, "tex2", kind, 0.0)?,
            })),
            "bilerp" => SpectrumTexture::Bilerp(Arc::new(Bilerp {
                map: mapping_2d(d)?,
                v: bilerp_spectra(&src, kind)?,
            })),
            "dots" => SpectrumTexture::Dots(Arc::new(Dots {
                map: mapping_2d(d)?,
                outside: self.spectrum(&src, "inside", kind, 1.0)?,
                inside: self.spectrum(&src, "outside", kind, 0.0)?,
            })),
            // pbrt-v4's marble is always an sRGB reflectance.
            "marble" => SpectrumTexture::Marble(Arc::new(Marble {
                noise: noise_sum(d)?,
                scale: p.get_float("scale", 1.0)?,
                variation: p.get_float("variation", 0.2)?,
            })),
            "imagemap" => SpectrumTexture::Image(Arc::new(SpectrumImageTexture {
                tex: self.images.texture(d)?,
                kind,
            })),
            other => return Err(unsupported(d, other, "spectrum", SPECTRUM_CLASSES)),
        };
        self.spectra.insert((i, kind), t.clone());
        Ok(t)
    }
}

/// The error for a texture class candela does not build.
fn unsupported(d: &TextureDesc, class: &str, kind: &str, known: &str) -> BuildError {
    let msg = match class {
        "ptex" => format!(
            "unsupported texture 'ptex' (\"{}\"): Ptex files are not supported yet",
            d.name
        ),
        _ => format!(
            "unknown {kind} texture type \"{class}\" for \"{}\" (supported: {known})",
            d.name
        ),
    };
    BuildError::at(&d.loc, msg)
}

/// The four corner spectra of a spectral `bilerp`.
fn bilerp_spectra(src: &Source, kind: SpectrumKind) -> Result<[Spectrum; 4], BuildError> {
    let v = |n: &str, dv: f32| -> Result<Spectrum, BuildError> {
        Ok(spectrum_param(src.params, n, kind, src.cs)?.unwrap_or(Spectrum::Constant(dv)))
    };
    Ok([
        v("v00", 0.0)?,
        v("v01", 1.0)?,
        v("v10", 0.0)?,
        v("v11", 1.0)?,
    ])
}

/// Texture-from-render: the inverse of the CTM at the `Texture` directive.
fn texture_from_render(d: &TextureDesc) -> Result<Transform, BuildError> {
    Transform::from_rows_f64(d.render_from_texture.m)
        .map(|t| t.inverse())
        .ok_or_else(|| BuildError::at(&d.loc, "singular texture transform"))
}

/// The 2D mapping from `"string mapping"` and its parameters [pbrt-v4 `TextureMapping2D::Create`].
pub(super) fn mapping_2d(d: &TextureDesc) -> Result<TextureMapping2D, BuildError> {
    let p = &d.params;
    Ok(match p.get_string("mapping", "uv")?.as_str() {
        "uv" => TextureMapping2D::Uv {
            su: p.get_float("uscale", 1.0)?,
            sv: p.get_float("vscale", 1.0)?,
            du: p.get_float("udelta", 0.0)?,
            dv: p.get_float("vdelta", 0.0)?,
        },
        "spherical" => TextureMapping2D::Spherical {
            texture_from_render: texture_from_render(d)?,
        },
        "cylindrical" => TextureMapping2D::Cylindrical {
            texture_from_render: texture_from_render(d)?,
        },
        "planar" => TextureMapping2D::Planar {
            texture_from_render: texture_from_render(d)?,
            vs: Vec3::from_array(p.get_vector3("v1", [1.0, 0.0, 0.0])?),
            vt: Vec3::from_array(p.get_vector3("v2", [0.0, 1.0, 0.0])?),
            ds: p.get_float("udelta", 0.0)?,
            dt: p.get_float("vdelta", 0.0)?,
        },
        other => {
            return Err(BuildError::at(
                p.param_loc("mapping").unwrap_or(&d.loc),
                format!("unknown 2D texture mapping \"{other}\" (known: uv, spherical, cylindrical, planar)"),
            ))
        }
    })
}

/// The 3D mapping: texture space is the CTM at the directive.
fn mapping_3d(d: &TextureDesc) -> Result<TextureMapping3D, BuildError> {
    Ok(TextureMapping3D {
        texture_from_render: texture_from_render(d)?,
    })
}

/// A 2D or 3D checkerboard layout from `"integer dimension"`.
fn checker_map(d: &TextureDesc) -> Result<CheckerMap, BuildError> {
    match d.params.get_int("dimension", 2)? {
        2 => Ok(CheckerMap::Planar(mapping_2d(d)?)),
        3 => Ok(CheckerMap::Solid(mapping_3d(d)?)),
        n => Err(BuildError::at(
            d.params.param_loc("dimension").unwrap_or(&d.loc),
            format!("{n}-dimensional checkerboard texture not supported (use 2 or 3)"),
        )),
    }
}

/// `"vector3 dir"` (default +y) in render space, normalised.
fn direction(d: &TextureDesc) -> Result<Vec3, BuildError> {
    let dir = Vec3::from_array(d.params.get_vector3("dir", [0.0, 1.0, 0.0])?);
    let render_from_texture = texture_from_render(d)?.inverse();
    let v = render_from_texture.vector(dir).normalize_or_zero();
    if v == Vec3::ZERO || !v.is_finite() {
        return Err(BuildError::at(
            d.params.param_loc("dir").unwrap_or(&d.loc),
            "\"dir\" must be a non-zero vector",
        ));
    }
    Ok(v)
}

/// `octaves` and `roughness` of the noise textures, with their 3D mapping.
fn noise_sum(d: &TextureDesc) -> Result<NoiseSum, BuildError> {
    let p = &d.params;
    let octaves = p.get_int("octaves", 8)?;
    if !(0..=32).contains(&octaves) {
        return Err(BuildError::at(
            p.param_loc("octaves").unwrap_or(&d.loc),
            format!("\"octaves\" must be between 0 and 32, found {octaves}"),
        ));
    }
    Ok(NoiseSum {
        map: mapping_3d(d)?,
        octaves: octaves as u32,
        omega: p.get_float("roughness", 0.5)?,
    })
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::math::Vec2;
    use crate::texture::{inside_polka_dot, TextureEvalContext};
    use std::path::Path;

    fn descs(world: &str) -> Vec<TextureDesc> {
        let text = format!("WorldBegin\n{world}\n");
        candela_scene::parse_str(&text, Path::new("t.pbrt"))
            .expect("parses")
            .textures
    }

    fn at_uv(u: f32, v: f32) -> TextureEvalContext {
        TextureEvalContext {
            uv: Vec2::new(u, v),
            ..Default::default()
        }
    }

    #[test]
    fn dots_swap_inside_and_outside_like_pbrt() {
        let d = descs(r#"Texture "d" "float" "dots" "float inside" [5] "float outside" [7]"#);
        let t = Textures::new(&d).build_float(0).expect("builds");
        // Find a cell with a dot; its centre is inside, its corner outside.
        let cell = (0..100)
            .map(|i| Vec2::new(i as f32, 0.0))
            .find(|&c| inside_polka_dot(c))
            .expect("some cell has a dot");
        assert_eq!(t.evaluate(&at_uv(cell.x, cell.y)), 7.0);
        assert_eq!(t.evaluate(&at_uv(cell.x + 0.49, cell.y + 0.49)), 5.0);
    }

    #[test]
    fn mapping_parameters_and_texture_space_are_read() {
        let d = descs(
            r#"Texture "c" "float" "checkerboard" "float uscale" [4] "float udelta" [0.5]
AttributeBegin
Rotate 90 1 0 0
Texture "m" "float" "directionmix" "float tex1" [1] "float tex2" [0] "vector3 dir" [0 1 0]
AttributeEnd"#,
        );
        let mut tex = Textures::new(&d);
        let c = tex.build_float(0).expect("builds");
        // s = 4u + 0.5: u = 0.1 → 0.9 (even cell), u = 0.2 → 1.3 (odd).
        assert_eq!(c.evaluate(&at_uv(0.1, 0.5)), 1.0);
        assert_eq!(c.evaluate(&at_uv(0.2, 0.5)), 0.0);
        // dir = +y in texture space is ±z in render space after the rotation.
        let m = tex.build_float(1).expect("builds");
        let ctx = |n: Vec3| TextureEvalContext {
            n,
            ..Default::default()
        };
        assert!((m.evaluate(&ctx(Vec3::Z)) - 1.0).abs() < 1e-6);
        assert!(m.evaluate(&ctx(Vec3::Y)).abs() < 1e-6);
        assert_eq!(tex.used(), &[true, true]);
    }
}
