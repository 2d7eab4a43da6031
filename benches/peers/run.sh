#!/usr/bin/env bash
# termid's back-ends against the peers, timed the same way on the same data, on this machine.
# Creates its own virtual environment (pinned versions in requirements.txt); Python serves
# only this comparison, never the product. Usage: benches/peers/run.sh [--quick]
set -euo pipefail
cd "$(dirname "$0")"
if [ ! -x .venv/bin/python ]; then
    python3 -m venv .venv
    .venv/bin/pip install -q -r requirements.txt
fi
cargo build --release --quiet
../../target/release/termid reproduce --out work >/dev/null
.venv/bin/python peers.py --termid ../../target/release/termid --data work/data "$@" | tee results.md
