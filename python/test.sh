#!/usr/bin/env bash
# The Python package's tests: `pip install ./python` into a virtual environment of its own
# (target/pyvenv, made on first use) with the test extras (pytest, pyarrow, dask), then pytest.
set -euo pipefail
cd "$(dirname "$0")/.."
if [ ! -x target/pyvenv/bin/python ]; then
    python3 -m venv target/pyvenv
    target/pyvenv/bin/pip install -q --upgrade pip
fi
target/pyvenv/bin/pip install -q "./python[test]"
# run from outside the source folder, so that `import termid` is the installed package
cd target && pyvenv/bin/python -m pytest -q ../python/tests
