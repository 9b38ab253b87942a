#!/usr/bin/env bash
# A split session with the RT box's program: fissure-rt (natively, or the aarch64 build under
# qemu-aarch64) at one end, the native `fissure host` at the other, over UDP on 127.0.0.1.
#   split_session_test.sh <fissure> <fissure-rt> [emulator and its arguments…]
# Checks: the link comes up on both ends, rt_core applies the host's proxies, no tick has a
# device fault and no proxy is rejected, and both ends exit 0 (the rt end after the host's
# proxies stop and its force fades — stale-proxy ticks from then on are expected).
# Bounded: every wait has a timeout; loopback only.
set -u
fissure="$1"
fissure_rt="$2"
shift 2
emulator=("$@")
if [[ ! -x $fissure ]]; then
  echo "SKIP: no native fissure at $fissure (build the default preset first: it is the host end)"
  exit 77
fi
port=$((40000 + ($$ + 13) % 20000))
spec="udp:127.0.0.1:${port}"
log_dir=$(mktemp -d)
trap 'rm -rf "$log_dir"; [ -n "${rt_pid:-}" ] && kill -KILL "$rt_pid" 2>/dev/null' EXIT

# The rt end runs a fixed time, longer than the host's settle + run, so it sees the host leave.
"${emulator[@]}" "$fissure_rt" --transport "$spec" --scene spatula-sphere --seconds 8 --quiet \
  >"$log_dir/rt.out" 2>"$log_dir/rt.err" &
rt_pid=$!
timeout 60 "$fissure" host spatula-sphere --transport "$spec" --seconds 3 --settle 0.2 --connect-timeout 20 --quiet \
  >"$log_dir/host.out" 2>"$log_dir/host.err"
host_rc=$?
for _ in $(seq 1 300); do kill -0 "$rt_pid" 2>/dev/null || break; sleep 0.1; done
if kill -0 "$rt_pid" 2>/dev/null; then
  echo "FAIL: fissure-rt did not finish within 30 s of the host"; kill -INT "$rt_pid"; sleep 2
fi
wait "$rt_pid"
rt_rc=$?
rt_pid=
fail=0
[ "$host_rc" -eq 0 ] || { echo "FAIL: fissure host exited $host_rc"; fail=1; }
[ "$rt_rc" -eq 0 ] || { echo "FAIL: fissure-rt exited $rt_rc"; fail=1; }
grep -q "link established" "$log_dir/host.out" || { echo "FAIL: the host did not report the link established"; fail=1; }
grep -Eq "steps [1-9][0-9]*" "$log_dir/host.out" || { echo "FAIL: the host never stepped"; fail=1; }
grep -q "link established" "$log_dir/rt.out" || { echo "FAIL: fissure-rt did not report the link established"; fail=1; }
grep -Eq "proxies used [1-9][0-9]*" "$log_dir/rt.out" || { echo "FAIL: fissure-rt applied no proxy"; fail=1; }
grep -q "device fault ticks 0 " "$log_dir/rt.out" || { echo "FAIL: fissure-rt had ticks with device faults"; fail=1; }
grep -q "proxies rejected 0 " "$log_dir/rt.out" || { echo "FAIL: fissure-rt rejected proxies"; fail=1; }
grep -q "closed cleanly by the host" "$log_dir/rt.out" || { echo "FAIL: fissure-rt did not report the host's clean exit"; fail=1; }
echo "--- host stdout"; cat "$log_dir/host.out"; echo "--- host stderr"; tail -5 "$log_dir/host.err"
echo "--- fissure-rt stdout"; cat "$log_dir/rt.out"; echo "--- fissure-rt stderr"; tail -8 "$log_dir/rt.err"
exit $fail
