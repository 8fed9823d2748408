//! Errors carry the right file:line:col and say what is wrong.

use std::path::{Path, PathBuf};

use candela_scene::*;

fn err(text: &str) -> String {
    parse_str(text, Path::new("t.pbrt"))
        .unwrap_err()
        .to_string()
}

/// A fresh directory under the system temp dir for file-based tests.
fn temp_dir(name: &str) -> PathBuf {
    let d = std::env::temp_dir().join(format!("candela-scene-{}-{name}", std::process::id()));
    let _ = std::fs::remove_dir_all(&d);
    std::fs::create_dir_all(&d).unwrap();
    d
}

#[test]
fn unknown_directive() {
    assert_eq!(
        err("WorldBegin\n  Foo 1"),
        "t.pbrt:2:3: unknown directive 'Foo'"
    );
}

#[test]
fn wrong_value_kind_in_list() {
    assert_eq!(
        err("Camera \"perspective\"\n    \"float fov\" [ \"x\" ]"),
        "t.pbrt:2:19: expected a number for 'fov', found string \"x\" (missing ']'?)"
    );
    assert_eq!(
        err("WorldBegin Shape \"trianglemesh\" \"integer indices\" [0 1.5 2]"),
        "t.pbrt:1:54: expected an integer for 'indices', found '1.5' (missing ']'?)"
    );
}

#[test]
fn getter_type_mismatch_reports_param_loc() {
    let d = parse_str(
        "Camera \"perspective\"\n  \"string fov\" \"wide\"",
        Path::new("t.pbrt"),
    )
    .unwrap();
    let e = d.camera.unwrap().params.get_float("fov", 90.0).unwrap_err();
    assert_eq!(
        e.to_string(),
        "t.pbrt:2:3: expected a float for 'fov', found string"
    );
}

#[test]
fn unterminated_string() {
    assert_eq!(
        err("WorldBegin\nShape \"sphere\n\"float radius\" 1"),
        "t.pbrt:2:7: unterminated string"
    );
}

#[test]
fn missing_close_bracket() {
    assert_eq!(
        err("WorldBegin\nShape \"trianglemesh\" \"point3 P\" [ 0 0 0\n  Shape \"sphere\""),
        "t.pbrt:3:3: expected a number for 'P', found 'Shape' (missing ']'?)"
    );
    assert_eq!(
        err("WorldBegin\nShape \"trianglemesh\" \"point3 P\" [ 0 0 0"),
        "t.pbrt:2:40: premature end of file: expected ']' to close the values of 'P'"
    );
}

#[test]
fn participating_media_are_unsupported() {
    assert_eq!(
        err("WorldBegin\n\nMakeNamedMedium \"fog\" \"string type\" \"homogeneous\""),
        "t.pbrt:3:1: participating media not supported yet"
    );
    assert_eq!(
        err("WorldBegin\n MediumInterface \"\" \"fog\""),
        "t.pbrt:2:2: participating media not supported yet"
    );
    let e = parse_str("WorldBegin\n MediumInterface \"fog\"", Path::new("t.pbrt")).unwrap_err();
    assert!(matches!(e, SceneError::Unsupported { .. }));
    assert!(parse_str(
        "WorldBegin MediumInterface \"\" \"\" Shape \"sphere\"",
        Path::new("t")
    )
    .is_ok());
    assert!(parse_str(
        "WorldBegin MediumInterface \"\" Shape \"sphere\"",
        Path::new("t")
    )
    .is_ok());
}

#[test]
fn structural_errors() {
    assert_eq!(
        err("Translate 1 2"),
        "t.pbrt:1:14: premature end of file: expected a number for Translate"
    );
    assert_eq!(
        err("WorldBegin\nAttributeEnd"),
        "t.pbrt:2:1: unmatched 'AttributeEnd'"
    );
    assert_eq!(
        err("WorldBegin\nAttributeBegin\n"),
        "t.pbrt:3:1: end of file inside the AttributeBegin block opened at t.pbrt:2:1"
    );
    assert_eq!(
        err("Shape \"sphere\""),
        "t.pbrt:1:1: 'Shape' is only allowed after WorldBegin"
    );
    assert_eq!(
        err("WorldBegin\nCamera \"perspective\""),
        "t.pbrt:2:1: 'Camera' is only allowed before WorldBegin"
    );
    assert_eq!(
        err("WorldBegin\nNamedMaterial \"nope\"\nShape \"sphere\""),
        "t.pbrt:3:1: named material 'nope' is not defined"
    );
    assert_eq!(
        err("WorldBegin ObjectInstance \"x\""),
        "t.pbrt:1:12: object 'x' is not defined"
    );
    assert_eq!(
        err("Film \"rgb\" \"rgb x\" [1 2]"),
        "t.pbrt:1:12: 'rgb x' needs 3 values, found 2 values"
    );
    assert_eq!(
        err("Film \"rgb\" \"floot x\" 1"),
        "t.pbrt:1:12: unknown parameter type 'floot'"
    );
    assert_eq!(err("[ 1 ]"), "t.pbrt:1:1: expected a directive, found '['");
}

#[test]
fn missing_main_file_carries_path() {
    let e = parse_file(Path::new("/nonexistent/scene.pbrt")).unwrap_err();
    assert!(matches!(e, SceneError::Io { .. }));
    // The path is named once: the location would only repeat it.
    let msg = e.to_string();
    assert!(
        msg.starts_with("cannot read '/nonexistent/scene.pbrt': "),
        "{msg}"
    );
    assert_eq!(msg.matches("/nonexistent/scene.pbrt").count(), 1, "{msg}");
    assert_eq!(msg.matches("No such file").count(), 1, "{msg}");
}

#[test]
fn missing_include_reports_the_include_directive() {
    let e = parse_str(
        "WorldBegin\n   Include \"nope.pbrt\"",
        Path::new("/virtual/main.pbrt"),
    )
    .unwrap_err();
    assert!(matches!(e, SceneError::Io { .. }));
    assert_eq!(e.loc().line, 2);
    assert_eq!(e.loc().col, 4);
    assert!(
        e.to_string()
            .starts_with("/virtual/main.pbrt:2:4: cannot read '/virtual/nope.pbrt'"),
        "{e}"
    );
}

#[test]
fn errors_in_included_files_carry_their_location() {
    let d = temp_dir("incl");
    std::fs::create_dir_all(d.join("sub")).unwrap();
    // Paths in included files are relative to the main file's directory.
    std::fs::write(d.join("sub/a.pbrt"), "Include \"sub/b.pbrt\"\n").unwrap();
    std::fs::write(d.join("sub/b.pbrt"), "Shape \"sphere\"\n\n  Bogus\n").unwrap();
    std::fs::write(d.join("main.pbrt"), "WorldBegin\nInclude \"sub/a.pbrt\"\n").unwrap();
    let e = parse_file(&d.join("main.pbrt")).unwrap_err();
    assert_eq!(
        e.to_string(),
        format!(
            "{}:3:3: unknown directive 'Bogus'",
            d.join("sub/b.pbrt").display()
        )
    );
}

#[test]
fn include_cycles_are_errors_not_stack_overflows() {
    let d = temp_dir("cycle");
    std::fs::write(d.join("a.pbrt"), "Include \"b.pbrt\"\n").unwrap();
    std::fs::write(d.join("b.pbrt"), "Shape \"sphere\"\nInclude \"a.pbrt\"\n").unwrap();
    std::fs::write(d.join("main.pbrt"), "WorldBegin Include \"a.pbrt\"\n").unwrap();
    let e = parse_file(&d.join("main.pbrt")).unwrap_err().to_string();
    assert!(
        e.starts_with(&format!(
            "{}:2:1: Include cycle",
            d.join("b.pbrt").display()
        )),
        "{e}"
    );
    // Self-inclusion of the main file is caught too.
    std::fs::write(d.join("self.pbrt"), "Include \"self.pbrt\"\n").unwrap();
    assert!(parse_file(&d.join("self.pbrt")).is_err());
}

#[test]
fn gzipped_scenes_and_import_scoping() {
    use std::io::Write;
    let d = temp_dir("gz");
    let mut gz = flate2::write::GzEncoder::new(Vec::new(), flate2::Compression::fast());
    gz.write_all(b"Translate 1 0 0\nShape \"sphere\"\n")
        .unwrap();
    std::fs::write(d.join("part.pbrt.gz"), gz.finish().unwrap()).unwrap();
    std::fs::write(
        d.join("main.pbrt"),
        "WorldBegin Import \"part.pbrt.gz\" Shape \"disk\" Include \"part.pbrt.gz\" Shape \"disk\"",
    )
    .unwrap();
    let s = parse_file(&d.join("main.pbrt")).unwrap();
    let x = |i: usize| s.shapes[i].render_from_object.transform_point([0.0; 3])[0];
    // Import scopes the graphics state; Include does not.
    assert_eq!([x(0), x(1), x(2), x(3)], [1.0, 0.0, 1.0, 1.0]);
}
