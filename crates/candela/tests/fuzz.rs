//! A short fuzz campaign against the binary built by this `cargo test`:
//! fails if a case panics, aborts or hangs with a signature that is not in
//! `crates/candela-fuzz/findings/known.txt` (reported bugs outside the
//! parser that are not fixed yet), or if any case hits the 2 GiB cap: each
//! case runs with `--memory-limit` at half the cap, so candela's budget
//! refuses what it estimates too large with a clean error, and an
//! allocation failing under the cap is a structure the estimate missed.
//!
//! About 3,000 cases: roughly 80-120 s on two cores (40 cases/s measured
//! with `candela-fuzz --cases 3000`). The seed is fixed, so the cases are
//! the same on every run; a time cap keeps a slow machine within bounds.

use std::path::Path;
use std::time::Duration;

use candela_fuzz::campaign::{self, Config};
use candela_fuzz::known;
use candela_fuzz::run::{Outcome, Runner};

#[test]
fn short_fuzz_run_finds_no_new_crash() {
    let out = Path::new(env!("CARGO_TARGET_TMPDIR")).join("fuzz-short");
    let _ = std::fs::remove_dir_all(&out);
    let cfg = Config {
        scenes: Path::new(env!("CARGO_MANIFEST_DIR")).join("../../scenes"),
        out: out.clone(),
        seed: 20_261_201,
        cases: Some(3000),
        duration: Some(Duration::from_secs(120)),
        jobs: 2,
        runner: Runner {
            candela: env!("CARGO_BIN_EXE_candela").into(),
            timeout: Duration::from_secs(20),
            mem_mib: 2048,
        },
    };
    let s = campaign::run(&cfg).unwrap();
    eprintln!("{}", s.report());
    // The harness works: cases ran, and both renders and refusals occurred.
    assert!(s.cases >= 500, "only {} cases", s.cases);
    assert!(s.count(Outcome::Ok) > s.cases / 10, "{}", s.report());
    assert!(
        s.count(Outcome::CleanError) > s.cases / 10,
        "{}",
        s.report()
    );
    let list = known::parse(known::KNOWN).unwrap();
    let new: Vec<String> = s
        .findings
        .iter()
        .filter(|((o, sig), _)| o.is_crash() && !known::is_known(&list, *o, sig))
        .map(|((o, sig), f)| {
            format!(
                "{} x{}: {sig} (e.g. {})",
                o.name(),
                f.count,
                f.example.display()
            )
        })
        .collect();
    assert!(new.is_empty(), "new crashes:\n{}", new.join("\n"));
    let over = s.count(Outcome::MemoryLimit);
    assert_eq!(over, 0, "{over} cases over the cap:\n{}", s.report());
}
