#!/usr/bin/env bash
# `fissure device kinematics` and `fissure bench kinematics` (app/device_kinematics.cpp,
# eval/src/bench_kinematics.cpp): JSON out, IK/FK agree, clear errors outside the workspace.
set -u
fissure=${1:?usage: device_kinematics_test.sh <path to fissure>}
fail() { echo "FAIL: $*"; exit 1; }

out=$("$fissure" device kinematics --ik 0 0 0.125) || fail "--ik at the centre exited $?"
for key in position_m theta_rad encoder; do grep -q "\"$key\":\[" <<<"$out" || fail "--ik output lacks $key: $out"; done
encoder=$(grep -o '"encoder":\[[^]]*\]' <<<"$out" | grep -o '\-\?[0-9]\+' | tr '\n' ' ')
read -r e1 e2 e3 <<<"$encoder"
[[ $e1 == "$e2" && $e2 == "$e3" ]] || fail "centre should give equal counts on all arms: $out"

# Negative coordinates parse as values, and FK of IK's counts lands within a few counts' travel.
out=$("$fissure" device kinematics --ik -0.02 0.01 0.11) || fail "--ik -0.02 0.01 0.11 exited $?"
encoder=$(grep -o '"encoder":\[[^]]*\]' <<<"$out" | grep -o '\-\?[0-9]\+' | tr '\n' ' ')
read -r e1 e2 e3 <<<"$encoder"
out=$("$fissure" device kinematics --fk "$e1" "$e2" "$e3") || fail "--fk $e1 $e2 $e3 exited $?"
position=$(grep -o '"position_m":\[[^]]*\]' <<<"$out" | sed 's/.*\[\(.*\)\]/\1/' | tr ',' ' ')
awk -v p="$position" 'BEGIN { split(p, v, " "); d = (v[1]+0.02)^2 + (v[2]-0.01)^2 + (v[3]-0.11)^2;
  exit !(d < (1e-4)^2) }' || fail "--fk of the counts of (-0.02, 0.01, 0.11) gave $position"

expect_error() {
  local want_rc=$1; shift
  local out rc
  out=$("$fissure" "$@" 2>&1); rc=$?
  [[ $rc -eq $want_rc ]] || fail "'fissure $*' exited $rc, want $want_rc (output: $out)"
  [[ $(wc -l <<<"$out") -eq 1 ]] || fail "'fissure $*' printed more than one line:"$'\n'"$out"
  grep -q '^fissure: error: ' <<<"$out" || fail "'fissure $*': $out"
  echo "$out"
}
expect_error 1 device kinematics --ik 0 0 0.3 | grep -q "outside the Falcon workspace" || fail "no workspace message"
expect_error 1 device kinematics --fk 30000 0 0 >/dev/null
expect_error 2 device kinematics >/dev/null
expect_error 2 device kinematics --fk 40000 0 0 >/dev/null
expect_error 2 device kinematics --ik 0 0 >/dev/null

# Benchmark smoke run: keys present and the accuracy figures (not the timings) hold.
json=$(mktemp)
trap 'rm -f "$json"' EXIT
"$fissure" bench kinematics --json "$json" --samples 256 --repeats 1 >/dev/null || fail "bench kinematics exited $?"
for key in fk_roundtrip_max_error_m jacobian_max_rel_error fk_warm_median_ns fk_cold_median_ns ik_median_ns \
           baseline_libnifalcon tolerance_table machine; do
  grep -q "\"$key\"" "$json" || fail "bench JSON lacks $key"
done
roundtrip=$(grep -o '"fk_roundtrip_max_error_m": [^,]*' "$json" | awk '{print $2}')
awk -v e="$roundtrip" 'BEGIN { exit !(e <= 1e-6) }' || fail "round-trip error $roundtrip m > 1 um"
echo "device/bench kinematics CLI holds"
