#!/usr/bin/env bash
# The release binary on an emulated CPU without AVX2 (QEMU's Nehalem model, which refuses AVX
# instructions with SIGILL): it must run, on its baseline copies of the hot loops, and print
# the numbers it prints on this CPU. A build that assumed AVX2 (a target-cpu flag) fails here.
set -euo pipefail
cd "$(dirname "$0")/.."
if ! command -v qemu-x86_64 >/dev/null 2>&1; then
    apt-get update -qq && apt-get install -y -qq qemu-user
fi
bin=${WOODPILE:-target/release/woodpile}
# auto at 1e-8: rkn6-contact with its verification runs, so every dispatched loop runs.
scene=scenes/single_eps10.toml
native=$("$bin" simulate "$scene")
emulated=$(qemu-x86_64 -cpu Nehalem "$bin" simulate "$scene")
python3 - "$native" "$emulated" <<'PY'
import json, sys
native, emulated = (json.loads(text) for text in sys.argv[1:3])
for run in (native, emulated):
    run.pop("wall_s", None)
if native != emulated:
    sys.exit(f"an emulated CPU without AVX2 gives other numbers:\n{native}\n{emulated}")
print("no AVX2 (emulated Nehalem): runs, and gives the same numbers as this CPU")
PY
