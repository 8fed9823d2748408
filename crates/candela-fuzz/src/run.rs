//! Running one case in a child process and classifying what happened.
//!
//! The case's files are written into a work directory whose other entries
//! are symbolic links to the seed scene's directory, so relative names
//! (`geometry/killeroo.ply`) resolve as in the original. The child is
//! `sh -c 'ulimit -v KB; exec candela render ...'`: the shell sets the
//! address-space limit and replaces itself with candela, so the child's
//! pid is candela's and a time-out kills exactly it. stderr goes to a file
//! (a pipe could fill and stall the child).
//!
//! Classification, first match wins: killed at the time limit → hang;
//! "memory allocation of N bytes failed" → memory limit (the allocator's
//! abort under the address-space cap); "panicked at" or exit code 101 →
//! panic; death by a signal (SIGABRT after "has overflowed its stack",
//! SIGSEGV) → abort; exit 0 → ok; any other exit with a
//! `candela: error:` message → clean error; anything else → abort.
//! Hangs are rerun with `--check-only`, so their signature says whether
//! parsing and building or rendering hangs.

use std::io::Read;
use std::os::unix::process::ExitStatusExt;
use std::path::{Path, PathBuf};
use std::process::{Command, ExitStatus, Stdio};
use std::time::{Duration, Instant};

use anyhow::{Context, Result};

/// What a case did.
#[derive(Debug, Clone, Copy, PartialEq, Eq, PartialOrd, Ord, Hash)]
pub enum Outcome {
    /// Rendered.
    Ok,
    /// Refused with an error message.
    CleanError,
    /// A Rust panic.
    Panic,
    /// Killed by a signal or exited oddly (stack overflow, SIGSEGV...).
    Abort,
    /// Still running at the time limit.
    Hang,
    /// An allocation failed under the memory limit.
    MemoryLimit,
}

impl Outcome {
    /// Every outcome, in report order.
    pub const ALL: [Outcome; 6] = [
        Outcome::Ok,
        Outcome::CleanError,
        Outcome::Panic,
        Outcome::Abort,
        Outcome::Hang,
        Outcome::MemoryLimit,
    ];

    /// A short lower-case name (also the directory saved cases go to).
    pub fn name(self) -> &'static str {
        match self {
            Outcome::Ok => "ok",
            Outcome::CleanError => "clean-error",
            Outcome::Panic => "panic",
            Outcome::Abort => "abort",
            Outcome::Hang => "hang",
            Outcome::MemoryLimit => "memory-limit",
        }
    }

    /// Whether this outcome is a robustness bug (crash or hang).
    pub fn is_crash(self) -> bool {
        matches!(self, Outcome::Panic | Outcome::Abort | Outcome::Hang)
    }
}

/// Limits and the program to run.
#[derive(Debug, Clone)]
pub struct Runner {
    /// The `candela` binary.
    pub candela: PathBuf,
    /// Wall-clock limit per case.
    pub timeout: Duration,
    /// Address-space limit per case, in MiB.
    pub mem_mib: u64,
}

/// The result of one run.
#[derive(Debug, Clone)]
pub struct RunResult {
    /// The class.
    pub outcome: Outcome,
    /// A one-line summary of stderr that identifies the failure.
    pub signature: String,
    /// For clean errors: whether the message names a `file:line:col`.
    pub located: bool,
    /// The child's stderr (at most 64 KiB).
    pub stderr: String,
    /// The command line, relative to the work directory.
    pub command: Vec<String>,
}

/// The arguments `candela` is run with for `scene` in `dir`, with its own
/// memory budget at `budget_mib` (half the address-space cap: the cap must
/// also hold the binary, the scene and allocator slack). A case whose
/// estimate is over the budget is then a clean error, and an allocation
/// failing under the cap means candela's estimate missed a structure.
pub fn candela_args(scene: &str, crop: [f32; 4], budget_mib: u64) -> Vec<String> {
    let cw = format!("{},{},{},{}", crop[0], crop[1], crop[2], crop[3]);
    let budget = format!("{budget_mib}MiB");
    [
        "render",
        scene,
        "--spp",
        "1",
        "--nthreads",
        "1",
        "--quiet",
        "--cropwindow",
        &cw,
        "--outfile",
        "fuzz_out.exr",
        "--memory-limit",
        &budget,
    ]
    .iter()
    .map(|s| s.to_string())
    .collect()
}

impl Runner {
    /// Runs `candela` with `args` in `dir` under the limits. A case that
    /// hangs is run again with `--check-only` (parse and build, no render)
    /// to tell which phase hangs: its signature says which.
    pub fn run(&self, dir: &Path, args: &[String]) -> Result<RunResult> {
        let (status, stderr) = self.spawn(dir, args)?;
        // 126/127: the shell could not run the program at all.
        if let Some(c @ (126 | 127)) = status.and_then(|s| s.code()) {
            anyhow::bail!("cannot run {} (exit {c}): {stderr}", self.candela.display());
        }
        let (outcome, mut signature) = classify(status, &stderr);
        if outcome == Outcome::Hang {
            let mut check = args.to_vec();
            check.push("--check-only".into());
            let (again, _) = self.spawn(dir, &check)?;
            signature += if again.is_none() {
                " in parse/build"
            } else {
                " while rendering"
            };
        }
        let located = outcome == Outcome::CleanError && has_location(&stderr);
        Ok(RunResult {
            outcome,
            signature,
            located,
            stderr,
            command: std::iter::once("candela".to_string())
                .chain(args.iter().cloned())
                .collect(),
        })
    }

    /// Runs the child once: its exit status (`None`: killed at the time
    /// limit) and stderr.
    fn spawn(&self, dir: &Path, args: &[String]) -> Result<(Option<ExitStatus>, String)> {
        let err_path = dir.join("fuzz_stderr.txt");
        let err_file = std::fs::File::create(&err_path)
            .with_context(|| format!("creating {}", err_path.display()))?;
        let script = format!("ulimit -v {}; exec \"$0\" \"$@\"", self.mem_mib * 1024);
        let mut child = Command::new("sh")
            .arg("-c")
            .arg(script)
            .arg(&self.candela)
            .args(args)
            .current_dir(dir)
            .stdin(Stdio::null())
            .stdout(Stdio::null())
            .stderr(err_file)
            .env("RUST_BACKTRACE", "1")
            .spawn()
            .with_context(|| format!("starting {}", self.candela.display()))?;
        let start = Instant::now();
        let mut nap = Duration::from_micros(250);
        let status = loop {
            if let Some(s) = child.try_wait()? {
                break Some(s);
            }
            if start.elapsed() > self.timeout {
                // Our own child, by its handle: SIGKILL, then reap it.
                child.kill().ok();
                child.wait().ok();
                break None;
            }
            std::thread::sleep(nap);
            nap = (nap * 2).min(Duration::from_millis(2));
        };
        Ok((status, read_capped(&err_path, 64 << 10)))
    }
}

/// The first `cap` bytes of a file as text (empty if unreadable).
fn read_capped(path: &Path, cap: u64) -> String {
    let mut buf = Vec::new();
    if let Ok(f) = std::fs::File::open(path) {
        f.take(cap).read_to_end(&mut buf).ok();
    }
    String::from_utf8_lossy(&buf).into_owned()
}

/// The class and signature of an exit `status` (`None`: timed out).
pub fn classify(status: Option<ExitStatus>, stderr: &str) -> (Outcome, String) {
    let Some(status) = status else {
        return (Outcome::Hang, "time limit".into());
    };
    let line = |pat: &str| stderr.lines().find(|l| l.contains(pat)).map(str::to_string);
    if let Some(l) = line("memory allocation of") {
        // The size in orders of magnitude: 137438945280 -> "~1e11".
        let digits = l.split_whitespace().nth(3).map_or(0, str::len);
        let sig = format!(
            "memory allocation of ~1e{} bytes failed",
            digits.saturating_sub(1)
        );
        return (Outcome::MemoryLimit, sig);
    }
    if let Some(i) = stderr.find("panicked at") {
        // "thread 'main' panicked at src/x.rs:1:2:\nmessage\nstack backtrace: ..."
        let rest = &stderr[i..];
        let mut it = rest.lines();
        let at = it.next().unwrap_or("").trim_end_matches(':');
        let at = at.strip_prefix("panicked at ").unwrap_or(at);
        let msg = normalize(it.next().unwrap_or(""));
        let frame = first_project_frame(rest).unwrap_or_else(|| at.to_string());
        return (Outcome::Panic, format!("panic in {frame}: {msg}"));
    }
    if status.code() == Some(101) {
        return (Outcome::Panic, first_line(stderr));
    }
    if let Some(sig) = status.signal() {
        let what = match line("overflowed its stack") {
            Some(_) => "stack overflow".to_string(),
            None => normalize(&first_line(stderr)),
        };
        return (Outcome::Abort, format!("signal {sig}: {what}"));
    }
    match status.code() {
        Some(0) => (Outcome::Ok, String::new()),
        Some(_) if stderr.contains("candela: error:") => (
            Outcome::CleanError,
            line("candela: error:").unwrap_or_default(),
        ),
        c => (
            Outcome::Abort,
            format!("exit {c:?} without an error message"),
        ),
    }
}

/// The first backtrace frame in this workspace's `crates/` (the panic
/// location itself is often inside the standard library), as
/// `crates/<path>.rs:<line>`.
fn first_project_frame(backtrace: &str) -> Option<String> {
    backtrace.lines().find_map(|l| {
        let at = l.trim().strip_prefix("at ")?;
        let i = at.find("crates/")?;
        let loc = &at[i..];
        // Drop the column: it changes with formatting, the line less so.
        let end = loc.rfind(':').filter(|&j| loc[..j].contains(".rs:"))?;
        Some(loc[..end].to_string())
    })
}

/// `s` with digit runs, thread ids and `inf`/`NaN` collapsed, so the same
/// failure with different values has one signature.
fn normalize(s: &str) -> String {
    let mut out = String::with_capacity(s.len());
    let mut last_digit = false;
    for c in s.chars() {
        if c.is_ascii_digit() {
            if !last_digit {
                out.push('N');
            }
            last_digit = true;
        } else {
            out.push(c);
            last_digit = false;
        }
    }
    out.replace("-inf", "N")
        .replace("inf", "N")
        .replace("NaN", "N")
}

/// The first line of `s`.
fn first_line(s: &str) -> String {
    s.lines().next().unwrap_or("").to_string()
}

/// Whether an error message names a `file:line:col` (or a PLY byte offset).
pub fn has_location(stderr: &str) -> bool {
    let Some(l) = stderr.lines().find(|l| l.contains("candela: error:")) else {
        return false;
    };
    if l.contains("(binary data at byte ") {
        return true;
    }
    // Look for ":<digits>:<digits>:" anywhere.
    let b = l.as_bytes();
    (0..b.len()).any(|i| {
        let digits = |mut j: usize| {
            let s = j;
            while j < b.len() && b[j].is_ascii_digit() {
                j += 1;
            }
            (j > s).then_some(j)
        };
        b[i] == b':'
            && digits(i + 1).is_some_and(|j| b.get(j) == Some(&b':') && digits(j + 1).is_some())
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    fn exit(code: i32) -> Option<std::process::ExitStatus> {
        Some(std::process::ExitStatus::from_raw(code << 8))
    }

    #[test]
    fn classification() {
        let panic = "thread 'main' panicked at crates/x/src/a.rs:3:9:\nboom\nnote: ...";
        let (o, s) = classify(exit(101), panic);
        assert_eq!(o, Outcome::Panic);
        assert_eq!(s, "panic in crates/x/src/a.rs:3:9: boom");
        let std_panic =
            "thread 'main' (77) panicked at /rustc/abc/library/core/src/num/f32.rs:1:2:\n\
                         min = 1.5, max = -inf\nstack backtrace:\n   3: core::f32::clamp\n\
                         \x20            at /rustc/abc/library/core/src/num/f32.rs:1:2\n\
                         \x20 4: candela_core::shape::Sphere::new\n\
                         \x20            at ./crates/candela-core/src/shape/sphere.rs:40:9\n";
        let (_, s) = classify(exit(101), std_panic);
        assert_eq!(
            s,
            "panic in crates/candela-core/src/shape/sphere.rs:40: min = N.N, max = N"
        );
        let overflow =
            "\nthread 'main' has overflowed its stack\nfatal runtime error: stack overflow";
        let (o, s) = classify(Some(std::process::ExitStatus::from_raw(6)), overflow);
        assert_eq!(o, Outcome::Abort);
        assert_eq!(s, "signal 6: stack overflow");
        let oom = "memory allocation of 80000000000 bytes failed\n";
        let (o, s) = classify(Some(std::process::ExitStatus::from_raw(6)), oom);
        assert_eq!(o, Outcome::MemoryLimit);
        assert_eq!(s, "memory allocation of ~1e10 bytes failed");
        assert_eq!(classify(None, "").0, Outcome::Hang);
        assert_eq!(classify(exit(0), "").0, Outcome::Ok);
        assert_eq!(
            classify(exit(1), "candela: error: t.pbrt:1:1: x").0,
            Outcome::CleanError
        );
        assert_eq!(classify(exit(1), "").0, Outcome::Abort);
    }

    #[test]
    fn hangs_are_killed_and_their_phase_found() {
        let dir = std::env::temp_dir().join(format!("candela-fuzz-run-{}", std::process::id()));
        std::fs::create_dir_all(&dir).unwrap();
        let runner = |prog: &str| Runner {
            candela: prog.into(),
            timeout: Duration::from_millis(300),
            mem_mib: 1024,
        };
        let args = |v: &[&str]| v.iter().map(|s| s.to_string()).collect::<Vec<_>>();
        let t = Instant::now();
        // `sleep 30 --check-only` fails at once: only the render hangs.
        let r = runner("/bin/sleep").run(&dir, &args(&["30"])).unwrap();
        assert_eq!(
            (r.outcome, r.signature.as_str()),
            (Outcome::Hang, "time limit while rendering")
        );
        // `sh -c 'exec sleep 30' --check-only` sleeps too: parse/build hangs
        // (exec, so that the kill reaches the sleep itself).
        let r = runner("/bin/sh")
            .run(&dir, &args(&["-c", "exec sleep 30"]))
            .unwrap();
        assert_eq!(r.signature, "time limit in parse/build");
        assert!(t.elapsed() < Duration::from_secs(10), "{:?}", t.elapsed());
        let r = runner("/bin/sh").run(&dir, &args(&["-c", "echo 'candela: error: x' >&2; exit 1"]));
        assert_eq!(r.unwrap().outcome, Outcome::CleanError);
    }

    #[test]
    fn locations_are_recognised() {
        assert!(has_location("candela: error: /a/case.pbrt:12:3: bad"));
        assert!(has_location(
            "candela: error: m.ply: x (binary data at byte 9)"
        ));
        assert!(!has_location("candela: error: film too large"));
        assert!(!has_location("candela: error: at 12:30"));
    }
}
