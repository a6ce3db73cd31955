#!/usr/bin/env bash
# Runs every test of lieflow: format and lint checks, the Rust tests (with proptest properties and
# a smoke run of each criterion bench) and the rustdoc build, then builds the Python extension once
# and runs pytest and the documentation build (Sphinx, warnings as errors; it runs the gallery).
# Makes its own virtual environment (.venv, or $LIEFLOW_VENV).
set -euo pipefail
cd "$(dirname "$0")/.."
export CARGO_TERM_COLOR=never
venv=$(realpath -m "${LIEFLOW_VENV:-.venv}")
t0=$SECONDS
step() { printf '\n== %s (%ds)\n' "$*" "$((SECONDS - t0))"; }

step "python environment"
[ -x "$venv/bin/python" ] || python3 -m venv "$venv"
"$venv/bin/python" -m pip install -q --disable-pip-version-check "maturin>=1.9.4,<2" numpy scipy pytest hypothesis tqdm matplotlib pillow xarray netCDF4 mypy dask distributed sphinx sphinx-gallery myst-parser pydata-sphinx-theme sphinx-mathjax-offline

step "cargo fmt --check"
cargo fmt --all -- --check

step "cargo clippy -D warnings"
cargo clippy --workspace --all-targets --release -- -D warnings

step "cargo test (release; benches run once in test mode)"
cargo test --workspace --exclude lieflow-py --release --all-targets
cargo test --workspace --exclude lieflow-py --release --doc

step "cargo doc (-D warnings)"
RUSTDOCFLAGS="-D warnings" cargo doc --no-deps --workspace

step "build the extension (maturin develop --release)"
VIRTUAL_ENV="$venv" PATH="$venv/bin:$PATH" "$venv/bin/maturin" develop --release -q

step "pytest"
"$venv/bin/python" -m pytest -q python/tests

step "wheel (maturin build --release) installed into a fresh venv with only the docs extra"
# The path a lab takes (docs/guide/installation.md): one abi3 wheel, built once (it reuses the
# extension just compiled), installed where there is no Rust; then the demo, and the docs built
# by that venv: docs/ -> docs/_build/html, MyST pages, the API reference from the installed
# wheel and the gallery, which executes every script in examples/ (docs/conf.py).
rm -rf target/wheels
"$venv/bin/maturin" build --release -q
wheel=$(ls target/wheels/lieflow-*-abi3-*.whl)
fresh=$(mktemp -d)
python3 -m venv "$fresh/venv"
"$fresh/venv/bin/python" -m pip install -q --disable-pip-version-check "$wheel[docs]"
(cd "$fresh" && "$fresh/venv/bin/python" -c "import lieflow, sys; assert 'site-packages' in lieflow.__file__, lieflow.__file__" && "$fresh/venv/bin/lieflow" demo)
"$fresh/venv/bin/python" -m sphinx -W --keep-going -b html docs docs/_build/html
rm -rf "$fresh"

step "typing (mypy.stubtest, mypy examples)"
# The .pyi stubs against the built module (allow-list: only what stubtest cannot see, each entry
# with its reason), then the examples type-checked with those stubs ([tool.mypy] in pyproject.toml).
"$venv/bin/python" -m mypy.stubtest lieflow --allowlist python/stubtest-allowlist.txt --mypy-config-file pyproject.toml
"$venv/bin/python" -m mypy examples/

step "done"
