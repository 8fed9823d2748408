#!/bin/sh
# Long fuzz campaign against candela's scene input (parser, builder, renderer).
#
#   bench/fuzz.sh [DURATION_SECONDS [SEED [OUTDIR]]]
#
# Defaults: 3600 s (one hour), seed = the current Unix time (printed, so a run
# can be repeated: the same seed gives the same cases), OUTDIR =
# target/fuzz-long-SEED. Builds candela and candela-fuzz in release mode,
# copies both binaries into OUTDIR/bin (so rebuilding the tree during the run
# cannot swap the binary under it), and runs `candela-fuzz` niced with two
# workers, a 20 s time limit and a 2 GiB address-space limit per case.
#
# Each case renders a mutated bundled scene (scenes/) with --spp 1 on a
# window of about 2% of the film. The summary (cases, cases/s, counts per
# outcome, distinct failure signatures with an example each) is printed and
# kept in OUTDIR/summary.txt. Cases that panicked, aborted, hung or hit the
# memory limit are saved under OUTDIR/<outcome>/<index>-<scene>/ with the
# case's files, stderr.txt, ops.txt (the mutations) and replay.sh:
#
#   CANDELA=OUTDIR/bin/candela sh OUTDIR/panic/0001234-cornell-box-scene/replay.sh
#
# Exit status: 0 when every crash signature is in
# crates/candela-fuzz/findings/known.txt, 1 when there are new ones.
# Extra options for candela-fuzz (e.g. --jobs 1) go in FUZZ_ARGS.
set -eu
cd "$(dirname "$0")/.."
duration=${1:-3600}
seed=${2:-$(date +%s)}
out=${3:-target/fuzz-long-$seed}
echo "fuzz: ${duration} s, seed ${seed}, output ${out}"
cargo build --release -p candela -p candela-fuzz
mkdir -p "$out/bin"
cp target/release/candela target/release/candela-fuzz "$out/bin/"
# The pipe through tee would hide the fuzzer's exit status: keep it in a file.
{
    st=0
    # shellcheck disable=SC2086
    nice -n 10 "$out/bin/candela-fuzz" --duration "$duration" --seed "$seed" \
        --out "$out" --scenes scenes --candela "$out/bin/candela" ${FUZZ_ARGS:-} || st=$?
    echo "$st" >"$out/status"
} | tee "$out/summary.txt"
status=$(cat "$out/status")
rm -rf "$out/work" "$out/status"
exit "$status"
