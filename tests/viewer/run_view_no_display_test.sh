#!/usr/bin/env bash
# `fissure run SCENE --lockstep --view` with no display: exactly one line says so, the
# session runs on to the end (exit 0, summary written, the window recorded as requested but not
# open).
#   run_view_no_display_test.sh FISSURE SCENE OUT_DIR
set -u
fissure=${1:?usage: run_view_no_display_test.sh FISSURE SCENE OUT_DIR}
scene=${2:?scene}
out=${3:?out dir}
rm -rf "$out"
mkdir -p "$out"
if ! env -u DISPLAY -u WAYLAND_DISPLAY "$fissure" run "$scene" --lockstep --view --quiet --no-plot --out "$out" > "$out/stdout.txt" 2> "$out/stderr.txt"; then
  cat "$out/stdout.txt" "$out/stderr.txt"; echo "FAIL: the session did not run on without a display"; exit 1
fi
lines=$(grep -c -- "--view: no display" "$out/stderr.txt")
if [[ $lines != 1 ]]; then cat "$out/stderr.txt"; echo "FAIL: $lines lines about the missing display, expected exactly 1"; exit 1; fi
/usr/bin/python3 - "$out/summary.json" <<'PY'
import json, sys
s = json.load(open(sys.argv[1]))
w = s["view"]["window"]
ok = w["requested"] and not w["open"] and s["ticks"] > 0 and s["crossed_nodes_max"] == 0
print("ok: ran on without the view" if ok else f"FAIL: summary view {s['view']}, ticks {s['ticks']}")
sys.exit(0 if ok else 1)
PY
