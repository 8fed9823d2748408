//! The shape of the code, checked: no source file over 600 lines (generated
//! data tables under a `data/` directory excepted), no function over 80
//! lines, and no circle among candela-core's top-level modules (a module's
//! dependencies are the `crate::x` paths in the non-comment lines of its
//! non-test files: unit tests may build scenes from text through `build`).

use std::collections::{BTreeMap, BTreeSet};
use std::path::{Path, PathBuf};

fn rust_files(dir: &Path, out: &mut Vec<PathBuf>) {
    let Ok(entries) = std::fs::read_dir(dir) else {
        return;
    };
    for e in entries.flatten() {
        let p = e.path();
        let name = p.file_name().and_then(|n| n.to_str()).unwrap_or("");
        if p.is_dir() && name != "target" && !name.starts_with('.') {
            rust_files(&p, out);
        } else if name.ends_with(".rs") {
            out.push(p);
        }
    }
}

fn workspace() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("../..")
}

fn all_sources() -> Vec<PathBuf> {
    let mut files = Vec::new();
    for top in ["crates", "python"] {
        rust_files(&workspace().join(top), &mut files);
    }
    assert!(files.len() > 100, "found only {} sources", files.len());
    files
}

/// (name, first line, length) of every function body in `text`.
fn functions(text: &str) -> Vec<(String, usize, usize)> {
    let lines: Vec<&str> = text.lines().collect();
    let mut out = Vec::new();
    let mut i = 0;
    while i < lines.len() {
        let l = lines[i].trim_start();
        let is_fn = [
            "fn ",
            "pub fn ",
            "pub(crate) fn ",
            "pub(super) fn ",
            "const fn ",
            "pub const fn ",
        ]
        .iter()
        .any(|p| l.starts_with(p));
        if !is_fn || l.trim_end().ends_with(';') {
            i += 1;
            continue;
        }
        let name = l
            .split("fn ")
            .nth(1)
            .unwrap_or("")
            .split(['(', '<'])
            .next()
            .unwrap_or("");
        let (mut depth, mut started, mut j) = (0i64, false, i);
        'scan: while j < lines.len() {
            for ch in lines[j].chars() {
                match ch {
                    '{' => {
                        depth += 1;
                        started = true;
                    }
                    '}' => depth -= 1,
                    _ => {}
                }
                if started && depth == 0 {
                    break 'scan;
                }
            }
            j += 1;
        }
        out.push((name.to_string(), i + 1, j - i + 1));
        i = j + 1;
    }
    out
}

#[test]
fn no_file_over_600_lines_and_no_function_over_80() {
    let mut bad = Vec::new();
    for f in all_sources() {
        let text = std::fs::read_to_string(&f).unwrap_or_default();
        let generated = f.components().any(|c| c.as_os_str() == "data");
        let n = text.lines().count();
        if n > 600 && !generated {
            bad.push(format!("{}: {n} lines", f.display()));
        }
        for (name, line, len) in functions(&text) {
            if len > 80 {
                bad.push(format!("{}:{line}: fn {name} is {len} lines", f.display()));
            }
        }
    }
    assert!(bad.is_empty(), "{}", bad.join("\n"));
}

#[test]
fn the_function_scanner_sees_long_functions() {
    let body: String = (0..81).map(|i| format!("    let x{i} = {i};\n")).collect();
    let text = format!("fn long() {{\n{body}}}\nfn short() {{ 1 }}\n");
    let f = functions(&text);
    assert_eq!(f[0], ("long".to_string(), 1, 83));
    assert_eq!(f[1].0, "short");
}

/// Top-level module → the top-level modules it uses.
fn core_module_graph() -> BTreeMap<String, BTreeSet<String>> {
    let src = workspace().join("crates/candela-core/src");
    let mut files = Vec::new();
    rust_files(&src, &mut files);
    let mut g: BTreeMap<String, BTreeSet<String>> = BTreeMap::new();
    for f in files {
        let rel = f.strip_prefix(&src).unwrap_or(&f);
        let first = rel
            .components()
            .next()
            .and_then(|c| c.as_os_str().to_str())
            .unwrap_or("");
        let module = first.trim_end_matches(".rs").to_string();
        let name = f.file_name().and_then(|n| n.to_str()).unwrap_or("");
        let test_code = name == "tests.rs"
            || name.ends_with("_tests.rs")
            || rel.components().any(|c| c.as_os_str() == "tests");
        if module == "lib" || test_code {
            continue;
        }
        let text = std::fs::read_to_string(&f).unwrap_or_default();
        let deps = g.entry(module.clone()).or_default();
        for line in text.lines() {
            let code = line.split("//").next().unwrap_or("");
            for part in code.split("crate::").skip(1) {
                let dep: String = part
                    .chars()
                    .take_while(|c| c.is_alphanumeric() || *c == '_')
                    .collect();
                if !dep.is_empty() && dep != module {
                    deps.insert(dep);
                }
            }
        }
    }
    g
}

/// A cycle through `start` in `g`, if any (depth-first search).
fn cycle(g: &BTreeMap<String, BTreeSet<String>>) -> Option<Vec<String>> {
    fn visit(
        g: &BTreeMap<String, BTreeSet<String>>,
        n: &str,
        path: &mut Vec<String>,
        done: &mut BTreeSet<String>,
    ) -> Option<Vec<String>> {
        if let Some(i) = path.iter().position(|p| p == n) {
            let mut c = path[i..].to_vec();
            c.push(n.to_string());
            return Some(c);
        }
        if done.contains(n) {
            return None;
        }
        path.push(n.to_string());
        for d in g.get(n).into_iter().flatten() {
            if let Some(c) = visit(g, d, path, done) {
                return Some(c);
            }
        }
        path.pop();
        done.insert(n.to_string());
        None
    }
    let mut done = BTreeSet::new();
    g.keys()
        .find_map(|k| visit(g, k, &mut Vec::new(), &mut done))
}

#[test]
fn candela_core_modules_form_no_circle() {
    let g = core_module_graph();
    assert!(g.contains_key("integrator") && g.contains_key("scene") && g.contains_key("build"));
    assert!(
        g["build"].contains("integrator"),
        "the scanner sees build's dependencies"
    );
    assert_eq!(cycle(&g), None, "module circle");
    // The scanner finds circles: scene → integrator would close one.
    let mut bad = g.clone();
    bad.get_mut("scene").map(|d| d.insert("build".to_string()));
    assert!(cycle(&bad).is_some());
}

/// The files whose non-comment lines hold an unsafe block, function or
/// impl, or allow unsafe code (the patterns are spelt in two parts so this
/// file does not match itself).
fn files_with_unsafe(files: &[PathBuf]) -> Vec<String> {
    let word = ["un", "safe"].concat();
    let patterns = [" {", " fn", " impl", "_code)"].map(|p| format!("{word}{p}"));
    files
        .iter()
        .filter(|f| {
            let text = std::fs::read_to_string(f).unwrap_or_default();
            text.lines().any(|l| {
                !l.trim_start().starts_with("//") && patterns.iter().any(|p| l.contains(p.as_str()))
            })
        })
        .map(|f| f.to_string_lossy().replace('\\', "/"))
        .collect()
}

#[test]
fn unsafe_code_lives_in_the_bvh_intrinsics_module_alone() {
    // The workspace denies unsafe code; accel/simd.rs allows it for CPU
    // intrinsics behind a safe API, and no other file may.
    let found = files_with_unsafe(&all_sources());
    assert!(
        found
            .iter()
            .all(|f| f.ends_with("candela-core/src/accel/simd.rs")),
        "unsafe outside accel/simd.rs: {found:?}"
    );
    assert_eq!(
        found.len(),
        1,
        "the scanner must see accel/simd.rs: {found:?}"
    );
}
