#!/usr/bin/env bash
# The whole test suite, as the README's test command and CI run it: the Rust tests
# (`cargo test --release`), then the Python package's. For the latter it makes a virtual
# environment (.venv, or $SMOOTHTRACE_VENV), installs the package from this checkout
# (`pip install .`: maturin builds python/ into the same target/ directory, so only the
# bindings and pyo3/numpy are compiled on top of the Rust tests' build), and runs
# pytest on tests/python. trimesh (with rtree, scipy) is installed when the package index
# provides it within two minutes; without it the comparison with trimesh skips and says
# why. So is playwright (the browser test drives the system's Chromium with it; no
# browser is downloaded), and so are dask, distributed and zarr (the `[dask]` extra,
# for smoothtrace.dask and reading the command line's .zarr volumes). Exits non-zero if either suite fails.
set -uo pipefail
cd "$(dirname "$0")/.."

cargo test --release
rust=$?

venv=${SMOOTHTRACE_VENV:-.venv}
python=${PYTHON:-python3}
py=1
if "$python" -m venv "$venv" && "$venv/bin/python" -m pip install --quiet --upgrade pip &&
    "$venv/bin/python" -m pip install --quiet . pytest numpy; then
    timeout 120 "$venv/bin/python" -m pip install --quiet trimesh rtree scipy ||
        echo "note: trimesh/rtree/scipy not installed; the trimesh comparison will skip"
    timeout 120 "$venv/bin/python" -m pip install --quiet playwright ||
        echo "note: playwright not installed; the browser test will skip"
    timeout 180 "$venv/bin/python" -m pip install --quiet "dask[array,distributed]>=2023.1" "zarr>=2.16" ||
        echo "note: dask/distributed/zarr not installed; the smoothtrace.dask tests will skip"
    SMOOTHTRACE_BIN="$PWD/target/release/smoothtrace" \
        "$venv/bin/python" -m pytest -p no:cacheprovider -rs tests/python
    py=$?
else
    echo "error: could not install the Python package (see above)"
fi

if [ "$rust" -ne 0 ] || [ "$py" -ne 0 ]; then
    echo "test suites failed: cargo exit $rust, pytest exit $py"
    exit 1
fi
