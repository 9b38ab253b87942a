#!/usr/bin/env bash
# `fissure run SCENE --lockstep --frames DIR --frame-every K`, no GPU, no display:
#   * the session writes one PNG per K host steps (ceil(host_steps / K), none dropped: lockstep
#     waits for each), listed in DIR/frames.json;
#   * every frame is a picture (not blank) with the sphere's silhouette where the camera puts it
#     (frames.json's subject_px, from the same OrbitCamera maths the shaders use): soft-body
#     colour filling the inner disc, none of it in a ring just outside;
#   * frames do not change the physics: the same session without --frames writes a byte-identical
#     trace.csv and the same summary figures (crossed nodes, forces, energy, ticks, host steps).
#   run_frames_test.sh FISSURE SCENE OUT_DIR FRAME_EVERY
set -u
fissure=${1:?usage: run_frames_test.sh FISSURE SCENE OUT_DIR FRAME_EVERY}
scene=${2:?scene}
out=${3:?out dir}
every=${4:?frame every}
rm -rf "$out"
common=(run "$scene" --lockstep --quiet --no-plot)
if ! "$fissure" "${common[@]}" --out "$out/plain"; then echo "FAIL: fissure run $scene --lockstep exited with an error"; exit 1; fi
if ! "$fissure" "${common[@]}" --out "$out/framed" --frames "$out/framed/frames" --frame-every "$every" --width 480 --height 360; then
  echo "FAIL: fissure run $scene --lockstep --frames exited with an error"; exit 1
fi
/usr/bin/python3 - "$out" "$every" <<'PY'
import json, math, os, sys
from PIL import Image  # Debian python3-pil (pulled in by python3-matplotlib, toolchain/setup.sh)

out, every = sys.argv[1], int(sys.argv[2])
failures = []
plain = json.load(open(os.path.join(out, "plain", "summary.json")))
framed = json.load(open(os.path.join(out, "framed", "summary.json")))

# Frames must not change the physics (lockstep is deterministic, so: exactly equal).
for key in ["crossed_nodes_max", "faults", "overruns", "force_max_n", "contact_force_max_n", "host_force_max_n", "energy_j",
            "ticks", "host_steps", "contact_depth_max_mm", "host_penetration_max_mm"]:
    if plain[key] != framed[key]:
        failures.append(f"summary {key}: {plain[key]} without frames, {framed[key]} with")
if open(os.path.join(out, "plain", "trace.csv"), "rb").read() != open(os.path.join(out, "framed", "trace.csv"), "rb").read():
    failures.append("trace.csv differs with --frames")
if plain["host_force_max_n"] <= 0.1:
    failures.append("the session made no contact: the comparison proves nothing")

view = framed.get("view", {}).get("frames")
frames_dir = os.path.join(out, "framed", "frames")
expected = math.ceil(framed["host_steps"] / every)
if view is None:
    failures.append("summary.json has no view.frames")
else:
    if view["written"] != expected: failures.append(f"summary: {view['written']} frames written, expected {expected}")
    if view["dropped"] != 0: failures.append(f"summary: {view['dropped']} frames dropped in lockstep")
index = json.load(open(os.path.join(frames_dir, "frames.json")))
pngs = sorted(f for f in os.listdir(frames_dir) if f.endswith(".png"))
if len(pngs) != expected: failures.append(f"{len(pngs)} PNG files, expected ceil({framed['host_steps']} / {every}) = {expected}")
if [f["file"] for f in index["frames"]] != pngs: failures.append("frames.json does not list the PNG files")
times = [f["time_s"] for f in index["frames"]]
step_s = 1.0 / framed["host_rate_hz"]
for i, t in enumerate(times):
    if abs(t - (i * every + 1) * step_s) > 1e-6: failures.append(f"{pngs[i]}: simulated time {t}, expected {(i * every + 1) * step_s}")

bg = (0.13, 0.14, 0.17)  # viewer palette::kBackground
def is_background(p): return all(abs(p[c] - round(bg[c] * 255)) <= 6 for c in range(3))
def is_soft(p):  # blue (rest) → red (deformed), through purple; not the orange tool, not grey ground
    r, g, b = p[:3]
    return (b > g + 25 and b > 60) or (r > 60 and g < r * 0.45 and b > r / 8)

cx, cy, radius = index["subject_px"]["x"], index["subject_px"]["y"], index["subject_px"]["radius"]
if not (index["width_px"] == 480 and index["height_px"] == 360): failures.append("frames.json: wrong image size")
if radius < 30: failures.append(f"subject radius {radius:.1f} px: the camera does not frame the sphere")
for name in pngs:
    im = Image.open(os.path.join(frames_dir, name)).convert("RGB")
    if im.size != (480, 360): failures.append(f"{name}: size {im.size}"); continue
    px = im.load()
    w, h = im.size
    total = w * h
    background = sum(1 for y in range(0, h, 2) for x in range(0, w, 2) if is_background(px[x, y])) / (total / 4)
    if background > 0.6: failures.append(f"{name}: {background:.0%} background (blank?)")
    inner = [px[x, y] for y in range(h) for x in range(w) if math.hypot(x + 0.5 - cx, y + 0.5 - cy) < 0.8 * radius]
    ring = [px[x, y] for y in range(h) for x in range(w) if 1.2 * radius <= math.hypot(x + 0.5 - cx, y + 0.5 - cy) < 1.5 * radius]
    soft_inner = sum(map(is_soft, inner)) / len(inner)
    soft_ring = sum(map(is_soft, ring)) / len(ring)
    # The spatula may cover part of the top of the disc; the sphere must fill the rest.
    if soft_inner < 0.85: failures.append(f"{name}: only {soft_inner:.0%} of the inner disc is soft body")
    if soft_ring > 0.02: failures.append(f"{name}: {soft_ring:.0%} of the ring outside the silhouette is soft body")
    print(f"{name}: t {times[pngs.index(name)]:.3f} s, background {background:.0%}, soft inside {soft_inner:.0%}, outside {soft_ring:.1%}")
for f in failures: print("FAIL:", f)
if not failures: print(f"ok: {len(pngs)} frames, physics identical with and without --frames")
sys.exit(1 if failures else 0)
PY
