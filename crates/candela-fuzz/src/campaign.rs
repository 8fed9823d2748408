//! A fuzz campaign: cases in parallel, outcomes counted, failures saved.
//!
//! Case `i` is generated from `Rng::for_case(seed, i)` alone, so a campaign
//! with a given seed and case count runs the same inputs whatever the
//! number of workers; only time-dependent outcomes (hangs near the limit)
//! can differ between runs. Workers take case indices from a shared
//! counter, each in its own work directory per seed scene.
//!
//! Every case that is not `ok` or a located clean error is saved under
//! `out/<outcome>/<index>-<scene>/`: the case's files, `stderr.txt`,
//! `ops.txt` (the mutations) and `replay.sh`, with symbolic links to the
//! seed scene's other files so the directory replays on its own. Clean
//! errors without a `file:line:col` are saved under `out/unlocated/` (the
//! first 100), as they are worth reading but are not crashes. At most
//! [`MAX_SAVED_PER_SIGNATURE`] cases are saved per failure signature.

use std::collections::BTreeMap;
use std::path::{Path, PathBuf};
use std::sync::atomic::{AtomicU64, Ordering};
use std::sync::Mutex;
use std::time::{Duration, Instant};

use anyhow::{Context, Result};

use crate::corpus::{self, Seed};
use crate::mutate::{make_case, Case};
use crate::rng::Rng;
use crate::run::{candela_args, Outcome, RunResult, Runner};

/// Cases saved per failure signature (the rest are only counted).
pub const MAX_SAVED_PER_SIGNATURE: u64 = 20;

/// Campaign settings.
#[derive(Debug, Clone)]
pub struct Config {
    /// The `scenes/` directory of seeds.
    pub scenes: PathBuf,
    /// Where work directories and saved cases go.
    pub out: PathBuf,
    /// Campaign seed.
    pub seed: u64,
    /// Stop after this many cases...
    pub cases: Option<u64>,
    /// ...or after this long, whichever comes first.
    pub duration: Option<Duration>,
    /// Parallel workers.
    pub jobs: usize,
    /// How each case is run.
    pub runner: Runner,
}

/// Count and first saved example of one failure signature.
#[derive(Debug, Clone)]
pub struct Finding {
    /// Cases with this signature.
    pub count: u64,
    /// The directory of the first one saved.
    pub example: PathBuf,
}

/// What a campaign found.
#[derive(Debug, Clone, Default)]
pub struct Summary {
    /// Cases run.
    pub cases: u64,
    /// Wall-clock time.
    pub elapsed: Duration,
    /// Cases per outcome.
    pub counts: BTreeMap<Outcome, u64>,
    /// Clean errors whose message names no location.
    pub unlocated: u64,
    /// Distinct failures: (outcome, signature) -> finding.
    pub findings: BTreeMap<(Outcome, String), Finding>,
}

impl Summary {
    /// Cases of `outcome`.
    pub fn count(&self, outcome: Outcome) -> u64 {
        self.counts.get(&outcome).copied().unwrap_or(0)
    }

    /// Cases per second.
    pub fn rate(&self) -> f64 {
        self.cases as f64 / self.elapsed.as_secs_f64().max(1e-9)
    }

    /// A human-readable report.
    pub fn report(&self) -> String {
        let mut s = format!(
            "{} cases in {:.1} s ({:.1} cases/s)\n",
            self.cases,
            self.elapsed.as_secs_f64(),
            self.rate()
        );
        for o in Outcome::ALL {
            s += &format!("  {:<13} {}\n", o.name(), self.count(o));
        }
        s += &format!(
            "  (clean errors without file:line:col: {})\n",
            self.unlocated
        );
        for ((o, sig), f) in &self.findings {
            s += &format!(
                "{} x{}: {sig}\n    e.g. {}\n",
                o.name(),
                f.count,
                f.example.display()
            );
        }
        s
    }
}

/// Runs a campaign.
pub fn run(cfg: &Config) -> Result<Summary> {
    anyhow::ensure!(
        cfg.cases.is_some() || cfg.duration.is_some(),
        "give a case count or a duration"
    );
    let seeds = corpus::load(&cfg.scenes)?;
    let work = cfg.out.join("work");
    let summary = Mutex::new(Summary::default());
    let next = AtomicU64::new(0);
    let start = Instant::now();
    std::thread::scope(|s| -> Result<()> {
        let handles: Vec<_> = (0..cfg.jobs.max(1))
            .map(|w| {
                let (seeds, summary, next, work) = (&seeds, &summary, &next, &work);
                s.spawn(move || worker(cfg, seeds, &work.join(w.to_string()), next, start, summary))
            })
            .collect();
        for h in handles {
            h.join()
                .map_err(|_| anyhow::anyhow!("a fuzz worker panicked"))??;
        }
        Ok(())
    })?;
    let mut out = summary
        .into_inner()
        .map_err(|_| anyhow::anyhow!("poisoned summary"))?;
    out.elapsed = start.elapsed();
    Ok(out)
}

/// One worker: takes case indices until the count or the time runs out.
fn worker(
    cfg: &Config,
    seeds: &[Seed],
    work: &Path,
    next: &AtomicU64,
    start: Instant,
    summary: &Mutex<Summary>,
) -> Result<()> {
    loop {
        if cfg.duration.is_some_and(|d| start.elapsed() >= d) {
            return Ok(());
        }
        let i = next.fetch_add(1, Ordering::Relaxed);
        if cfg.cases.is_some_and(|n| i >= n) {
            return Ok(());
        }
        let mut rng = Rng::for_case(cfg.seed, i);
        let seed = &seeds[rng.below(seeds.len())];
        let case = make_case(&mut rng, seed, seeds);
        let crop = crop_window(&mut rng);
        let dir = work.join(dir_name(seed));
        prepare_dir(&dir, seed)?;
        write_case(&dir, &case)?;
        let args = candela_args("case.pbrt", crop, cfg.runner.mem_mib / 2);
        let res = cfg.runner.run(&dir, &args)?;
        record(cfg, summary, i, seed, &case, &res)?;
    }
}

/// A window of about 2 % of the film in each direction, somewhere on it.
fn crop_window(rng: &mut Rng) -> [f32; 4] {
    let x = (rng.unit() * 0.97) as f32;
    let y = (rng.unit() * 0.97) as f32;
    let q = |v: f32| (v * 1000.0).round() / 1000.0;
    [q(x), q(x + 0.02), q(y), q(y + 0.02)]
}

/// A file-system-friendly name for a seed (`cornell-box-scene`).
fn dir_name(seed: &Seed) -> String {
    seed.label.trim_end_matches(".pbrt").replace('/', "-")
}

/// Creates `dir` with links to every entry of the seed's directory.
fn prepare_dir(dir: &Path, seed: &Seed) -> Result<()> {
    if dir.exists() {
        return Ok(());
    }
    std::fs::create_dir_all(dir).with_context(|| format!("creating {}", dir.display()))?;
    for e in std::fs::read_dir(&seed.dir)? {
        let e = e?;
        let name = e.file_name();
        if e.path().extension().is_some_and(|x| x == "exr") {
            continue;
        }
        std::os::unix::fs::symlink(e.path(), dir.join(&name))
            .with_context(|| format!("linking {}", e.path().display()))?;
    }
    Ok(())
}

/// Writes the case's files into `dir`.
fn write_case(dir: &Path, case: &Case) -> Result<()> {
    std::fs::write(dir.join("case.pbrt"), &case.scene)?;
    for (name, bytes) in &case.extra {
        std::fs::write(dir.join(name), bytes)?;
    }
    Ok(())
}

/// Counts a result and saves the case if it is worth keeping.
fn record(
    cfg: &Config,
    summary: &Mutex<Summary>,
    index: u64,
    seed: &Seed,
    case: &Case,
    res: &RunResult,
) -> Result<()> {
    let unlocated = res.outcome == Outcome::CleanError && !res.located;
    let mut sum = summary
        .lock()
        .map_err(|_| anyhow::anyhow!("poisoned summary"))?;
    sum.cases += 1;
    *sum.counts.entry(res.outcome).or_default() += 1;
    sum.unlocated += u64::from(unlocated);
    let class = if unlocated && sum.unlocated <= 100 {
        "unlocated"
    } else if matches!(res.outcome, Outcome::Ok | Outcome::CleanError) {
        return Ok(());
    } else {
        res.outcome.name()
    };
    let dir = cfg
        .out
        .join(class)
        .join(format!("{index:07}-{}", dir_name(seed)));
    if class != "unlocated" {
        let key = (res.outcome, res.signature.clone());
        let f = sum.findings.entry(key).or_insert_with(|| Finding {
            count: 0,
            example: dir.clone(),
        });
        f.count += 1;
        if f.count > MAX_SAVED_PER_SIGNATURE {
            return Ok(());
        }
    }
    drop(sum);
    save(&dir, seed, case, res)
}

/// Saves a case so that `sh replay.sh` in its directory reruns it.
fn save(dir: &Path, seed: &Seed, case: &Case, res: &RunResult) -> Result<()> {
    if dir.exists() {
        std::fs::remove_dir_all(dir)?;
    }
    prepare_dir(dir, seed)?;
    write_case(dir, case)?;
    std::fs::write(dir.join("stderr.txt"), &res.stderr)?;
    let ops = format!("seed scene {}\n{}\n", seed.label, case.ops.join("\n"));
    std::fs::write(dir.join("ops.txt"), ops)?;
    let quoted: Vec<String> = res
        .command
        .iter()
        .skip(1)
        .map(|a| format!("'{a}'"))
        .collect();
    let replay = format!(
        "#!/bin/sh\n# Replays this case: run from anywhere, CANDELA overrides the binary.\n\
         cd \"$(dirname \"$0\")\" && exec \"${{CANDELA:-candela}}\" {}\n",
        quoted.join(" ")
    );
    std::fs::write(dir.join("replay.sh"), replay)?;
    Ok(())
}
