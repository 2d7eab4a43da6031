#!/usr/bin/env bash
# The Python package's tests, run against the wheel users install: the wheel is built
# (maturin, stable ABI for Python >= 3.9, release without debug info, stripped) into
# target/wheels, installed with its test extras into a virtual environment of its own
# (target/pyvenv: made afresh under CI, reused otherwise), and the pytest suite runs against it;
# then the API reference is generated from the docstrings (pdoc) into target/pydoc.
set -euo pipefail
cd "$(dirname "$0")/.."
if [ -n "${CI:-}" ]; then rm -rf target/pyvenv; fi
if [ ! -x target/pyvenv/bin/python ]; then
    python3 -m venv target/pyvenv
    target/pyvenv/bin/pip install -q --upgrade pip
fi
rm -rf target/wheels
target/pyvenv/bin/pip wheel -q --no-deps -w target/wheels ./python
wheel=$(ls target/wheels/termid-*.whl)
echo "built $(basename "$wheel") ($(du -k "$wheel" | cut -f1) kB)"
target/pyvenv/bin/pip install -q --force-reinstall --no-deps "$wheel"
target/pyvenv/bin/pip install -q "${wheel}[test,docs]"
# run from outside the source folder, so that `import termid` is the installed wheel
(cd target && pyvenv/bin/python -m pytest -q ../python/tests)
rm -rf target/pydoc
target/pyvenv/bin/python -m pdoc -o target/pydoc termid termid.plot termid.sklearn 2>&1 | tee target/pydoc.log
if grep -qi "warn" target/pydoc.log; then echo "pdoc warned: see above" >&2; exit 1; fi
echo "API reference: target/pydoc/termid.html"
