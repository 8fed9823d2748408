//! Hostile inputs: files that never end or block, byte-order marks,
//! exponential include trees, absurd numbers. Each must give one located
//! error (or parse), never hang, panic or allocate without bound.

use std::path::{Path, PathBuf};
use std::time::Instant;

use candela_scene::*;

/// A fresh directory under the system temp dir.
fn temp_dir(name: &str) -> PathBuf {
    let d = std::env::temp_dir().join(format!("candela-hostile-{}-{name}", std::process::id()));
    let _ = std::fs::remove_dir_all(&d);
    std::fs::create_dir_all(&d).unwrap();
    d
}

#[test]
fn including_devices_and_directories_is_a_located_error() {
    let d = temp_dir("dev");
    let main = d.join("main.pbrt");
    for (target, why) in [
        ("/dev/zero", "it is not a regular file"),
        ("/dev/null", "it is not a regular file"),
        (".", "it is a directory"),
    ] {
        for directive in ["Include", "Import"] {
            std::fs::write(&main, format!("WorldBegin\n  {directive} \"{target}\"\n")).unwrap();
            let t = Instant::now();
            let e = parse_file(&main).unwrap_err();
            assert!(t.elapsed().as_secs() < 5, "{target} took {:?}", t.elapsed());
            assert!(matches!(e, SceneError::Io { .. }), "{e}");
            let msg = e.to_string();
            let want = format!("{}:2:3: cannot read '", main.display());
            assert!(msg.starts_with(&want), "{msg}");
            assert!(msg.contains(why), "{msg}");
        }
    }
    // The main file itself is checked the same way.
    let e = parse_file(Path::new("/dev/zero")).unwrap_err().to_string();
    assert_eq!(
        e,
        "cannot read '/dev/zero': it is not a regular file (a device, FIFO or socket)"
    );
}

#[test]
fn including_a_fifo_does_not_block() {
    let d = temp_dir("fifo");
    let fifo = d.join("pipe.pbrt");
    let made = std::process::Command::new("mkfifo").arg(&fifo).status();
    if !made.is_ok_and(|s| s.success()) {
        eprintln!("mkfifo unavailable: skipping");
        return;
    }
    let main = d.join("main.pbrt");
    std::fs::write(&main, "Include \"pipe.pbrt\"\n").unwrap();
    // Opening a FIFO with no writer would block forever; it must be refused
    // before it is opened.
    let e = parse_file(&main).unwrap_err().to_string();
    assert!(
        e.starts_with(&format!("{}:1:1: cannot read", main.display())),
        "{e}"
    );
    assert!(e.contains("not a regular file"), "{e}");
}

#[test]
fn byte_order_marks_are_accepted_in_every_file() {
    let d = temp_dir("bom");
    std::fs::write(
        d.join("part.pbrt"),
        "\u{feff}Shape \"sphere\"\nShape \"disk\"\n",
    )
    .unwrap();
    let main = d.join("main.pbrt");
    std::fs::write(
        &main,
        "\u{feff}LookAt 0 0 5  0 0 0  0 1 0\nCamera \"perspective\"\nWorldBegin\nInclude \"part.pbrt\"\n",
    )
    .unwrap();
    let s = parse_file(&main).unwrap();
    assert_eq!(s.shapes.len(), 2);
    // Columns on the first line count from after the mark.
    assert_eq!((s.shapes[0].loc.line, s.shapes[0].loc.col), (1, 1));
    // A mark anywhere else is still an error, located.
    let e = parse_str("WorldBegin\n\u{feff}Shape \"sphere\"", Path::new("t.pbrt"))
        .unwrap_err()
        .to_string();
    assert!(e.starts_with("t.pbrt:2:1: unknown directive"), "{e}");
}

#[test]
fn exponential_include_trees_stop_at_the_directive_limit() {
    // Level k includes level k+1 ten times: six levels are 10^6 leaves
    // (ten times the limit) and each extra level multiplies by ten. The
    // parse must stop with an error instead of reading every leaf.
    const { assert!(MAX_INCLUDED_FILES < 1_000_000) };
    let d = temp_dir("laughs");
    std::fs::write(d.join("l6.pbrt"), "ReverseOrientation\n").unwrap();
    for k in (0..6).rev() {
        let line = format!("Include \"l{}.pbrt\"\n", k + 1);
        std::fs::write(d.join(format!("l{k}.pbrt")), line.repeat(10)).unwrap();
    }
    let t = Instant::now();
    let e = parse_file(&d.join("l0.pbrt")).unwrap_err().to_string();
    let secs = t.elapsed().as_secs_f64();
    assert!(
        e.contains(&format!(
            "more than {MAX_INCLUDED_FILES} Include/Import directives"
        )),
        "{e}"
    );
    let located =
        (0..6).any(|k| e.starts_with(&format!("{}:", d.join(format!("l{k}.pbrt")).display())));
    assert!(located, "located in the file doing the including: {e}");
    eprintln!("{MAX_INCLUDED_FILES} includes refused after {secs:.2} s");
}

#[test]
fn invalid_utf8_and_giant_numbers_are_clean() {
    let p = Path::new("t.pbrt");
    let e = parse_bytes(b"WorldBegin\n\xff\xfeShape \"sphere\"", p)
        .unwrap_err()
        .to_string();
    assert!(e.starts_with("t.pbrt:2:1: unknown directive"), "{e}");
    // Non-UTF-8 bytes inside strings are replaced, not a panic.
    let s = parse_bytes(b"WorldBegin\nShape \"sph\xffere\"", p).unwrap();
    assert_eq!(s.shapes[0].name, "sph\u{fffd}ere");
    // Numbers beyond f32/f64/i32 range are located errors in transforms
    // (they would make every bound below them infinite).
    let e = parse_str("WorldBegin\nTranslate 1e39 1e400 -1e400\n", p)
        .unwrap_err()
        .to_string();
    assert!(e.starts_with("t.pbrt:2:") && e.contains("finite"), "{e}");
    let e = parse_str(
        "WorldBegin\nShape \"trianglemesh\" \"integer indices\" [2147483648]",
        p,
    )
    .unwrap_err()
    .to_string();
    assert!(e.starts_with("t.pbrt:2:"), "{e}");
    let long = format!("WorldBegin\nTranslate {} 0 0\n", "9".repeat(100_000));
    let e = parse_str(&long, p).unwrap_err().to_string();
    assert!(e.starts_with("t.pbrt:2:") && e.contains("finite"), "{e}");
}

#[test]
fn deep_block_nesting_is_a_located_error() {
    let text = format!(
        "WorldBegin\n{}",
        "AttributeBegin\n".repeat(MAX_BLOCK_DEPTH + 1)
    );
    let e = parse_str(&text, Path::new("t.pbrt"))
        .unwrap_err()
        .to_string();
    let line = MAX_BLOCK_DEPTH + 2;
    assert_eq!(
        e,
        format!("t.pbrt:{line}:1: blocks nested deeper than {MAX_BLOCK_DEPTH}")
    );
}

#[test]
fn copying_large_attributes_into_many_entities_stops_at_the_budget() {
    // One Attribute of 2^20 values copied into 100 shapes would be 10^8
    // values; the budget stops it at about 64 shapes (~260 MB), and the
    // error names the shape that crossed it.
    let values = " 1".repeat(1 << 20);
    let text = format!(
        "WorldBegin\nAttribute \"shape\" \"float junk\" [{values}]\n{}",
        "Shape \"sphere\"\n".repeat(100)
    );
    let e = parse_str(&text, Path::new("t.pbrt"))
        .unwrap_err()
        .to_string();
    assert!(e.contains("copies more than"), "{e}");
    let line: usize = e.split(':').nth(1).unwrap().parse().unwrap();
    let shapes = (line - 2) as u64;
    let per_shape = (1u64 << 20) + 1;
    assert_eq!(shapes, MAX_COPIED_VALUES / per_shape + 1, "{e}");
    // Area-light parameters copied into shapes count too, and so does the
    // state saved by AttributeBegin.
    let text = format!(
        "WorldBegin\nAreaLightSource \"diffuse\" \"float junk\" [{values}]\n{}",
        "AttributeBegin\n".repeat(100)
    );
    let e = parse_str(&text, Path::new("t.pbrt"))
        .unwrap_err()
        .to_string();
    assert!(e.contains("copies more than"), "{e}");
    // Ordinary use stays far below: a default copied into 10^5 shapes.
    let text = format!(
        "WorldBegin\nAttribute \"shape\" \"float alpha\" [1]\n{}",
        "Shape \"sphere\"\n".repeat(100_000)
    );
    assert_eq!(
        parse_str(&text, Path::new("t.pbrt")).unwrap().shapes.len(),
        100_000
    );
}
