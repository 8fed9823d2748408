//! `imagemap` textures: parameters, file loading and a cache of loaded images.
//!
//! Parameters and defaults are pbrt-v4's (`FloatImageTexture::Create`,
//! `SpectrumImageTexture::Create`): `filename` (relative to the scene file's
//! directory), `filter` (`bilinear`, `point`, `trilinear`, `ewa`),
//! `maxanisotropy` (EWA only), `wrap` (`repeat`, `black`, `clamp`,
//! `octahedralsphere`), `scale`, `invert`, `encoding` (`sRGB` for `.png`
//! files, else `linear`; or `gamma γ`) and the 2D mapping. As in pbrt-v4's
//! texture cache, a file is loaded (and resized to power-of-two sides) once
//! per wrap mode and encoding, however many textures and meanings use it,
//! with its MIP pyramid: every filter reads the level pbrt-v4's
//! `MIPMap::Filter` picks for the footprint.

use super::textures::mapping_2d;
use super::BuildError;
use crate::image::{
    read_map, resize_to_power_of_two, ColorEncoding, MapImage, MipPyramid, WrapMode,
};
use crate::spectrum::ColorSpace;
use crate::texture::{ImageFilter, ImageTexture};
use candela_scene::TextureDesc;
use std::collections::HashMap;
use std::path::PathBuf;
use std::sync::Arc;

/// A loaded image (as a pyramid) and its colour space.
type Loaded = (Arc<MipPyramid>, &'static ColorSpace);

/// Images loaded so far, by file, wrap mode and encoding.
#[derive(Default)]
pub struct ImageCache {
    loaded: HashMap<(PathBuf, WrapMode, String), Loaded>,
    normal_maps: HashMap<PathBuf, Arc<MapImage>>,
    /// Non-fatal problems met while loading or reading parameters.
    pub warnings: Vec<String>,
}

impl ImageCache {
    /// The lookup of `imagemap` texture `d`.
    pub fn texture(&mut self, d: &TextureDesc) -> Result<ImageTexture, BuildError> {
        let p = &d.params;
        let loc_of = |n: &str| p.param_loc(n).unwrap_or(&d.loc);
        let Some(path) = p.get_filename("filename")? else {
            return Err(BuildError::at(
                &d.loc,
                format!("imagemap texture \"{}\" needs a \"filename\"", d.name),
            ));
        };
        let max_anisotropy = p.get_float("maxanisotropy", 8.0)?;
        let filter = match p.get_string("filter", "bilinear")?.as_str() {
            "bilinear" => ImageFilter::Bilinear,
            "point" => ImageFilter::Point,
            "trilinear" => ImageFilter::Trilinear,
            "ewa" => ImageFilter::Ewa { max_anisotropy },
            other => {
                return Err(BuildError::at(
                    loc_of("filter"),
                    format!(
                    "unknown texture filter \"{other}\" (known: bilinear, point, trilinear, ewa)"
                ),
                ))
            }
        };
        let wrap_name = p.get_string("wrap", "repeat")?;
        let wrap = WrapMode::parse(&wrap_name).ok_or_else(|| {
            BuildError::at(
                loc_of("wrap"),
                format!("unknown wrap mode \"{wrap_name}\" (known: repeat, black, clamp, octahedralsphere)"),
            )
        })?;
        let is_png = path
            .extension()
            .is_some_and(|e| e.eq_ignore_ascii_case("png"));
        let enc_name = p.get_string("encoding", if is_png { "sRGB" } else { "linear" })?;
        let encoding = ColorEncoding::parse(&enc_name).ok_or_else(|| {
            BuildError::at(
                loc_of("encoding"),
                format!("unknown color encoding \"{enc_name}\" (known: linear, sRGB, \"gamma <value>\")"),
            )
        })?;
        let (pyramid, color_space) =
            self.load(path, wrap, &enc_name, encoding, loc_of("filename"))?;
        Ok(ImageTexture {
            map: mapping_2d(d)?,
            pyramid,
            wrap,
            filter,
            scale: p.get_float("scale", 1.0)?,
            invert: p.get_bool("invert", false)?,
            color_space,
        })
    }

    /// A normal map: read with linear encoding (pbrt-v4 reads normal maps
    /// as `ColorEncoding::Linear`), not resized, RGB required.
    pub fn normal_map(
        &mut self,
        path: PathBuf,
        loc: &candela_scene::Loc,
    ) -> Result<Arc<MapImage>, BuildError> {
        if let Some(image) = self.normal_maps.get(&path) {
            return Ok(image.clone());
        }
        if !path.is_file() {
            return Err(BuildError::at(
                loc,
                format!("normal map \"{}\" not found", path.display()),
            ));
        }
        let file = read_map(&path, ColorEncoding::Linear)
            .map_err(|e| BuildError::at(loc, e.to_string()))?;
        if file.image.channels != 3 {
            return Err(BuildError::at(
                loc,
                format!(
                    "normal map \"{}\" must have R, G and B channels (it has {})",
                    path.display(),
                    file.image.channels
                ),
            ));
        }
        let image = Arc::new(file.image);
        self.normal_maps.insert(path, image.clone());
        Ok(image)
    }

    /// The image at `path` resized for `wrap` and its MIP pyramid (every
    /// filter picks a level, as in pbrt-v4), loaded on first request.
    fn load(
        &mut self,
        path: PathBuf,
        wrap: WrapMode,
        enc_name: &str,
        encoding: ColorEncoding,
        loc: &candela_scene::Loc,
    ) -> Result<Loaded, BuildError> {
        let key = (path, wrap, enc_name.to_string());
        if let Some(l) = self.loaded.get(&key) {
            return Ok(l.clone());
        }
        let path = &key.0;
        if !path.is_file() {
            return Err(BuildError::at(
                loc,
                format!("image file \"{}\" not found", path.display()),
            ));
        }
        let file = read_map(path, encoding).map_err(|e| BuildError::at(loc, e.to_string()))?;
        if let Some(w) = file.warning {
            self.warnings.push(format!("{loc}: {w}"));
        }
        let base = resize_to_power_of_two(&file.image, wrap);
        let pyramid = MipPyramid::build(base);
        // Fit the RGB table now rather than on the first lookup, mid-render.
        file.color_space.rgb_table();
        let l = (Arc::new(pyramid), file.color_space);
        self.loaded.insert(key, l.clone());
        Ok(l)
    }
}
