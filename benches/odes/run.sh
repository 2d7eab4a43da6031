#!/usr/bin/env bash
# termid's defaults against pysindy's on published ODE systems (README.md here). Uses the peers'
# virtual environment (pinned versions in ../peers/requirements.txt). Usage:
#   benches/odes/run.sh [--systems lorenz,rossler] [--no-pysindy]
set -euo pipefail
cd "$(dirname "$0")"
venv=../peers/.venv
if [ ! -x $venv/bin/python ] || ! $venv/bin/python -c 'import pysindy, scipy' 2>/dev/null; then
    python3 -m venv $venv
    $venv/bin/pip install -q -r ../peers/requirements.txt
fi
cargo build --release --quiet
$venv/bin/python odes.py --termid ../../target/release/termid --work work "$@" | tee results.md
