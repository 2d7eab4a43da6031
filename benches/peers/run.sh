#!/usr/bin/env bash
# termid's back-ends against the peers, timed the same way on the same data, on this machine.
# Creates its own virtual environment (pinned versions in requirements.txt); Python serves
# only this comparison and termid's own Python package (python/), never the core. Usage: benches/peers/run.sh [--quick]
set -euo pipefail
cd "$(dirname "$0")"
if [ ! -x .venv/bin/python ]; then
    python3 -m venv .venv
    .venv/bin/pip install -q -r requirements.txt
fi
# termid's Python package, so that the peers are timed against it in the same process
.venv/bin/pip install -q ../../python
cargo build --release --quiet
../../target/release/termid reproduce --out work >/dev/null
.venv/bin/python peers.py --termid ../../target/release/termid --data work/data "$@" | tee results.md
