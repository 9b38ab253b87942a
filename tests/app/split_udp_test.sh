#!/usr/bin/env bash
# Split deployment over real UDP on loopback, two processes (issue 6):
#   fissure rt   --transport udp:127.0.0.1:PORT --scene spatula-sphere   (background)
#   fissure host spatula-sphere --transport udp:127.0.0.1:PORT --seconds 2
# Checks: the host exits 0 having established the link and stepped; the rt end notices the
# host's exit (host silent → fade) and, on SIGINT (Ctrl-C), ramps out and exits 0.
# Bounded: every wait has a timeout; loopback only.
set -u
fissure="$1"
port=$((40000 + $$ % 20000))
spec="udp:127.0.0.1:${port}"
log_dir=$(mktemp -d)
trap 'rm -rf "$log_dir"; [ -n "${rt_pid:-}" ] && kill -KILL "$rt_pid" 2>/dev/null' EXIT

"$fissure" rt --transport "$spec" --scene spatula-sphere --seconds 60 >"$log_dir/rt.out" 2>"$log_dir/rt.err" &
rt_pid=$!
timeout 40 "$fissure" host spatula-sphere --transport "$spec" --seconds 2 --settle 0.2 --connect-timeout 20 \
  >"$log_dir/host.out" 2>"$log_dir/host.err"
host_rc=$?
# Give rt_core time to see the host go silent (100 ms bound) and fade (50 ms).
sleep 1
kill -INT "$rt_pid"
for _ in $(seq 1 100); do kill -0 "$rt_pid" 2>/dev/null || break; sleep 0.1; done
if kill -0 "$rt_pid" 2>/dev/null; then
  echo "FAIL: fissure rt did not exit within 10 s of SIGINT"; cat "$log_dir"/rt.*; exit 1
fi
wait "$rt_pid"
rt_rc=$?
rt_pid=
fail=0
show() { echo "--- host stdout"; cat "$log_dir/host.out"; echo "--- host stderr"; tail -20 "$log_dir/host.err";
         echo "--- rt stdout"; cat "$log_dir/rt.out"; echo "--- rt stderr"; tail -20 "$log_dir/rt.err"; }
[ "$host_rc" -eq 0 ] || { echo "FAIL: fissure host exited $host_rc"; fail=1; }
[ "$rt_rc" -eq 0 ] || { echo "FAIL: fissure rt exited $rt_rc"; fail=1; }
grep -q "link established" "$log_dir/host.out" || { echo "FAIL: host did not report the link established"; fail=1; }
grep -Eq "steps [1-9][0-9]*" "$log_dir/host.out" || { echo "FAIL: host never stepped"; fail=1; }
grep -q "link established" "$log_dir/rt.out" || { echo "FAIL: rt did not report the link established"; fail=1; }
cat "$log_dir/rt.out" "$log_dir/rt.err" | grep -q "host silent" || { echo "FAIL: rt did not notice the host's exit"; fail=1; }
grep -q "stopped by Ctrl-C" "$log_dir/rt.out" || { echo "FAIL: rt did not report the Ctrl-C stop"; fail=1; }
show
exit $fail
