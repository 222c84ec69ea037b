#!/usr/bin/env bash
# CI: the Python package (python/, docs/python.md): built and installed
# from the repository into a fresh virtual environment, with its test
# dependencies from PyPI, then its pytest suite.
set -euo pipefail
cd "$(dirname "$0")/.."

# Debian's python3 makes virtual environments only with python3-venv.
venv="$(mktemp -d)/venv"
if ! python3 -m venv "$venv" 2>/dev/null; then
    apt-get update -qq
    DEBIAN_FRONTEND=noninteractive apt-get install -y -qq python3-venv >/dev/null
    rm -rf "$venv"
    python3 -m venv "$venv"
fi
"$venv/bin/pip" install --quiet --upgrade pip
"$venv/bin/pip" install --quiet maturin numpy shapely geopandas dask distributed dask-geopandas pytest trimesh tqdm
# The README's install command (a release build of the engine).
"$venv/bin/pip" install --quiet ./python

# From the repository root, so that `import cga` is the installed package,
# not the source folder python/cga (which lacks the compiled module).
"$venv/bin/pytest" -q -p no:cacheprovider python/tests

# The build's disk space, for the fuzz build that follows.
rm -rf python/target "$venv"
