#!/usr/bin/env bash
# `fissure stress --jobs N` runs cases in child processes (eval/src/stress_parallel.cpp): the rows
# must be the ones the in-process run gives (same figures, same order), since each case is
# deterministic from its own seed — only the wall time may differ.
set -euo pipefail
fissure="$1"
out="$(mktemp -d)"
trap 'rm -rf "$out"' EXIT
cases=(--case hand_jerks --case encoder_stuck --case link_loss_10% --case mesh_zero_area_triangle --case hc_n_2.00)
"$fissure" stress --profile ci "${cases[@]}" --jobs 1 --json "$out/serial.json" > "$out/serial.txt"
"$fissure" stress --profile ci "${cases[@]}" --jobs 3 --json "$out/forked.json" > "$out/forked.txt"
python3 - "$out/serial.json" "$out/forked.json" <<'PY'
import json, sys
serial, forked = (json.load(open(p)) for p in sys.argv[1:3])
assert forked["jobs"] == 3 and serial["jobs"] == 1, (serial["jobs"], forked["jobs"])
def strip(rows):
    return [{k: v for k, v in r.items() if k != "wall_s"} for r in rows]
a, b = strip(serial["cases"]), strip(forked["cases"])
assert [r["name"] for r in a] == ["hand_jerks", "encoder_stuck", "link_loss_10%", "mesh_zero_area_triangle", "hc_n_2.00"], [r["name"] for r in a]
assert all(r["ticks"] > 0 for r in a if r["name"] != "mesh_zero_area_triangle"), "a case ran no ticks"
for x, y in zip(a, b):
    assert x == y, f"row {x['name']} differs between --jobs 1 and --jobs 3:\n{x}\n{y}"
assert serial["failed"] == forked["failed"]
print(f"{len(a)} rows identical between --jobs 1 and --jobs 3")
PY
# The printed table lists the cases in the same order.
diff <(awk '{print $1, $4}' "$out/serial.txt" | grep -v '^fissure\|^case\|^[0-9]' ) \
     <(awk '{print $1, $4}' "$out/forked.txt" | grep -v '^fissure\|^case\|^[0-9]' )
