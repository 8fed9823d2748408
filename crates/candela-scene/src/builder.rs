//! Directive semantics: the graphics state and the description being built.
//!
//! The parser calls one [`Builder`] method per directive. The builder keeps
//! pbrt-v4's graphics state — the current transformation matrix (CTM, one
//! for the start and one for the end time), reverse orientation, color
//! space, current material and area light, and `Attribute` defaults — and a
//! stack of saved states for `AttributeBegin`/`ObjectBegin`/`Import`. Each
//! entity directive snapshots the relevant state into the
//! [`SceneDescription`]. Cross-references that pbrt-v4 resolves after
//! parsing (named materials, object instances) are checked in
//! [`Builder::finish`].
//!
//! Snapshots copy parameters: `Attribute` defaults go into every later
//! entity, the area light into every shape, and each `AttributeBegin` saves
//! a copy of the whole state. A small scene could thus demand memory far
//! beyond its size (one 10⁶-value `Attribute` followed by 10⁵ shapes is
//! 10¹¹ copied values). The builder counts the values it copies and stops
//! past [`MAX_COPIED_VALUES`], and block nesting stops past
//! [`MAX_BLOCK_DEPTH`]; both are far above what real scenes do.

use std::collections::{HashMap, HashSet};
use std::path::Path;

use crate::desc::*;
use crate::error::{Loc, SceneError, Warning};
use crate::math::Mat4d;
use crate::param::{Param, ParamSet};

type Result<T> = std::result::Result<T, SceneError>;

/// Maximum nesting of `AttributeBegin`/`ObjectBegin`/`Import` blocks.
pub const MAX_BLOCK_DEPTH: usize = 10_000;

/// Maximum number of parameter values (plus a fixed cost per saved state)
/// that snapshots of the graphics state may copy in one scene.
pub const MAX_COPIED_VALUES: u64 = 1 << 26;

/// Values copied so far into snapshots of the graphics state.
#[derive(Debug, Default)]
pub(crate) struct CopyBudget {
    copied: u64,
}

impl CopyBudget {
    /// Counts `n` more copied values; an error at `loc` past the limit.
    pub(crate) fn charge(&mut self, n: u64, loc: &Loc) -> Result<()> {
        self.copied = self.copied.saturating_add(n);
        if self.copied > MAX_COPIED_VALUES {
            return Err(SceneError::at(
                loc,
                format!(
                    "the scene copies more than {MAX_COPIED_VALUES} parameter values into its \
                     entities (large Attribute or AreaLightSource parameters repeated into many \
                     shapes or nested blocks?)"
                ),
            ));
        }
        Ok(())
    }
}

/// The number of values in `params` (one at least per parameter), the
/// unit of [`CopyBudget`].
pub(crate) fn weight(params: &[Param]) -> u64 {
    use crate::param::ParamValue as V;
    use crate::spectrum::SpectrumValue as S;
    let one = |p: &Param| match &p.value {
        V::Floats(v) => v.len(),
        V::Ints(v) => v.len(),
        V::Bools(v) => v.len(),
        V::Strings(v) => v.iter().map(|s| 1 + s.len() / 8).sum(),
        V::Spectrum(S::Sampled(v)) => v.len(),
        V::Spectrum(S::Named(s)) => 1 + s.len() / 8,
        V::Spectrum(S::Blackbody(_)) => 1,
    };
    params.iter().map(|p| 1 + one(p) as u64).sum()
}

/// Why a graphics state was pushed.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub(crate) enum Block {
    /// `AttributeBegin` (or the deprecated `TransformBegin`).
    Attribute,
    /// `ObjectBegin`.
    Object,
    /// An `Import`ed file: its state changes do not leak out.
    Import,
}

/// The options-block entities that take a name and parameters.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub(crate) enum OptionEntity {
    Film,
    Sampler,
    Integrator,
    PixelFilter,
    Accelerator,
}

/// Defaults set with `Attribute "target" ...`.
#[derive(Debug, Clone, Default)]
pub(crate) struct Attributes {
    pub(crate) shape: Vec<Param>,
    pub(crate) light: Vec<Param>,
    pub(crate) material: Vec<Param>,
    pub(crate) medium: Vec<Param>,
    pub(crate) texture: Vec<Param>,
}

/// pbrt-v4's per-attribute-block state.
#[derive(Debug, Clone)]
pub(crate) struct GraphicsState {
    pub(crate) ctm: [Mat4d; 2],
    pub(crate) active: [bool; 2],
    pub(crate) reverse_orientation: bool,
    pub(crate) color_space: String,
    pub(crate) material: MaterialRef,
    pub(crate) area_light: Option<Entity>,
    pub(crate) attributes: Attributes,
}

impl GraphicsState {
    /// What saving a copy of this state costs in [`CopyBudget`] units: its
    /// parameters plus a fixed 64 for the rest (about 500 bytes).
    fn weight(&self) -> u64 {
        let a = &self.attributes;
        let lists = [&a.shape, &a.light, &a.material, &a.medium, &a.texture];
        let area = self
            .area_light
            .as_ref()
            .map_or(0, |e| weight(&e.params.params));
        64 + area + lists.iter().map(|l| weight(l)).sum::<u64>()
    }
}

impl Default for GraphicsState {
    fn default() -> Self {
        GraphicsState {
            ctm: [Mat4d::IDENTITY; 2],
            active: [true; 2],
            reverse_orientation: false,
            color_space: "srgb".to_string(),
            material: MaterialRef::None,
            area_light: None,
            attributes: Attributes::default(),
        }
    }
}

/// Builds a [`SceneDescription`] from directives.
#[derive(Debug)]
pub(crate) struct Builder {
    pub(crate) desc: SceneDescription,
    pub(crate) gs: GraphicsState,
    pub(crate) stack: Vec<(GraphicsState, Block, Loc)>,
    named_coords: HashMap<String, [Mat4d; 2]>,
    in_world: bool,
    pub(crate) object: Option<InstanceDefinition>,
    pub(crate) object_names: HashSet<String>,
    pub(crate) texture_names: HashSet<(String, bool)>,
    pub(crate) material_names: HashSet<String>,
    warned_motion: bool,
    warned_transform_begin: bool,
    pub(crate) budget: CopyBudget,
}

impl Builder {
    /// A builder for a scene whose relative files live in `base_dir`.
    pub(crate) fn new(base_dir: &Path) -> Builder {
        let desc = SceneDescription {
            base_dir: base_dir.to_path_buf(),
            transform_times: [0.0, 1.0],
            ..SceneDescription::default()
        };
        Builder {
            desc,
            gs: GraphicsState::default(),
            stack: Vec::new(),
            named_coords: HashMap::new(),
            in_world: false,
            object: None,
            object_names: HashSet::new(),
            texture_names: HashSet::new(),
            material_names: HashSet::new(),
            warned_motion: false,
            warned_transform_begin: false,
            budget: CopyBudget::default(),
        }
    }

    /// Records a scene file that was read.
    pub(crate) fn add_source(&mut self, path: &Path, bytes: &[u8]) {
        self.desc.sources.push(crate::desc::SourceFile {
            path: path.to_path_buf(),
            hash: crate::desc::fnv1a64(bytes),
        });
    }

    /// Records a warning.
    pub(crate) fn warn(&mut self, loc: &Loc, message: impl Into<String>) {
        self.desc.warnings.push(Warning {
            loc: loc.clone(),
            message: message.into(),
        });
    }

    pub(crate) fn require_options(&self, what: &str, loc: &Loc) -> Result<()> {
        if self.in_world {
            return Err(SceneError::at(
                loc,
                format!("'{what}' is only allowed before WorldBegin"),
            ));
        }
        Ok(())
    }

    pub(crate) fn require_world(&self, what: &str, loc: &Loc) -> Result<()> {
        if !self.in_world {
            return Err(SceneError::at(
                loc,
                format!("'{what}' is only allowed after WorldBegin"),
            ));
        }
        Ok(())
    }

    // ---- transforms -------------------------------------------------

    /// Replaces each active CTM with `f(ctm)`.
    pub(crate) fn apply(&mut self, f: impl Fn(&Mat4d) -> Mat4d) {
        for i in 0..2 {
            if self.gs.active[i] {
                self.gs.ctm[i] = f(&self.gs.ctm[i]);
            }
        }
    }

    /// `CoordinateSystem "name"`: remembers the CTM.
    pub(crate) fn coordinate_system(&mut self, name: String) {
        self.named_coords.insert(name, self.gs.ctm);
    }

    /// `CoordSysTransform "name"`: restores a remembered CTM.
    pub(crate) fn coord_sys_transform(&mut self, name: &str, loc: &Loc) {
        match self.named_coords.get(name) {
            Some(m) => self.gs.ctm = *m,
            None => self.warn(
                loc,
                format!("couldn't find named coordinate system '{name}'"),
            ),
        }
    }

    /// `ActiveTransform StartTime|EndTime|All`.
    pub(crate) fn active_transform(&mut self, start: bool, end: bool) {
        self.gs.active = [start, end];
    }

    /// `TransformTimes start end`.
    pub(crate) fn transform_times(&mut self, start: f32, end: f32, loc: &Loc) -> Result<()> {
        self.require_options("TransformTimes", loc)?;
        self.desc.transform_times = [start, end];
        Ok(())
    }

    /// `ReverseOrientation`.
    pub(crate) fn reverse_orientation(&mut self) {
        self.gs.reverse_orientation = !self.gs.reverse_orientation;
    }

    /// The start-time CTM for a directive that cannot move (`what`: camera,
    /// light, texture), warning once if the end-time CTM differs.
    pub(crate) fn ctm(&mut self, loc: &Loc, what: &str) -> Mat4d {
        if self.gs.ctm[0] != self.gs.ctm[1] && !self.warned_motion {
            self.warned_motion = true;
            self.warn(
                loc,
                format!("motion of a {what} is not supported (only shapes and object instances move); using its start transform"),
            );
        }
        self.gs.ctm[0]
    }

    /// The start-time CTM, and the end-time CTM when it differs.
    pub(crate) fn ctm_motion(&self) -> (Mat4d, Option<Mat4d>) {
        let [start, end] = self.gs.ctm;
        (start, (start != end).then_some(end))
    }

    // ---- options block ------------------------------------------------

    /// `Option "type name" value`.
    pub(crate) fn option(&mut self, param: Param) {
        self.desc.options.push((param.name.clone(), param));
    }

    /// `ColorSpace "name"`.
    pub(crate) fn color_space(&mut self, name: String) {
        self.gs.color_space = name;
    }

    pub(crate) fn entity(&self, name: String, params: ParamSet, loc: &Loc) -> Entity {
        Entity {
            name,
            params,
            color_space: self.gs.color_space.clone(),
            loc: loc.clone(),
        }
    }

    /// `Camera "name" params`.
    pub(crate) fn camera(&mut self, name: String, params: ParamSet, loc: &Loc) -> Result<()> {
        self.require_options("Camera", loc)?;
        let camera_from_world = self.ctm(loc, "camera");
        let world_from_camera = self.gs.ctm.map(|m| m.inverse());
        match world_from_camera {
            [Some(a), Some(b)] => {
                self.named_coords.insert("camera".into(), [a, b]);
            }
            _ => return Err(SceneError::at(loc, "camera transform is not invertible")),
        }
        self.desc.camera = Some(CameraDesc {
            name,
            params,
            camera_from_world,
            color_space: self.gs.color_space.clone(),
            loc: loc.clone(),
        });
        Ok(())
    }

    /// `Film`, `Sampler`, `Integrator`, `PixelFilter` or `Accelerator`.
    pub(crate) fn option_entity(
        &mut self,
        which: OptionEntity,
        name: String,
        params: ParamSet,
        loc: &Loc,
    ) -> Result<()> {
        self.require_options(&format!("{which:?}"), loc)?;
        let (mut name, mut params) = (name, params);
        if let Some(w) = crate::upgrade::option_entity(which, &mut name, &mut params, loc) {
            self.warn(loc, w);
        }
        let e = Some(self.entity(name, params, loc));
        match which {
            OptionEntity::Film => self.desc.film = e,
            OptionEntity::Sampler => self.desc.sampler = e,
            OptionEntity::Integrator => self.desc.integrator = e,
            OptionEntity::PixelFilter => self.desc.filter = e,
            OptionEntity::Accelerator => self.desc.accelerator = e,
        }
        Ok(())
    }

    /// `WorldBegin`: resets the CTM and names the "world" system.
    pub(crate) fn world_begin(&mut self, loc: &Loc) -> Result<()> {
        self.require_options("WorldBegin", loc)?;
        self.in_world = true;
        self.gs.ctm = [Mat4d::IDENTITY; 2];
        self.gs.active = [true; 2];
        self.named_coords.insert("world".into(), self.gs.ctm);
        Ok(())
    }

    // ---- attribute blocks ---------------------------------------------

    /// Saves the graphics state (`AttributeBegin`, `ObjectBegin`, `Import`).
    pub(crate) fn push(&mut self, block: Block, loc: &Loc) -> Result<()> {
        if self.stack.len() >= MAX_BLOCK_DEPTH {
            return Err(SceneError::at(
                loc,
                format!("blocks nested deeper than {MAX_BLOCK_DEPTH}"),
            ));
        }
        self.budget.charge(self.gs.weight(), loc)?;
        self.stack.push((self.gs.clone(), block, loc.clone()));
        Ok(())
    }

    /// Restores the graphics state saved by the matching `push`.
    pub(crate) fn pop(&mut self, block: Block, what: &str, loc: &Loc) -> Result<()> {
        match self.stack.last() {
            Some((_, b, _)) if *b == block => {}
            Some((_, b, open)) => {
                let open = open.clone();
                return Err(SceneError::at(
                    loc,
                    format!("mismatched nesting: '{what}' closes {b:?} block opened at {open}"),
                ));
            }
            None => return Err(SceneError::at(loc, format!("unmatched '{what}'"))),
        }
        if let Some((gs, _, _)) = self.stack.pop() {
            self.gs = gs;
        }
        Ok(())
    }

    /// `TransformBegin`: deprecated alias of `AttributeBegin` in pbrt-v4.
    pub(crate) fn transform_begin(&mut self, loc: &Loc) -> Result<()> {
        if !self.warned_transform_begin {
            self.warned_transform_begin = true;
            self.warn(
                loc,
                "TransformBegin/End are deprecated; use AttributeBegin/End",
            );
        }
        self.push(Block::Attribute, loc)
    }

    /// `Attribute "target" params`: defaults for later entities.
    pub(crate) fn attribute(&mut self, target: &str, params: ParamSet, loc: &Loc) -> Result<()> {
        let a = &mut self.gs.attributes;
        let list = match target {
            "shape" => &mut a.shape,
            "light" => &mut a.light,
            "material" => &mut a.material,
            "medium" => &mut a.medium,
            "texture" => &mut a.texture,
            _ => {
                return Err(SceneError::at(
                    loc,
                    format!(
                        "unknown attribute target '{target}'; expected \"shape\", \"light\", \
                         \"material\", \"medium\" or \"texture\""
                    ),
                ))
            }
        };
        list.extend(params.params.into_iter().map(|mut p| {
            p.may_be_unused = true;
            p
        }));
        Ok(())
    }
}

/// `params` preceded by the attribute `defaults` (so `params` win lookups).
/// `params` after the `Attribute` `defaults` (which lose to them), with the
/// copy charged to `budget`.
pub(crate) fn with_defaults(
    defaults: &[Param],
    params: ParamSet,
    budget: &mut CopyBudget,
    loc: &Loc,
) -> Result<ParamSet> {
    if defaults.is_empty() {
        return Ok(params);
    }
    budget.charge(weight(defaults), loc)?;
    let mut all = defaults.to_vec();
    all.extend(params.params);
    Ok(ParamSet {
        params: all,
        base_dir: params.base_dir,
    })
}
