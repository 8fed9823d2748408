//! World-block directives: textures, materials, lights, shapes, instances.
//!
//! Continues [`Builder`] with the directives that create scene entities.
//! Each one merges the matching `Attribute` defaults into its parameters and
//! snapshots the graphics state. Shapes inside `ObjectBegin`/`ObjectEnd` go
//! to the open instance definition with their CTM (which is then relative to
//! the instance, as in pbrt-v4). Participating media are rejected with an
//! "unsupported" error at the directive.

use crate::builder::{weight, with_defaults, Block, Builder};
use crate::desc::*;
use crate::error::{Loc, SceneError};
use crate::param::ParamSet;
use crate::upgrade;

type Result<T> = std::result::Result<T, SceneError>;

impl Builder {
    /// `Texture "name" "float"|"spectrum" "class" params`.
    pub(crate) fn texture(
        &mut self,
        name: String,
        kind: &str,
        class: String,
        params: ParamSet,
        loc: &Loc,
    ) -> Result<()> {
        self.require_world("Texture", loc)?;
        let kind = match kind {
            "float" => TextureKind::Float,
            "spectrum" => TextureKind::Spectrum,
            "color" => {
                self.warn(
                    loc,
                    "texture type \"color\" is pbrt-v3 syntax; use \"spectrum\"",
                );
                TextureKind::Spectrum
            }
            _ => {
                return Err(SceneError::at(
                    loc,
                    format!("texture type must be \"float\" or \"spectrum\", found \"{kind}\""),
                ))
            }
        };
        let mut params = params;
        if let Some(w) = upgrade::texture(&class, kind == TextureKind::Float, &mut params, loc)? {
            self.warn(loc, w);
        }
        if !self
            .texture_names
            .insert((name.clone(), kind == TextureKind::Float))
        {
            return Err(SceneError::at(loc, format!("redefining texture '{name}'")));
        }
        let params = with_defaults(&self.gs.attributes.texture, params, &mut self.budget, loc)?;
        let render_from_texture = self.ctm(loc, "texture");
        self.desc.textures.push(TextureDesc {
            name,
            kind,
            class,
            params,
            render_from_texture,
            color_space: self.gs.color_space.clone(),
            loc: loc.clone(),
        });
        Ok(())
    }

    fn material_desc(&mut self, ty: String, params: ParamSet, loc: &Loc) -> Result<MaterialDesc> {
        Ok(MaterialDesc {
            ty,
            params: with_defaults(&self.gs.attributes.material, params, &mut self.budget, loc)?,
            color_space: self.gs.color_space.clone(),
            loc: loc.clone(),
        })
    }

    /// `Material "type" params`: an anonymous material becomes current.
    pub(crate) fn material(&mut self, ty: String, params: ParamSet, loc: &Loc) -> Result<()> {
        self.require_world("Material", loc)?;
        let (mut ty, mut params) = (ty, params);
        if let Some(w) = upgrade::material(&mut ty, &mut params, loc)? {
            self.warn(loc, w);
        }
        let m = self.material_desc(ty, params, loc)?;
        self.desc.materials.push(m);
        self.gs.material = MaterialRef::Index(self.desc.materials.len() - 1);
        Ok(())
    }

    /// `MakeNamedMaterial "name" "string type" ... params`.
    pub(crate) fn make_named_material(
        &mut self,
        name: String,
        params: ParamSet,
        loc: &Loc,
    ) -> Result<()> {
        self.require_world("MakeNamedMaterial", loc)?;
        let mut m = self.material_desc(String::new(), params, loc)?;
        m.ty = m.params.get_string("type", "")?;
        if m.ty.is_empty() {
            return Err(SceneError::at(
                loc,
                format!("named material '{name}': \"string type\" parameter is required"),
            ));
        }
        m.params.params.retain(|p| p.name != "type");
        if let Some(w) = upgrade::material(&mut m.ty, &mut m.params, loc)? {
            self.warn(loc, w);
        }
        if !self.material_names.insert(name.clone()) {
            return Err(SceneError::at(
                loc,
                format!("named material '{name}' redefined"),
            ));
        }
        self.desc.named_materials.push((name, m));
        Ok(())
    }

    /// `NamedMaterial "name"`: makes a named material current.
    pub(crate) fn named_material(&mut self, name: String, loc: &Loc) -> Result<()> {
        self.require_world("NamedMaterial", loc)?;
        self.gs.material = MaterialRef::Named(name);
        Ok(())
    }

    /// `LightSource "type" params`.
    pub(crate) fn light_source(&mut self, name: String, params: ParamSet, loc: &Loc) -> Result<()> {
        self.require_world("LightSource", loc)?;
        let mut params = params;
        if let Some(w) = upgrade::light(&name, &mut params, loc)? {
            self.warn(loc, w);
        }
        let params = with_defaults(&self.gs.attributes.light, params, &mut self.budget, loc)?;
        let render_from_light = self.ctm(loc, "light");
        self.desc.lights.push(LightDesc {
            name,
            params,
            render_from_light,
            reverse_orientation: self.gs.reverse_orientation,
            color_space: self.gs.color_space.clone(),
            loc: loc.clone(),
        });
        Ok(())
    }

    /// `AreaLightSource "type" params`: applies to later shapes in the block.
    pub(crate) fn area_light_source(
        &mut self,
        name: String,
        params: ParamSet,
        loc: &Loc,
    ) -> Result<()> {
        self.require_world("AreaLightSource", loc)?;
        let (mut name, mut params) = (name, params);
        if let Some(w) = upgrade::area_light(&mut name, &mut params, loc)? {
            self.warn(loc, w);
        }
        let params = with_defaults(&self.gs.attributes.light, params, &mut self.budget, loc)?;
        self.gs.area_light = Some(self.entity(name, params, loc));
        Ok(())
    }

    /// `Shape "type" params`.
    pub(crate) fn shape(&mut self, name: String, params: ParamSet, loc: &Loc) -> Result<()> {
        self.require_world("Shape", loc)?;
        let mut params = params;
        if let Some(w) = upgrade::shape(&name, &mut params, loc) {
            self.warn(loc, w);
        }
        let params = with_defaults(&self.gs.attributes.shape, params, &mut self.budget, loc)?;
        let (render_from_object, render_from_object_end) = self.ctm_motion();
        if let Some(al) = &self.gs.area_light {
            self.budget.charge(weight(&al.params.params), loc)?;
        }
        let mut area_light = self.gs.area_light.clone();
        if self.object.is_some() && area_light.is_some() {
            self.warn(
                loc,
                "area lights are not supported with object instancing; ignored",
            );
            area_light = None;
        }
        let shape = ShapeDesc {
            name,
            params,
            render_from_object,
            render_from_object_end,
            reverse_orientation: self.gs.reverse_orientation,
            material: self.gs.material.clone(),
            area_light,
            color_space: self.gs.color_space.clone(),
            loc: loc.clone(),
        };
        match &mut self.object {
            Some(def) => def.shapes.push(shape),
            None => self.desc.shapes.push(shape),
        }
        Ok(())
    }

    /// `ObjectBegin "name"`: starts an instance definition.
    pub(crate) fn object_begin(&mut self, name: String, loc: &Loc) -> Result<()> {
        self.require_world("ObjectBegin", loc)?;
        if let Some(def) = &self.object {
            return Err(SceneError::at(
                loc,
                format!("ObjectBegin inside the definition of '{}'", def.name),
            ));
        }
        if !self.object_names.insert(name.clone()) {
            return Err(SceneError::at(loc, format!("redefining object '{name}'")));
        }
        self.push(Block::Object, loc)?;
        self.object = Some(InstanceDefinition {
            name,
            shapes: Vec::new(),
            loc: loc.clone(),
        });
        Ok(())
    }

    /// `ObjectEnd`: closes the instance definition.
    pub(crate) fn object_end(&mut self, loc: &Loc) -> Result<()> {
        self.require_world("ObjectEnd", loc)?;
        if self.object.is_none() {
            return Err(SceneError::at(loc, "ObjectEnd without ObjectBegin"));
        }
        self.pop(Block::Object, "ObjectEnd", loc)?;
        if let Some(def) = self.object.take() {
            self.desc.instance_definitions.push(def);
        }
        Ok(())
    }

    /// `ObjectInstance "name"`.
    pub(crate) fn object_instance(&mut self, name: String, loc: &Loc) -> Result<()> {
        self.require_world("ObjectInstance", loc)?;
        if self.object.is_some() {
            return Err(SceneError::at(
                loc,
                "ObjectInstance can't be used inside an instance definition",
            ));
        }
        let (render_from_instance, render_from_instance_end) = self.ctm_motion();
        self.desc.instances.push(InstanceUse {
            name,
            render_from_instance,
            render_from_instance_end,
            loc: loc.clone(),
        });
        Ok(())
    }

    /// `MakeNamedMedium`: media are not supported yet.
    pub(crate) fn make_named_medium(&mut self, loc: &Loc) -> Result<()> {
        Err(SceneError::unsupported(
            loc,
            "participating media not supported yet",
        ))
    }

    /// `MediumInterface "inside" ["outside"]`: only empty media are accepted.
    pub(crate) fn medium_interface(
        &mut self,
        inside: &str,
        outside: &str,
        loc: &Loc,
    ) -> Result<()> {
        if inside.is_empty() && outside.is_empty() {
            return Ok(());
        }
        Err(SceneError::unsupported(
            loc,
            "participating media not supported yet",
        ))
    }

    /// `WorldEnd` (pbrt-v3): accepted and ignored.
    pub(crate) fn world_end(&mut self, loc: &Loc) {
        self.warn(loc, "WorldEnd is pbrt-v3 syntax and is ignored");
    }

    /// Checks open blocks and cross-references, and returns the scene.
    pub(crate) fn finish(self, end: &Loc) -> Result<SceneDescription> {
        if let Some((_, block, open)) = self.stack.last() {
            let what = match block {
                Block::Object => "ObjectBegin",
                _ => "AttributeBegin",
            };
            return Err(SceneError::at(
                end,
                format!("end of file inside the {what} block opened at {open}"),
            ));
        }
        let defined = |m: &MaterialRef| match m {
            MaterialRef::Named(n) => self.material_names.contains(n),
            _ => true,
        };
        let all_shapes = self.desc.shapes.iter().chain(
            self.desc
                .instance_definitions
                .iter()
                .flat_map(|d| d.shapes.iter()),
        );
        for s in all_shapes {
            if let (false, MaterialRef::Named(n)) = (defined(&s.material), &s.material) {
                return Err(SceneError::at(
                    &s.loc,
                    format!("named material '{n}' is not defined"),
                ));
            }
        }
        for i in &self.desc.instances {
            if !self.object_names.contains(&i.name) {
                return Err(SceneError::at(
                    &i.loc,
                    format!("object '{}' is not defined", i.name),
                ));
            }
        }
        Ok(self.desc)
    }
}
