//! Text meshes parse at a useful speed (no per-number allocation).

use std::fmt::Write;
use std::path::Path;
use std::time::Instant;

use candela_scene::*;

#[test]
fn large_text_trianglemesh() {
    let n = 300usize; // n*n vertices, 2(n-1)^2 ≈ 180k triangles
    let mut s = String::from("WorldBegin\nShape \"trianglemesh\"\n\"point3 P\" [\n");
    for j in 0..n {
        for i in 0..n {
            let _ = writeln!(s, "{}.25 {}.5 -0.125", i, j);
        }
    }
    s.push_str("]\n\"integer indices\" [\n");
    for j in 0..n - 1 {
        for i in 0..n - 1 {
            let v = j * n + i;
            let _ = writeln!(
                s,
                "{} {} {} {} {} {}",
                v,
                v + 1,
                v + n + 1,
                v,
                v + n + 1,
                v + n
            );
        }
    }
    s.push_str("]\n");
    let t = Instant::now();
    let d = parse_str(&s, Path::new("big.pbrt")).unwrap();
    let secs = t.elapsed().as_secs_f64();
    let p = &d.shapes[0].params;
    assert_eq!(p.get_point3s("P").unwrap().unwrap().len(), n * n);
    assert_eq!(
        p.get_ints("indices").unwrap().unwrap().len(),
        6 * (n - 1) * (n - 1)
    );
    let mb = s.len() as f64 / 1e6;
    eprintln!(
        "{mb:.1} MB of mesh text in {secs:.3} s ({:.0} MB/s)",
        mb / secs
    );
    assert!(secs < 2.0, "{secs}");
}
