#!/usr/bin/env bash
# Every test of candela: the Rust workspace, then the Python module and the
# Dask farm (python/tests) in a virtual environment made here with the
# packages of python/requirements-test.txt from PyPI. Needs cargo and
# CPython >= 3.9 with pip (python3, or $PYTHON).
set -euo pipefail
cd "$(dirname "$0")"
cargo test --workspace --release
# The CLI the Python tests compare with (already built by the tests above).
cargo build --release -p candela
venv=target/python-venv
if [ ! -x "$venv/bin/python" ]; then
    "${PYTHON:-python3}" -m venv "$venv"
fi
# maturin's build backend and the tests' `dask` commands are found on PATH.
export PATH="$PWD/$venv/bin:$PATH"
pip=("$venv/bin/python" -m pip --disable-pip-version-check --quiet)
"${pip[@]}" install -r python/requirements-test.txt
"${pip[@]}" install --no-build-isolation --force-reinstall --no-deps ./python
CANDELA_BIN="$PWD/target/release/candela" "$venv/bin/python" -m pytest python/tests -q -p no:cacheprovider
