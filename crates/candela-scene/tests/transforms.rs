//! Graphics-state semantics: transforms, attribute scopes, instancing.

use std::path::Path;

use candela_scene::*;

fn parse(text: &str) -> SceneDescription {
    parse_str(text, Path::new("/virtual/t.pbrt")).unwrap()
}

fn rows(m: [[f64; 4]; 4]) -> Mat4d {
    Mat4d::from_rows(m)
}

fn assert_mat(got: &Mat4d, want: &Mat4d) {
    assert!(got.approx_eq(want, 1e-9), "got {got:?}\nwant {want:?}");
}

#[test]
fn look_at_along_x_matches_hand_computed_matrix() {
    let d = parse("LookAt 0 0 0  1 0 0  0 1 0\nCamera \"perspective\"");
    // right = up x dir = -z, up = y, dir = x; camera-from-world has them as rows.
    let want = rows([
        [0.0, 0.0, -1.0, 0.0],
        [0.0, 1.0, 0.0, 0.0],
        [1.0, 0.0, 0.0, 0.0],
        [0.0, 0.0, 0.0, 1.0],
    ]);
    assert_mat(&d.camera.unwrap().camera_from_world, &want);
}

#[test]
fn look_at_translation_only() {
    let d = parse("LookAt 1 2 3  1 2 4  0 1 0 Camera \"perspective\"");
    assert_mat(
        &d.camera.unwrap().camera_from_world,
        &Mat4d::translate([-1.0, -2.0, -3.0]),
    );
}

#[test]
fn rotate_takes_degrees_and_scale_composes_on_the_right() {
    let d = parse(
        "WorldBegin Rotate 90 0 0 1 Shape \"sphere\" Scale 2 3 4 Translate 1 0 0 Shape \"disk\"",
    );
    let rz = rows([
        [0.0, -1.0, 0.0, 0.0],
        [1.0, 0.0, 0.0, 0.0],
        [0.0, 0.0, 1.0, 0.0],
        [0.0, 0.0, 0.0, 1.0],
    ]);
    assert_mat(&d.shapes[0].render_from_object, &rz);
    // Rz * S * T maps the origin to Rz(2, 0, 0) = (0, 2, 0).
    let p = d.shapes[1].render_from_object.transform_point([0.0; 3]);
    assert!((p[0]).abs() < 1e-12 && (p[1] - 2.0).abs() < 1e-12, "{p:?}");
    let want = rz
        * rows([
            [2.0, 0.0, 0.0, 2.0],
            [0.0, 3.0, 0.0, 0.0],
            [0.0, 0.0, 4.0, 0.0],
            [0.0, 0.0, 0.0, 1.0],
        ]);
    assert_mat(&d.shapes[1].render_from_object, &want);
}

#[test]
fn transform_and_concat_are_column_major() {
    let d = parse(
        "WorldBegin Transform [1 0 0 0 0 1 0 0 0 0 1 0 5 6 7 1] Shape \"sphere\"
         ConcatTransform [2 0 0 0 0 2 0 0 0 0 2 0 0 0 0 1] Shape \"sphere\"
         Identity Shape \"sphere\"",
    );
    assert_mat(
        &d.shapes[0].render_from_object,
        &Mat4d::translate([5.0, 6.0, 7.0]),
    );
    let want = Mat4d::translate([5.0, 6.0, 7.0]) * Mat4d::scale([2.0; 3]);
    assert_mat(&d.shapes[1].render_from_object, &want);
    assert_mat(&d.shapes[2].render_from_object, &Mat4d::IDENTITY);
}

#[test]
fn attribute_block_restores_ctm_material_and_orientation() {
    let d = parse(
        "WorldBegin
         Material \"diffuse\"
         Translate 1 0 0
         AttributeBegin
           Material \"conductor\"
           ReverseOrientation
           Translate 0 1 0
           AreaLightSource \"diffuse\" \"blackbody L\" 5500
           Shape \"sphere\"
         AttributeEnd
         Shape \"sphere\"",
    );
    let (a, b) = (&d.shapes[0], &d.shapes[1]);
    assert_mat(&a.render_from_object, &Mat4d::translate([1.0, 1.0, 0.0]));
    assert_mat(&b.render_from_object, &Mat4d::translate([1.0, 0.0, 0.0]));
    assert_eq!(a.material, MaterialRef::Index(1));
    assert_eq!(b.material, MaterialRef::Index(0));
    assert!(a.reverse_orientation && !b.reverse_orientation);
    assert!(a.area_light.is_some() && b.area_light.is_none());
    let l = a
        .area_light
        .as_ref()
        .unwrap()
        .params
        .get_spectrum("L")
        .unwrap();
    assert_eq!(
        l,
        Some(ParamSpectrum::Value(SpectrumValue::Blackbody(5500.0)))
    );
}

#[test]
fn object_instances_record_definitions_and_uses() {
    let d = parse(
        "WorldBegin
         Translate 0 0 5
         ObjectBegin \"thing\"
           Translate 1 0 0
           Shape \"sphere\"
           Shape \"disk\"
         ObjectEnd
         Shape \"cylinder\"
         Translate 10 0 0
         ObjectInstance \"thing\"
         ObjectInstance \"thing\"",
    );
    assert_eq!(d.instance_definitions.len(), 1);
    let def = &d.instance_definitions[0];
    assert_eq!(def.name, "thing");
    assert_eq!(def.shapes.len(), 2);
    assert_mat(
        &def.shapes[0].render_from_object,
        &Mat4d::translate([1.0, 0.0, 5.0]),
    );
    assert_eq!(d.shapes.len(), 1);
    assert_mat(
        &d.shapes[0].render_from_object,
        &Mat4d::translate([0.0, 0.0, 5.0]),
    );
    assert_eq!(d.instances.len(), 2);
    assert_mat(
        &d.instances[0].render_from_instance,
        &Mat4d::translate([10.0, 0.0, 5.0]),
    );
}

#[test]
fn named_coordinate_systems_and_camera_space() {
    let d = parse(
        "Translate 0 0 4 CoordinateSystem \"mine\" Camera \"perspective\"
         WorldBegin
         CoordSysTransform \"camera\" LightSource \"point\"
         CoordSysTransform \"mine\" LightSource \"point\"
         CoordSysTransform \"world\" LightSource \"point\"",
    );
    let m = Mat4d::translate([0.0, 0.0, 4.0]);
    assert_mat(&d.camera.as_ref().unwrap().camera_from_world, &m);
    assert_mat(&d.lights[0].render_from_light, &m.inverse().unwrap());
    assert_mat(&d.lights[1].render_from_light, &m);
    assert_mat(&d.lights[2].render_from_light, &Mat4d::IDENTITY);
}

#[test]
fn attribute_defaults_apply_in_scope_and_entity_params_win() {
    let d = parse(
        "WorldBegin
         AttributeBegin
           Attribute \"shape\" \"float radius\" 2 \"float zmax\" 1
           Shape \"sphere\"
           Shape \"sphere\" \"float radius\" 3
         AttributeEnd
         Shape \"sphere\"",
    );
    assert_eq!(d.shapes[0].params.get_float("radius", 1.0).unwrap(), 2.0);
    assert_eq!(d.shapes[1].params.get_float("radius", 1.0).unwrap(), 3.0);
    assert_eq!(d.shapes[2].params.get_float("radius", 1.0).unwrap(), 1.0);
    // Inherited defaults are never reported unused.
    assert!(d.shapes[0].params.unused().is_empty());
}

#[test]
fn named_materials_textures_color_space_and_options() {
    let d = parse(
        "Option \"bool disablepixeljitter\" true
         ColorSpace \"aces2065-1\"
         WorldBegin
         Texture \"checks\" \"spectrum\" \"checkerboard\" \"float uscale\" 4
         MakeNamedMaterial \"gold\" \"string type\" \"conductor\" \"spectrum eta\" \"metal-Au-eta\"
         NamedMaterial \"gold\"
         Shape \"sphere\"",
    );
    assert_eq!(d.options.len(), 1);
    assert_eq!(d.options[0].0, "disablepixeljitter");
    let (name, m) = &d.named_materials[0];
    assert_eq!((name.as_str(), m.ty.as_str()), ("gold", "conductor"));
    assert!(m.params.get("type").is_none());
    assert_eq!(
        m.params.get_spectrum("eta").unwrap(),
        Some(ParamSpectrum::Value(SpectrumValue::Named(
            "metal-Au-eta".into()
        )))
    );
    assert_eq!(d.shapes[0].material, MaterialRef::Named("gold".into()));
    assert_eq!(d.shapes[0].color_space, "aces2065-1");
    let t = &d.textures[0];
    assert_eq!(
        (t.kind, t.class.as_str()),
        (TextureKind::Spectrum, "checkerboard")
    );
}

#[test]
fn moving_shapes_keep_both_transforms_and_world_end_warns() {
    let d = parse(
        "WorldBegin ActiveTransform EndTime Translate 1 0 0 ActiveTransform All
         Shape \"sphere\" WorldEnd",
    );
    assert_mat(&d.shapes[0].render_from_object, &Mat4d::IDENTITY);
    let end = d.shapes[0].render_from_object_end.expect("the shape moves");
    assert_eq!(end.m[0][3], 1.0, "{end:?}");
    assert_eq!(d.warnings.len(), 1, "{:?}", d.warnings);
    assert!(d.warnings[0].message.contains("WorldEnd"));
}

#[test]
fn moving_lights_warn_and_keep_their_start_transform() {
    let d = parse(
        "WorldBegin ActiveTransform EndTime Translate 1 0 0 ActiveTransform All
         LightSource \"point\"",
    );
    assert_eq!(d.warnings.len(), 1, "{:?}", d.warnings);
    assert!(d.warnings[0].message.contains("motion of a light"));
}

#[test]
fn inline_spectrum_pairs_and_unused_params() {
    let d = parse(
        "WorldBegin LightSource \"point\" \"spectrum I\" [400 1 500 2 600 3] \"float scale\" 2 \"float typo\" 1",
    );
    let p = &d.lights[0].params;
    assert_eq!(
        p.get_spectrum("I").unwrap(),
        Some(ParamSpectrum::Value(SpectrumValue::Sampled(vec![
            (400.0, 1.0),
            (500.0, 2.0),
            (600.0, 3.0)
        ])))
    );
    assert_eq!(p.get_float("scale", 1.0).unwrap(), 2.0);
    let unused = p.unused();
    assert_eq!(unused.len(), 1);
    assert_eq!(unused[0].0, "typo");
    assert_eq!((unused[0].1.line, unused[0].1.col), (1, 81));
}
