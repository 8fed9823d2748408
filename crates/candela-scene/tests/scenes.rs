//! The shared pbrt-v4 scenes parse into the expected descriptions.

use std::path::{Path, PathBuf};

use candela_scene::*;

fn scene(rel: &str) -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR"))
        .join("../../scenes")
        .join(rel)
}

#[test]
fn cornell_box() {
    let d = parse_file(&scene("cornell-box/scene.pbrt")).unwrap();
    assert_eq!(d.shapes.len(), 8);
    assert_eq!(
        d.shapes.iter().filter(|s| s.area_light.is_some()).count(),
        1
    );
    let light = d.shapes[0].area_light.as_ref().unwrap();
    assert_eq!(light.name, "diffuse");
    assert_eq!(
        light.params.get_spectrum("L").unwrap(),
        Some(ParamSpectrum::Rgb([18.387, 13.9873, 6.75357]))
    );
    assert_eq!(d.materials.len(), 8);
    assert_eq!(d.shapes[7].material, MaterialRef::Index(7));
    let cam = d.camera.as_ref().unwrap();
    assert_eq!(cam.name, "perspective");
    assert_eq!(cam.params.get_float("fov", 90.0).unwrap(), 39.3077);
    // Scale -1 1 1 then LookAt: the first row is negated w.r.t. the LookAt.
    let look = Mat4d::look_at(
        [0.0, 0.0, 3.9000001],
        [0.0, 0.0, 2.9000001],
        [0.0, 0.99999994, 0.0],
    )
    .unwrap();
    let expected = Mat4d::scale([-1.0, 1.0, 1.0]) * look;
    assert!(cam.camera_from_world.approx_eq(&expected, 1e-12));
    assert!(cam.camera_from_world.swaps_handedness());
    let film = d.film.as_ref().unwrap();
    assert_eq!(film.params.get_int("xresolution", 0).unwrap(), 256);
    assert!(!film.params.get_bool("savefp16", true).unwrap());
    assert_eq!(d.integrator.as_ref().unwrap().name, "path");
    assert_eq!(d.filter.as_ref().unwrap().name, "box");
    let tri = &d.shapes[7];
    assert_eq!(tri.params.get_ints("indices").unwrap().unwrap().len(), 36);
    assert_eq!(tri.params.get_point3s("P").unwrap().unwrap().len(), 24);
    assert_eq!(tri.params.get_normals("N").unwrap().unwrap().len(), 24);
    assert!(tri.params.unused().is_empty());
    assert!(d.warnings.is_empty(), "{:?}", d.warnings);
}

#[test]
fn caustic_glass() {
    let d = parse_file(&scene("caustic-glass/scene.pbrt")).unwrap();
    assert_eq!(d.lights.len(), 2);
    assert_eq!(d.lights[0].name, "spot");
    assert_eq!(d.lights[1].name, "infinite");
    assert_eq!(
        d.lights[0].params.get_point3("from", [0.0; 3]).unwrap(),
        [0.0, 5.0, 9.0]
    );
    let plys: Vec<_> = d.shapes.iter().filter(|s| s.name == "plymesh").collect();
    assert_eq!(plys.len(), 2);
    let f = plys[0].params.get_filename("filename").unwrap().unwrap();
    assert_eq!(f, scene("caustic-glass/geometry/mesh_00001.ply"));
    assert!(f.is_file());
    let film = d.film.as_ref().unwrap();
    assert_eq!(film.params.get_float("iso", 100.0).unwrap(), 150.0);
    assert_eq!(film.color_space, "srgb");
    assert_eq!(d.sampler.as_ref().unwrap().name, "sobol");
    let m = match &plys[0].material {
        MaterialRef::Index(i) => &d.materials[*i],
        other => panic!("{other:?}"),
    };
    assert_eq!(m.ty, "dielectric");
    assert_eq!(m.params.get_float("eta", 1.5).unwrap(), 1.25);
}

#[test]
fn killeroo_include_brings_two_loopsubdivs_with_distinct_materials() {
    let d = parse_file(&scene("killeroo-simple/killeroo-simple.pbrt")).unwrap();
    let subs: Vec<_> = d.shapes.iter().filter(|s| s.name == "loopsubdiv").collect();
    assert_eq!(subs.len(), 2);
    assert_ne!(subs[0].material, subs[1].material);
    for s in &subs {
        assert!(s.loc.file.ends_with("geometry/killeroo.pbrt"));
        assert_eq!(s.loc.line, 1);
        assert_eq!(s.params.get_int("levels", 0).unwrap(), 1);
    }
    let reflectance = |s: &ShapeDesc| match &s.material {
        MaterialRef::Index(i) => d.materials[*i].params.get_rgb("reflectance").unwrap(),
        _ => None,
    };
    assert_eq!(reflectance(subs[0]), Some([0.4, 0.2, 0.2]));
    assert_eq!(reflectance(subs[1]), Some([0.4, 0.5, 0.4]));
    // The second copy is translated by -200 along the (scaled, rotated) x.
    let p0 = subs[0].render_from_object.transform_point([0.0; 3]);
    let p1 = subs[1].render_from_object.transform_point([0.0; 3]);
    let dist = ((p0[0] - p1[0]).powi(2) + (p0[1] - p1[1]).powi(2)).sqrt();
    assert!((dist - 100.0).abs() < 1e-9, "{dist}");
    assert_eq!(d.shapes.len(), 5);
    assert_eq!(d.shapes[0].name, "sphere");
    assert!(d.shapes[0].area_light.is_some());
}
