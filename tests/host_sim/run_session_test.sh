#!/usr/bin/env bash
# One paper scene end to end in lockstep: SimFalcon + rt_core + host_sim + proxy
# builder through `fissure run SCENE --lockstep`, then the session's summary.json is checked.
#   run_session_test.sh FISSURE SCENE OUT_DIR safety   runs the session; asserts 0 crossed nodes,
#                                                      no faults, |F| within the rt force limit,
#                                                      and that the session really made contact
#   run_session_test.sh FISSURE SCENE OUT_DIR energy   reads OUT_DIR/summary.json (written by the
#                                                      safety test); asserts energy_j <= 0 (passive)
set -u
fissure=${1:?usage: run_session_test.sh FISSURE SCENE OUT_DIR safety|energy}
scene=${2:?scene}
out=${3:?out dir}
check=${4:?safety|energy}
if [[ $check == safety ]]; then
  rm -rf "$out"
  if ! "$fissure" run "$scene" --lockstep --quiet --no-plot --out "$out"; then
    echo "FAIL: fissure run $scene --lockstep exited with an error"; exit 1
  fi
fi
if [[ ! -f $out/summary.json ]]; then echo "FAIL: $out/summary.json missing"; exit 1; fi
/usr/bin/python3 - "$out/summary.json" "$check" <<'PY'
import json, sys
s = json.load(open(sys.argv[1]))
check = sys.argv[2]
failures = []
if check == "safety":
    if s["crossed_nodes_max"] != 0: failures.append(f"crossed_nodes_max = {s['crossed_nodes_max']} (must be 0)")
    if s["faults"] != 0: failures.append(f"faults = {s['faults']} ticks ({', '.join(s['fault_kinds'])})")
    if s["proxies_rejected"] != 0: failures.append(f"proxies_rejected = {s['proxies_rejected']}")
    if not s["force_max_n"] <= s["force_limit_n"]: failures.append(f"force_max_n = {s['force_max_n']:.3f} > limit {s['force_limit_n']}")
    if s["ticks"] < 0.99 * s["duration_s"] * s["rt_rate_hz"]: failures.append(f"only {s['ticks']} ticks in {s['duration_s']} s")
    # A fault-free session has one position epoch (its first sample): one re-seat, never a sweep
    # from the scene's start pose; and the soft body is never turned inside out.
    if s["tool_reseats"] != 1: failures.append(f"tool_reseats = {s['tool_reseats']} (a fault-free session has exactly 1)")
    if not s["soft_volume_ratio_min"] > 0.0: failures.append(f"soft_volume_ratio_min = {s['soft_volume_ratio_min']:.3f}: soft body turned inside out")
    # The session must touch the soft body, or the checks above prove nothing.
    if not s["host_force_max_n"] > 0.1: failures.append(f"host_force_max_n = {s['host_force_max_n']:.3f}: no contact happened")
    if not s["contact_force_max_n"] > 0.1: failures.append(f"contact_force_max_n = {s['contact_force_max_n']:.3f}: rt rendered no contact")
elif check == "energy":
    if not s["energy_j"] <= 0.0: failures.append(f"energy_j = {s['energy_j']:.6g} J > 0: the session put energy into the hand (not passive)")
else:
    failures.append("unknown check " + check)
for f in failures: print(f"FAIL {s['scene']}: {f}")
if not failures: print(f"ok {s['scene']} ({check}): crossed {s['crossed_nodes_max']}, faults {s['faults']}, "
                      f"force max {s['force_max_n']:.2f} N, energy {s['energy_j']:.3g} J")
sys.exit(1 if failures else 0)
PY
