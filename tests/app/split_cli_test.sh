#!/usr/bin/env bash
# CLI contract of the split-deployment commands (issue 6): transport errors are one line with
# the right exit code, and `fissure hil latency` writes every distribution for inproc and for
# UDP on loopback (a 1 s smoke run: checks structure and counts, never machine-speed figures).
set -u
fissure="$1"
out=$(mktemp -d)
trap 'rm -rf "$out"' EXIT
fail=0
expect() {  # expect <exit code> <pattern in stderr> <args…>
  local code="$1" pattern="$2"; shift 2
  "$fissure" "$@" >"$out/stdout" 2>"$out/stderr"
  local rc=$?
  if [ "$rc" -ne "$code" ]; then echo "FAIL: fissure $* exited $rc, expected $code"; cat "$out/stderr"; fail=1; return; fi
  if ! grep -q -- "$pattern" "$out/stderr"; then echo "FAIL: fissure $*: stderr lacks '$pattern'"; cat "$out/stderr"; fail=1; return; fi
  local lines; lines=$(grep -c "error" "$out/stderr")
  if [ "$lines" -ne 1 ]; then echo "FAIL: fissure $*: $lines error lines, expected one"; cat "$out/stderr"; fail=1; fi
}
expect 2 "needs can:IFACE or udp:HOST:PORT" rt --transport inproc
expect 2 "transport" rt --transport bogus:1
expect 2 "needs can:IFACE or udp:HOST:PORT" host spatula-sphere --transport inproc --settle 0
if ! grep -qs can /proc/net/protocols; then
  # This kernel has no AF_CAN: `can:` must fail at once with one clear line (BRIEF §8).
  expect 1 "AF_CAN" rt --transport can:vcan0
  expect 1 "AF_CAN" hil latency --transport can:vcan0 --seconds 1 --json "$out/can.json"
fi
port=$((40000 + ($$ + 7) % 20000))
# An rt end no host ever answered did nothing: it says so and fails (issue 25).
expect 1 "link never established" rt --transport "udp:127.0.0.1:$((port + 1))" --seconds 0.3 --quiet
for transport in inproc "udp:127.0.0.1:${port}"; do
  json="$out/hil.json"
  if ! timeout 60 "$fissure" hil latency --transport "$transport" --seconds 1 --settle 0.2 --json "$json" >"$out/stdout" 2>&1; then
    echo "FAIL: hil latency --transport $transport"; cat "$out/stdout"; fail=1; continue
  fi
  python3 - "$json" "$transport" <<'PY' || fail=1
import json, sys
d = json.load(open(sys.argv[1]))
ok = True
for key in ("device_round_trip_us", "rt_tick_us", "host_step_us", "proxy_age_ms", "end_to_end_ms"):
    dist = d[key]
    if not (dist["count"] > 0 and 0 <= dist["median"] <= dist["p99"] <= dist["max"]):
        print(f"FAIL: {sys.argv[2]}: {key} = {dist}"); ok = False
if d["ticks"] < 100 or d["host_steps"] < 10 or d["transport"] != sys.argv[2]:
    print(f"FAIL: {sys.argv[2]}: ticks {d['ticks']} host_steps {d['host_steps']}"); ok = False
for key in ("nproc", "cpu_model", "kernel"):
    if key not in d["machine"]:
        print(f"FAIL: machine.{key} missing"); ok = False
# End to end is at least one rt tick: a proxy is built after the sample it answers.
if d["end_to_end_ms"]["median"] <= 0:
    print("FAIL: end-to-end latency not positive"); ok = False
sys.exit(0 if ok else 1)
PY
done
exit $fail
