//! PLY reader: the shared binary meshes and hand-written files.

use std::path::{Path, PathBuf};
use std::time::Instant;

use candela_scene::ply::parse_ply;
use candela_scene::*;

fn temp_file(name: &str, bytes: &[u8]) -> PathBuf {
    let d = std::env::temp_dir().join(format!("candela-ply-{}", std::process::id()));
    std::fs::create_dir_all(&d).unwrap();
    let p = d.join(name);
    std::fs::write(&p, bytes).unwrap();
    p
}

/// Header counts of a PLY file: (vertices, faces).
fn header_counts(path: &Path) -> (usize, usize) {
    let bytes = std::fs::read(path).unwrap();
    let end = bytes.windows(10).position(|w| w == b"end_header").unwrap();
    let header = String::from_utf8_lossy(&bytes[..end]);
    let count = |el: &str| {
        header
            .lines()
            .find_map(|l| l.strip_prefix(&format!("element {el} ")))
            .unwrap()
            .trim()
            .parse()
            .unwrap()
    };
    (count("vertex"), count("face"))
}

#[test]
fn caustic_glass_meshes() {
    let dir = Path::new(env!("CARGO_MANIFEST_DIR")).join("../../scenes/caustic-glass/geometry");
    for name in ["mesh_00001.ply", "mesh_00002.ply"] {
        let path = dir.join(name);
        let (nv, nf) = header_counts(&path);
        let m = read_ply(&path).unwrap();
        assert_eq!(m.positions.len(), nv);
        assert_eq!(m.normals.as_ref().unwrap().len(), nv);
        assert!(m.uvs.is_none() && m.face_indices.is_none());
        // All faces are triangles in these files.
        assert_eq!(m.indices.len(), 3 * nf);
        assert!(m.positions.iter().flatten().all(|c| c.is_finite()));
        let n = m.normals.unwrap()[0];
        let len = (n[0] * n[0] + n[1] * n[1] + n[2] * n[2]).sqrt();
        assert!((len - 1.0).abs() < 1e-3, "{len}");
    }
}

const QUAD_ASCII: &str = "ply
format ascii 1.0
comment a unit quad and a triangle, with extra properties to skip
element vertex 5
property float x
property float y
property float z
property uchar red
property float s
property float t
element face 2
property list uchar int vertex_indices
property int face_indices
property list ushort double junk
element edge 1
property int vertex1
property int vertex2
end_header
0 0 0 255 0 0
1 0 0 255 1 0
1 1 0 255 1 1
0 1 0 255 0 1
2 2 2 0 0.5 0.5
4 0 1 2 3 7 2 1.5 2.5
3 1 4 2 9 0
0 1
";

#[test]
fn ascii_quads_uvs_face_indices_and_skipped_properties() {
    let p = temp_file("quad.ply", QUAD_ASCII.as_bytes());
    let m = read_ply(&p).unwrap();
    assert_eq!(m.positions.len(), 5);
    assert_eq!(m.positions[4], [2.0, 2.0, 2.0]);
    assert_eq!(m.uvs.as_ref().unwrap()[2], [1.0, 1.0]);
    assert!(m.normals.is_none());
    assert_eq!(m.indices, vec![0, 1, 2, 0, 2, 3, 1, 4, 2]);
    assert_eq!(m.face_indices, Some(vec![7, 7, 9]));
}

/// A binary PLY with a quad and a triangle, little or big endian.
fn binary_ply(big: bool, bad_index: bool) -> Vec<u8> {
    let fmt = if big {
        "binary_big_endian"
    } else {
        "binary_little_endian"
    };
    let mut out = format!(
        "ply\nformat {fmt} 1.0\nelement vertex 4\nproperty float x\nproperty float y\n\
         property float z\nproperty double nx\nproperty double ny\nproperty double nz\n\
         property short extra\nelement face 2\nproperty list int uint vertex_index\nend_header\n"
    )
    .into_bytes();
    let f32b = |v: f32| {
        if big {
            v.to_be_bytes()
        } else {
            v.to_le_bytes()
        }
    };
    let f64b = |v: f64| {
        if big {
            v.to_be_bytes()
        } else {
            v.to_le_bytes()
        }
    };
    let i32b = |v: i32| {
        if big {
            v.to_be_bytes()
        } else {
            v.to_le_bytes()
        }
    };
    for i in 0..4 {
        for c in [i as f32, 2.0 * i as f32, -1.0] {
            out.extend(f32b(c));
        }
        for c in [0.0, 0.0, 1.0] {
            out.extend(f64b(c));
        }
        out.extend(if big {
            7i16.to_be_bytes()
        } else {
            7i16.to_le_bytes()
        });
    }
    let last = if bad_index { 4 } else { 1 };
    for face in [&[0, 1, 2, 3][..], &[3, 2, last][..]] {
        out.extend(i32b(face.len() as i32));
        for &v in face {
            out.extend(i32b(v));
        }
    }
    out
}

#[test]
fn binary_both_endiannesses() {
    for big in [false, true] {
        let m = parse_ply(&binary_ply(big, false), Path::new("b.ply")).unwrap();
        assert_eq!(m.positions[3], [3.0, 6.0, -1.0], "big={big}");
        assert_eq!(m.normals.as_ref().unwrap()[1], [0.0, 0.0, 1.0]);
        assert_eq!(m.indices, vec![0, 1, 2, 0, 2, 3, 3, 2, 1]);
    }
}

#[test]
fn gzipped_ply() {
    use std::io::Write;
    let mut gz = flate2::write::GzEncoder::new(Vec::new(), flate2::Compression::fast());
    gz.write_all(&binary_ply(false, false)).unwrap();
    let p = temp_file("mesh.ply.gz", &gz.finish().unwrap());
    assert_eq!(read_ply(&p).unwrap().indices.len(), 9);
}

#[test]
fn invalid_files_are_errors() {
    let bad = binary_ply(false, true);
    let e = parse_ply(&bad, Path::new("b.ply")).unwrap_err().to_string();
    let at: usize = e
        .strip_prefix(
            "b.ply: vertex index 4 out of range (the mesh has 4 vertices) (binary data at byte ",
        )
        .and_then(|r| r.strip_suffix(')'))
        .and_then(|n| n.parse().ok())
        .unwrap_or_else(|| panic!("{e}"));
    // The offset names the bad index itself: the last 4 bytes of the file.
    assert_eq!(at, bad.len() - 4);
    let mut truncated = binary_ply(true, false);
    truncated.truncate(truncated.len() - 3);
    assert!(parse_ply(&truncated, Path::new("b.ply")).is_err());
    let e = parse_ply(
        b"ply\nformat ascii 1.0\nelement vertex x\n",
        Path::new("h.ply"),
    )
    .unwrap_err();
    assert_eq!(e.to_string(), "h.ply:3:1: bad element count 'x'");
    assert!(parse_ply(b"PLY\n", Path::new("h.ply")).is_err());
    assert!(read_ply(Path::new("/nonexistent.ply")).is_err());
    // Every truncation of a valid file is handled without panicking.
    let full = QUAD_ASCII.as_bytes();
    for n in 0..full.len() {
        let _ = parse_ply(&full[..n], Path::new("t.ply"));
    }
}

#[test]
fn million_triangles_binary_is_fast() {
    let (nx, ny) = (709usize, 709usize); // ~1M triangles
    let mut out = format!(
        "ply\nformat binary_little_endian 1.0\nelement vertex {}\nproperty float x\n\
         property float y\nproperty float z\nelement face {}\n\
         property list uchar int vertex_indices\nend_header\n",
        nx * ny,
        (nx - 1) * (ny - 1) * 2
    )
    .into_bytes();
    for j in 0..ny {
        for i in 0..nx {
            for c in [i as f32, j as f32, 0.0] {
                out.extend(c.to_le_bytes());
            }
        }
    }
    for j in 0..ny - 1 {
        for i in 0..nx - 1 {
            let v = (j * nx + i) as i32;
            for tri in [
                [v, v + 1, v + 1 + nx as i32],
                [v, v + 1 + nx as i32, v + nx as i32],
            ] {
                out.push(3);
                for x in tri {
                    out.extend(x.to_le_bytes());
                }
            }
        }
    }
    let t = Instant::now();
    let m = parse_ply(&out, Path::new("big.ply")).unwrap();
    let secs = t.elapsed().as_secs_f64();
    assert!(m.indices.len() / 3 >= 1_000_000);
    eprintln!("1M-triangle binary PLY decoded in {secs:.3} s");
    assert!(secs < 1.0, "{secs}");
}

/// A little-endian triangle mesh: `declared` vertices in the header, `held`
/// in the body, one face with the indices `face`.
fn small_binary(declared: usize, held: usize, face: &[u32]) -> Vec<u8> {
    let mut out = format!(
        "ply\nformat binary_little_endian 1.0\nelement vertex {declared}\nproperty float x\n\
         property float y\nproperty float z\nelement face 1\n\
         property list uchar uint vertex_indices\nend_header\n"
    )
    .into_bytes();
    for i in 0..held {
        for c in [i as f32, 1.0, 0.0] {
            out.extend(c.to_le_bytes());
        }
    }
    out.push(face.len() as u8);
    for &v in face {
        out.extend(v.to_le_bytes());
    }
    out
}

#[test]
fn header_counts_that_disagree_with_the_body_are_errors() {
    let p = Path::new("m.ply");
    assert_eq!(
        parse_ply(&small_binary(3, 3, &[0, 1, 2]), p)
            .unwrap()
            .indices
            .len(),
        3
    );
    // One vertex more than declared: the face then reads vertex data and
    // bytes are left over. Before, this could come out as 0 triangles.
    let e = parse_ply(&small_binary(3, 4, &[0, 1, 2]), p)
        .unwrap_err()
        .to_string();
    assert!(e.starts_with("m.ply: "), "{e}");
    // Whatever the misread, it is an error naming a byte offset.
    assert!(e.contains("(binary data at byte "), "{e}");
    let mut trailing = small_binary(3, 3, &[0, 1, 2]);
    trailing.extend([0u8; 5]);
    let e = parse_ply(&trailing, p).unwrap_err().to_string();
    assert!(e.contains("5 bytes of data after the last element"), "{e}");
    // Fewer vertices than declared: the face is read as the last vertex,
    // leaving one byte as an empty face (or nothing at all).
    let e = parse_ply(&small_binary(4, 3, &[0, 1, 2]), p)
        .unwrap_err()
        .to_string();
    assert!(e.contains("face 0 has 0 vertex indices"), "{e}");
    let e = parse_ply(&small_binary(5, 3, &[0, 1, 2]), p)
        .unwrap_err()
        .to_string();
    assert!(e.contains("unexpected end of PLY data"), "{e}");
}

#[test]
fn faces_with_fewer_than_three_indices_are_errors() {
    let p = Path::new("m.ply");
    for face in [&[0u32, 1][..], &[2][..], &[][..]] {
        let e = parse_ply(&small_binary(3, 3, face), p)
            .unwrap_err()
            .to_string();
        let want = format!(
            "face 0 has {} vertex indices (a face needs at least 3)",
            face.len()
        );
        assert!(e.contains(&want), "{e}");
    }
    let ascii = "ply\nformat ascii 1.0\nelement vertex 3\nproperty float x\nproperty float y\n\
                 property float z\nelement face 2\nproperty list uchar int vertex_indices\n\
                 end_header\n0 0 0\n1 0 0\n0 1 0\n3 0 1 2\n  2 0 1\n";
    let e = parse_ply(ascii.as_bytes(), p).unwrap_err().to_string();
    // Located at the last index of the short face: line 14, column 7.
    assert_eq!(
        e,
        "m.ply:14:7: face 1 has 2 vertex indices (a face needs at least 3)"
    );
}

#[test]
fn ascii_errors_name_line_and_column() {
    let p = Path::new("a.ply");
    let head = "ply\nformat ascii 1.0\nelement vertex 3\nproperty float x\nproperty float y\n\
                property float z\nelement face 1\nproperty list uchar int vertex_indices\n\
                end_header\n";
    let e = parse_ply(format!("{head}0 0 0\n1 0 x\n").as_bytes(), p).unwrap_err();
    assert_eq!(e.to_string(), "a.ply:11:5: expected a number, found 'x'");
    let e = parse_ply(
        format!("{head}0 0 0\n1 0 0\n0 1 0\n3 0 1 3\n").as_bytes(),
        p,
    )
    .unwrap_err();
    assert_eq!(
        e.to_string(),
        "a.ply:13:7: vertex index 3 out of range (the mesh has 3 vertices)"
    );
    let e = parse_ply(
        format!("{head}0 0 0\n1 0 0\n0 1 0\n3 0 1 2\n7\n").as_bytes(),
        p,
    )
    .unwrap_err();
    assert!(
        e.to_string()
            .starts_with("a.ply:14:1: '7' of data after the last element"),
        "{e}"
    );
    // Trailing whitespace is fine.
    let ok = format!("{head}0 0 0\n1 0 0\n0 1 0\n3 0 1 2\n\n  \n");
    assert_eq!(parse_ply(ok.as_bytes(), p).unwrap().indices, [0, 1, 2]);
}

#[test]
fn headers_without_a_mesh_or_with_absurd_counts_are_errors() {
    let p = Path::new("h.ply");
    let e = parse_ply(b"ply\nformat ascii 1.0\nend_header\n", p).unwrap_err();
    assert_eq!(
        e.to_string(),
        "h.ply:3:1: PLY header declares no 'vertex' element"
    );
    let e = parse_ply(
        b"ply\nformat ascii 1.0\nelement vertex 0\nproperty float x\nproperty float z\nend_header\n",
        p,
    )
    .unwrap_err();
    assert_eq!(
        e.to_string(),
        "h.ply:3:1: PLY 'vertex' element has no 'y' property"
    );
    let e = parse_ply(
        b"ply\nformat ascii 1.0\nelement vertex 0\nproperty float x\nproperty float y\n\
          property float z\nelement face 0\nend_header\n",
        p,
    )
    .unwrap_err();
    assert!(
        e.to_string()
            .starts_with("h.ply:7:1: PLY header declares no 'face'"),
        "{e}"
    );
    // Counts near usize::MAX neither allocate nor loop: an element without
    // properties is skipped, and one with properties runs out of data.
    let huge = format!(
        "ply\nformat binary_little_endian 1.0\nelement junk {max}\nelement vertex {max}\n\
         property float x\nproperty float y\nproperty float z\nelement face {max}\n\
         property list uint uint vertex_indices\nend_header\n\x01\x02",
        max = usize::MAX
    );
    let e = parse_ply(huge.as_bytes(), p).unwrap_err();
    assert!(e.to_string().contains("unexpected end of PLY data"), "{e}");
    let dup = b"ply\nformat ascii 1.0\nelement vertex 0\nelement vertex 0\nend_header\n";
    let e = parse_ply(dup, p).unwrap_err();
    assert_eq!(
        e.to_string(),
        "h.ply:4:1: PLY element 'vertex' declared twice"
    );
}

#[test]
fn devices_and_directories_are_refused_as_meshes() {
    let e = read_ply(Path::new("/dev/zero")).unwrap_err();
    assert!(matches!(e, SceneError::Io { .. }), "{e}");
    assert!(e.to_string().contains("not a regular file"), "{e}");
    let e = read_ply(&std::env::temp_dir()).unwrap_err();
    assert!(e.to_string().contains("is a directory"), "{e}");
}
