//! pbrt-v3 directives other than materials are rewritten as pbrt-v4's
//! `--upgrade` does, each with one warning at the directive (materials and
//! lights are checked through the build in candela-core's `pbrt_v3` tests).

use std::path::Path;

use candela_scene::*;

fn parse(text: &str) -> SceneDescription {
    parse_str(text, Path::new("v3.pbrt")).unwrap_or_else(|e| panic!("{text}: {e}"))
}

/// The one warning of `d`, which must be at `line`.
fn one_warning(d: &SceneDescription, line: u32) -> String {
    assert_eq!(d.warnings.len(), 1, "{:#?}", d.warnings);
    assert_eq!(d.warnings[0].loc.line, line, "{}", d.warnings[0]);
    d.warnings[0].message.clone()
}

#[test]
fn options_block_entities() {
    let d = parse("Film \"image\" \"float scale\" [2] \"float maxsampleluminance\" [10]");
    let f = d.film.as_ref().unwrap();
    assert_eq!(f.name, "rgb");
    assert_eq!(f.params.get_float("iso", 0.0).unwrap(), 200.0);
    assert_eq!(f.params.get_float("maxcomponentvalue", 0.0).unwrap(), 10.0);
    let w = one_warning(&d, 1);
    assert!(w.starts_with("Film \"image\" upgraded to \"rgb\""), "{w}");

    let d = parse("Sampler \"lowdiscrepancy\" \"integer pixelsamples\" [4]");
    assert_eq!(d.sampler.as_ref().unwrap().name, "paddedsobol");
    one_warning(&d, 1);
    let d = parse("Sampler \"random\"");
    assert_eq!(d.sampler.as_ref().unwrap().name, "independent");
    one_warning(&d, 1);

    let d = parse(
        "\nIntegrator \"directlighting\" \"integer maxdepth\" [5] \"float rrthreshold\" [0.1]",
    );
    let i = d.integrator.as_ref().unwrap();
    assert_eq!(i.name, "path");
    assert_eq!(i.params.get_int("maxdepth", 0).unwrap(), 1);
    assert!(i.params.get("rrthreshold").is_none());
    let w = one_warning(&d, 2);
    assert!(w.contains("dropped \"float rrthreshold\""), "{w}");

    let d = parse(
        "PixelFilter \"gaussian\" \"float xwidth\" [2] \"float ywidth\" [2] \"float alpha\" [2]",
    );
    let p = &d.filter.as_ref().unwrap().params;
    assert_eq!(p.get_float("xradius", 0.0).unwrap(), 2.0);
    assert_eq!(p.get_float("yradius", 0.0).unwrap(), 2.0);
    assert_eq!(p.get_float("sigma", 0.0).unwrap(), 0.5); // 1/√(2·2)
    one_warning(&d, 1);
}

#[test]
fn v4_files_are_left_alone() {
    let d = parse(
        "Film \"rgb\" \"float iso\" [100]\nSampler \"zsobol\"\nIntegrator \"path\"\nPixelFilter \"gaussian\" \"float sigma\" [0.5]\n\
         WorldBegin\nTexture \"t\" \"float\" \"scale\" \"float tex\" [1] \"float scale\" [2]\n\
         LightSource \"point\" \"blackbody I\" [5000] \"float scale\" [2]\nAreaLightSource \"diffuse\"\n\
         Material \"coateddiffuse\"\nShape \"trianglemesh\" \"point3 P\" [0 0 0 1 0 0 0 1 0] \"point2 uv\" [0 0 1 0 0 1]",
    );
    assert!(d.warnings.is_empty(), "{:#?}", d.warnings);
}

#[test]
fn shapes() {
    let d = parse(
        "WorldBegin\nShape \"loopsubdiv\" \"integer nlevels\" [2] \"point3 P\" [0 0 0 1 0 0 0 1 0] \"integer indices\" [0 1 2]",
    );
    assert_eq!(d.shapes[0].params.get_int("levels", 0).unwrap(), 2);
    one_warning(&d, 2);
    let d = parse(
        "WorldBegin\nShape \"trianglemesh\" \"point3 P\" [0 0 0 1 0 0 0 1 0] \"float uv\" [0 0 1 0 0 1] \"bool discarddegenerateUVs\" true",
    );
    let uv = d.shapes[0].params.get_point2s("uv").unwrap().unwrap();
    assert_eq!(uv, vec![[0.0, 0.0], [1.0, 0.0], [0.0, 1.0]]);
    let w = one_warning(&d, 2);
    assert!(w.contains("\"float uv\" → \"point2 uv\""), "{w}");
}

#[test]
fn textures() {
    let d = parse(
        "WorldBegin\nTexture \"s\" \"float\" \"scale\" \"float tex1\" [0.5] \"float tex2\" [3]",
    );
    let p = &d.textures[0].params;
    assert_eq!(p.get_float("tex", 0.0).unwrap(), 0.5);
    assert_eq!(p.get_float("scale", 0.0).unwrap(), 3.0);
    one_warning(&d, 2);
    let d = parse(
        "WorldBegin\nTexture \"c\" \"spectrum\" \"checkerboard\"\nTexture \"s\" \"spectrum\" \"scale\" \"rgb tex1\" [2 2 2] \"texture tex2\" \"c\"",
    );
    let p = &d.textures[1].params;
    assert_eq!(p.get_texture("tex").as_deref(), Some("c"));
    assert_eq!(p.get_float("scale", 0.0).unwrap(), 2.0);
    one_warning(&d, 3);
    let e = parse_str(
        "WorldBegin\nTexture \"s\" \"spectrum\" \"scale\" \"rgb tex1\" [1 2 3] \"rgb tex2\" [1 1 1]",
        Path::new("v3.pbrt"),
    );
    assert!(e.is_ok(), "a grey rgb is found in either slot");
    let e = parse_str(
        "WorldBegin\nTexture \"s\" \"spectrum\" \"scale\" \"rgb tex1\" [1 2 3]",
        Path::new("v3.pbrt"),
    )
    .unwrap_err();
    assert!(e.to_string().starts_with("v3.pbrt:2:32: a non-grey"), "{e}");
    let d = parse(
        "WorldBegin\nTexture \"i\" \"spectrum\" \"imagemap\" \"string filename\" \"a.png\" \"bool trilinear\" true \"bool gamma\" false",
    );
    let p = &d.textures[0].params;
    assert_eq!(p.get_string("filter", "").unwrap(), "trilinear");
    assert_eq!(p.get_string("encoding", "").unwrap(), "linear");
}
