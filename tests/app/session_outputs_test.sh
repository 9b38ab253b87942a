#!/usr/bin/env bash
# What `fissure run` / `fissure sim` leave on disk and say when refused (issue 25): a run refused
# before it starts (no Falcon, a lockstep rate that does not divide, a duration over a day, a
# ball that falls through the ground) leaves an earlier run's files byte for byte; a scene name
# that is no file lists the known scenes and where it looked; a directory is called one; a
# recording replays bit for bit in lockstep, also one recorded in real time.
set -u
fissure=${1:?usage: session_outputs_test.sh <path to fissure>}
work=$(mktemp -d)
trap 'rm -rf "$work"' EXIT
fail=0
bad() { echo "FAIL: $*"; fail=1; }
expect_refusal() {  # expect_refusal <text> <args…>: exit 1 or 2, one line containing <text>
  local text="$1"; shift
  local out rc
  out=$("$fissure" "$@" 2>&1 >/dev/null); rc=$?
  [[ $rc -eq 1 || $rc -eq 2 ]] || { bad "fissure $* exited $rc (output: $out)"; return; }
  [[ $(wc -l <<<"$out") -eq 1 ]] || bad "fissure $* printed more than one line:"$'\n'"$out"
  grep -qF -- "$text" <<<"$out" || bad "fissure $*: want '$text', got: $out"
}

run_dir="$work/run"
"$fissure" run spatula-sphere --lockstep --no-plot --quiet --out "$run_dir" >/dev/null 2>&1 || bad "the lockstep run failed"
[[ -s $run_dir/trace.csv && -s $run_dir/summary.json ]] || bad "the lockstep run wrote no trace or summary"
before=$(cd "$run_dir" && md5sum trace.csv summary.json)

if "$fissure" device probe >/dev/null 2>&1; then
  echo "a Falcon is attached: the --device usb refusal is not checked"
else
  expect_refusal "--device usb" run spatula-sphere --device usb --duration 0.1 --quiet --out "$run_dir"
fi
expect_refusal "use --rate 1000, 2000, 3000, 4000" run spatula-sphere --lockstep --rate 700 --quiet --out "$run_dir"
expect_refusal "at most 86400 s" run spatula-sphere --lockstep --duration 1e9 --quiet --out "$run_dir"
sed 's/^time_step_s = 0.001 /time_step_s = 0.1   /' scenes/spatula-sphere.toml >"$work/coarse.toml"
expect_refusal "field 'simulation.time_step_s': must be in [1e-06, 0.005] (got 0.1)" run "$work/coarse.toml" --lockstep --quiet --out "$run_dir"
after=$(cd "$run_dir" && md5sum trace.csv summary.json)
[[ $before == "$after" ]] || bad "a refused run changed the earlier outputs:"$'\n'"$before"$'\n'"$after"
[[ -z $(ls -A "$run_dir" | grep -v -x -e trace.csv -e summary.json) ]] || bad "temporaries left in $run_dir: $(ls -A "$run_dir")"

echo "earlier csv" >"$work/sim.csv"
expect_refusal "field 'simulation.time_step_s': must be in [1e-06, 0.005] (got 0.1)" sim "$work/coarse.toml" --settle-seconds 1 --csv "$work/sim.csv"
[[ $(cat "$work/sim.csv") == "earlier csv" ]] || bad "a refused fissure sim overwrote its --csv file"
expect_refusal "at most 86400 s" sim spatula-sphere --seconds 1e9
# --contact-response overrides the scene's response (and says so in the JSON), but not into
# dropping a tool friction the scene asks for, which only in_solver solves.
"$fissure" sim spatula-sphere --contact-response in_solver --seconds 0.02 --settle-seconds 0 --json "$work/sim.json" >/dev/null 2>&1 ||
  bad "fissure sim --contact-response in_solver failed"
grep -q '"contact_response": "in_solver"' "$work/sim.json" || bad "fissure sim --contact-response in_solver: the JSON does not say in_solver"
expect_refusal "which only the in_solver response solves" sim convex-spatula-sphere --contact-response after_step --seconds 0.02
expect_refusal "--contact-response: inside not in {after_step,in_solver}" sim spatula-sphere --contact-response inside

expect_refusal "known scenes: clamp-sphere, clamp-vessel, clamp-vessel-lift, clamp-vessel-retract, convex-spatula-sphere, spatula-ball-drag, spatula-blob, spatula-fem-lobe, spatula-fissure, spatula-sphere" run no-such-scene --lockstep
expect_refusal "looked for $PWD/scenes/no-such-scene.toml" run no-such-scene --lockstep
expect_refusal "is a directory, not a scene file" run "$work" --lockstep

# Record and replay through the command line: the replayed lockstep trace is the recorded one.
"$fissure" run spatula-sphere --lockstep --duration 0.4 --settle 0.2 --no-plot --quiet --out "$work/rec" \
  --record "$work/session.frec" >/dev/null 2>&1 || bad "the recording run failed"
replay_out=$("$fissure" run spatula-sphere --lockstep --settle 0.2 --no-plot --quiet --out "$work/rep" \
  --replay "$work/session.frec" 2>&1) || bad "the replay run failed: $replay_out"
grep -q "0 commands differing from the recorded ones" <<<"$replay_out" || bad "replay summary line: $replay_out"
cmp -s "$work/rec/trace.csv" "$work/rep/trace.csv" || bad "the replayed trace differs from the recorded one"
# The lab's workflow: a session recorded in real time (as the USB Falcon is) replays in lockstep
# the same on every run, whatever the recording run's timing was.
"$fissure" run spatula-sphere --duration 0.4 --settle 0.2 --no-plot --quiet --out "$work/rt-rec" \
  --record "$work/realtime.frec" >/dev/null 2>&1 || bad "the real-time recording run failed"
for i in 1 2; do
  "$fissure" run spatula-sphere --lockstep --settle 0.2 --no-plot --quiet --out "$work/rt-rep$i" \
    --replay "$work/realtime.frec" >/dev/null 2>&1 || bad "lockstep replay $i of the real-time recording failed"
done
cmp -s "$work/rt-rep1/trace.csv" "$work/rt-rep2/trace.csv" || bad "two lockstep replays of a real-time recording differ"
head -c 40 "$work/session.frec" >"$work/cut.frec"
expect_refusal "cut.frec: at byte offset" run spatula-sphere --lockstep --replay "$work/cut.frec" --out "$work/rep"
expect_refusal "it needs --device sim" run spatula-sphere --device usb --replay "$work/session.frec" --out "$work/rep"

[[ $fail -eq 0 ]] && echo "session outputs hold"
exit $fail
