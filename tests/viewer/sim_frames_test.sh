#!/usr/bin/env bash
# `fissure sim SCENE --frames DIR --frame-every K`, no GPU, no display: one PNG per K
# steps (ceil(steps / K), each waited for), listed in DIR/frames.json, each a real picture (not
# the background colour alone), and the summary JSON reports them.
#   sim_frames_test.sh FISSURE SCENE OUT_DIR FRAME_EVERY SECONDS
set -u
fissure=${1:?usage: sim_frames_test.sh FISSURE SCENE OUT_DIR FRAME_EVERY SECONDS}
scene=${2:?scene}
out=${3:?out dir}
every=${4:?frame every}
seconds=${5:?seconds}
rm -rf "$out"
if ! "$fissure" sim "$scene" --seconds "$seconds" --settle-seconds 0.1 --frames "$out/frames" --frame-every "$every" \
     --width 320 --height 240 --json "$out/summary.json" > "$out.log" 2>&1; then
  cat "$out.log"; echo "FAIL: fissure sim $scene --frames exited with an error"; exit 1
fi
/usr/bin/python3 - "$out" "$every" <<'PY'
import json, math, os, sys
from PIL import Image
out, every = sys.argv[1], int(sys.argv[2])
s = json.load(open(os.path.join(out, "summary.json")))
index = json.load(open(os.path.join(out, "frames", "frames.json")))
pngs = sorted(f for f in os.listdir(os.path.join(out, "frames")) if f.endswith(".png"))
expected = math.ceil(s["steps"] / every)
failures = []
if len(pngs) != expected: failures.append(f"{len(pngs)} PNGs for {s['steps']} steps every {every}, expected {expected}")
if s["frames"]["written"] != expected or s["frames"]["dropped"] != 0: failures.append(f"summary frames {s['frames']}")
if [f["file"] for f in index["frames"]] != pngs: failures.append("frames.json does not list the PNG files")
for name in pngs:
    im = Image.open(os.path.join(out, "frames", name)).convert("RGB")
    colours = im.getcolors(maxcolors=1 << 20)
    if im.size != (320, 240) or colours is None or len(colours) < 50: failures.append(f"{name}: blank or wrong size")
for f in failures: print("FAIL:", f)
if not failures: print(f"ok: {len(pngs)} frames from {s['steps']} steps")
sys.exit(1 if failures else 0)
PY
