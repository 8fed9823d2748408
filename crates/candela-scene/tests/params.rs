//! Parameter getters: kinds, coercions, files, usage tracking.

use std::path::{Path, PathBuf};

use candela_scene::*;

fn shape_params(params: &str) -> ParamSet {
    let text = format!("WorldBegin\nShape \"x\"\n{params}");
    let mut d = parse_str(&text, Path::new("/scenes/demo/main.pbrt")).unwrap();
    d.shapes.remove(0).params
}

#[test]
fn coercions_and_defaults() {
    let p = shape_params(
        "\"float a\" 3 \"bool b\" \"true\" \"bool c\" [false] \"integer i\" [-7] \"string s\" \"hi\"",
    );
    assert_eq!(p.get_float("a", 0.0).unwrap(), 3.0);
    assert!(p.get_bool("b", false).unwrap());
    assert!(!p.get_bool("c", true).unwrap());
    assert_eq!(p.get_int("i", 0).unwrap(), -7);
    assert_eq!(p.get_string("s", "").unwrap(), "hi");
    assert_eq!(p.get_float("missing", 2.5).unwrap(), 2.5);
    assert_eq!(
        p.get_vector3("missing", [1.0, 2.0, 3.0]).unwrap(),
        [1.0, 2.0, 3.0]
    );
    assert!(p.unused().is_empty());
}

#[test]
fn mismatches_and_counts_report_the_parameter() {
    let p = shape_params("\"integer n\" [1 2]\n\"texture tex\" \"wood\" \"point2 uv\" [0 0 1 1]");
    let e = p.get_int("n", 0).unwrap_err().to_string();
    assert_eq!(
        e,
        "/scenes/demo/main.pbrt:3:1: expected an integer (1 value) for 'n', found 2 values"
    );
    let e = p.get_float("tex", 0.0).unwrap_err().to_string();
    assert_eq!(
        e,
        "/scenes/demo/main.pbrt:4:1: expected a float for 'tex', found texture"
    );
    assert_eq!(p.get_texture("tex"), Some("wood".into()));
    assert_eq!(p.get_texture("uv"), None);
    assert_eq!(
        p.get_point2s("uv").unwrap().unwrap(),
        vec![[0.0, 0.0], [1.0, 1.0]]
    );
    assert_eq!(p.param_loc("uv").map(|l| (l.line, l.col)), Some((4, 22)));
    let e = p
        .error_at("uv", &Loc::file_only(Path::new("x")), "bad uv")
        .to_string();
    assert_eq!(e, "/scenes/demo/main.pbrt:4:22: bad uv");
}

#[test]
fn last_duplicate_wins_and_unused_lists_the_rest() {
    let p = shape_params("\"float r\" 1 \"float r\" 2 \"float extra\" 0");
    assert_eq!(p.get_float("r", 0.0).unwrap(), 2.0);
    let names: Vec<_> = p.unused().into_iter().map(|(n, _)| n).collect();
    assert_eq!(names, vec!["r", "extra"]);
}

#[test]
fn filenames_resolve_against_the_main_file_directory() {
    let p = shape_params("\"string filename\" \"geo/m.ply\" \"string abs\" \"/data/m.ply\"");
    assert_eq!(
        p.get_filename("filename").unwrap(),
        Some(PathBuf::from("/scenes/demo/geo/m.ply"))
    );
    assert_eq!(
        p.get_filename("abs").unwrap(),
        Some(PathBuf::from("/data/m.ply"))
    );
    assert_eq!(p.get_filename("none").unwrap(), None);
}

#[test]
fn spectrum_files_names_and_errors() {
    let d = std::env::temp_dir().join(format!("candela-spd-{}", std::process::id()));
    std::fs::create_dir_all(&d).unwrap();
    std::fs::write(
        d.join("s.spd"),
        "# lambda value\n400 0.5\n500 0.75 # trailing\n",
    )
    .unwrap();
    let text = "WorldBegin LightSource \"point\" \"spectrum I\" \"s.spd\" \
                \"spectrum J\" \"stdillum-D65\" \"rgb K\" [1 2 3]";
    let s = parse_str(text, &d.join("main.pbrt")).unwrap();
    let p = &s.lights[0].params;
    let v = |x| Some(ParamSpectrum::Value(x));
    assert_eq!(
        p.get_spectrum("I").unwrap(),
        v(SpectrumValue::Sampled(vec![(400.0, 0.5), (500.0, 0.75)]))
    );
    assert_eq!(
        p.get_spectrum("J").unwrap(),
        v(SpectrumValue::Named("stdillum-D65".into()))
    );
    assert_eq!(
        p.get_spectrum("K").unwrap(),
        Some(ParamSpectrum::Rgb([1.0, 2.0, 3.0]))
    );
    let e = parse_str(
        "WorldBegin LightSource \"point\" \"spectrum I\" \"nope.spd\"",
        &d.join("m.pbrt"),
    );
    assert!(matches!(e, Err(SceneError::Io { .. })));
    let e = parse_str(
        "WorldBegin LightSource \"point\" \"spectrum I\" [400 1 500]",
        Path::new("m"),
    )
    .unwrap_err()
    .to_string();
    assert!(e.starts_with("m:1:32: I: expected an even"), "{e}");
}
