//! `candela-fuzz`: runs a fuzz campaign against the `candela` binary.
//!
//! ```text
//! candela-fuzz [--cases N | --duration SECS] [--seed S] [--jobs J]
//!              [--timeout SECS] [--mem-mib M] [--out DIR] [--scenes DIR]
//!              [--candela PATH]
//! ```
//! The summary goes to stdout; the exit status is 1 if a case panicked,
//! aborted or hung with a signature not in `findings/known.txt`.

use std::path::PathBuf;
use std::time::Duration;

use anyhow::{Context, Result};
use candela_fuzz::campaign::{self, Config};
use candela_fuzz::known;
use candela_fuzz::run::Runner;
use clap::Parser;

/// Structure-aware mutation fuzzer for candela's scene input.
#[derive(Parser)]
#[command(about)]
struct Args {
    /// Number of cases to run.
    #[arg(long)]
    cases: Option<u64>,
    /// Run for this many seconds (with --cases: whichever ends first).
    #[arg(long)]
    duration: Option<u64>,
    /// Campaign seed: the same seed gives the same cases.
    #[arg(long, default_value_t = 1)]
    seed: u64,
    /// Cases run in parallel.
    #[arg(long, default_value_t = 2)]
    jobs: usize,
    /// Time limit per case, in seconds.
    #[arg(long, default_value_t = 20)]
    timeout: u64,
    /// Address-space limit per case, in MiB.
    #[arg(long, default_value_t = 2048)]
    mem_mib: u64,
    /// Output directory (work directories and saved cases).
    #[arg(long, default_value = "target/fuzz-out")]
    out: PathBuf,
    /// Seed scenes.
    #[arg(long, default_value = concat!(env!("CARGO_MANIFEST_DIR"), "/../../scenes"))]
    scenes: PathBuf,
    /// The candela binary (default: `candela` beside this program).
    #[arg(long)]
    candela: Option<PathBuf>,
}

fn main() -> Result<()> {
    let a = Args::parse();
    let candela = match a.candela {
        Some(p) => p,
        None => std::env::current_exe()?
            .parent()
            .context("no directory for this program")?
            .join("candela"),
    };
    anyhow::ensure!(
        candela.is_file(),
        "no candela binary at {}",
        candela.display()
    );
    // Cases run in their own directories: a relative path would not resolve.
    let candela = std::fs::canonicalize(&candela)?;
    let cfg = Config {
        scenes: a.scenes,
        out: a.out,
        seed: a.seed,
        cases: a.cases,
        duration: a.duration.map(Duration::from_secs),
        jobs: a.jobs,
        runner: Runner {
            candela,
            timeout: Duration::from_secs(a.timeout),
            mem_mib: a.mem_mib,
        },
    };
    let summary = campaign::run(&cfg)?;
    print!("{}", summary.report());
    let list = known::parse(known::KNOWN).map_err(anyhow::Error::msg)?;
    let new: Vec<_> = summary
        .findings
        .keys()
        .filter(|(o, s)| o.is_crash() && !known::is_known(&list, *o, s))
        .collect();
    println!(
        "new crash signatures (not in findings/known.txt): {}",
        new.len()
    );
    if !new.is_empty() {
        std::process::exit(1);
    }
    Ok(())
}
