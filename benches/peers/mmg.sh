#!/usr/bin/env bash
# termid's MMG model file (models/mmg_kvlcc2.toml) against the shipmmg package: turning circles
# ±35°, ±20° and zigzags 10/10, 20/20, the same rudder series given to both. Uses the peers'
# virtual environment (pinned versions in requirements.txt). Exit status 1 if a difference
# exceeds the targets (0.5 % on advance and tactical diameter, 0.2° on overshoots).
set -euo pipefail
cd "$(dirname "$0")"
if [ ! -x .venv/bin/python ] || ! .venv/bin/python -c 'import shipmmg' 2>/dev/null; then
    python3 -m venv .venv
    .venv/bin/pip install -q -r requirements.txt
fi
cargo build --release --quiet
cd ../..
benches/peers/.venv/bin/python benches/peers/shipmmg_compare.py --termid target/release/termid \
    --work benches/peers/work/mmg "$@" | tee benches/peers/shipmmg.md
