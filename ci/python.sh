#!/usr/bin/env bash
# The Python package: a fresh venv under target/, the pinned build and test tools from PyPI,
# `pip install ./python` (maturin compiles the extension and the core in release mode), then
# the tests in python/tests, one of which compares the result with the command-line tool's.
# PYTHON names the interpreter (default python3, 3.11 or newer for the pinned NumPy).
set -euo pipefail
cd "$(dirname "$0")/.."

# The build backend pyproject.toml pins.
MATURIN_VERSION=1.16.0
PYTEST_VERSION=9.2.0
NUMPY_VERSION=2.4.6
PYTHON=${PYTHON:-python3}
VENV=target/python-venv

export PIP_DISABLE_PIP_VERSION_CHECK=1
# Nothing written into the source tree: no __pycache__ beside the tests.
export PYTHONDONTWRITEBYTECODE=1

rm -rf "$VENV"
"$PYTHON" -m venv "$VENV"
# As `activate` does: the build backend runs the `maturin` command it finds on PATH.
export PATH="$PWD/$VENV/bin:$PATH"
pip install --quiet "maturin==$MATURIN_VERSION" "pytest==$PYTEST_VERSION" \
    "numpy==$NUMPY_VERSION"

# The tool the tests compare with (already built when .ci/run calls this script).
cargo build --release --example complete

# --no-build-isolation: build with the maturin just installed, fetching nothing more. (A plain
# `pip install ./python` fetches the same version, pinned in pyproject.toml, into a build venv.)
pip install --quiet --no-build-isolation ./python

# -p no:cacheprovider: no .pytest_cache in the source tree.
log=target/python-pytest.log
python -m pytest python/tests -q -p no:cacheprovider | tee "$log"
echo "python: $(tail -n 1 "$log") (ci/python.sh took ${SECONDS} s)"
