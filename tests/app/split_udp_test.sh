#!/usr/bin/env bash
# Split deployment over real UDP on loopback, two processes (issue 6):
#   fissure rt   --transport udp:127.0.0.1:PORT --scene spatula-sphere   (background)
#   fissure host spatula-sphere --transport udp:127.0.0.1:PORT --seconds 2
# Checks: the host exits 0 having established the link and stepped; the rt end reports the
# host's clean exit as "closed cleanly by the host" (not "host silent") and, on SIGINT (Ctrl-C),
# ramps out and exits 0. Then (issue 25) a host killed with SIGKILL: the rt end reports the host
# silent and exits 1 "link lost"; an rt end killed with SIGKILL: the host says when the link was
# lost and exits 1; and an rt on clamp-vessel with a host on spatula-sphere: both refuse the link
# naming both scenes, exit 1.
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
grep -q "closed cleanly by the host" "$log_dir/rt.out" || { echo "FAIL: rt did not report the host's clean exit"; fail=1; }
grep -q "host silent" "$log_dir/rt.err" && { echo "FAIL: a clean host exit was reported as 'host silent'"; fail=1; }
grep -q "stopped by Ctrl-C" "$log_dir/rt.out" || { echo "FAIL: rt did not report the Ctrl-C stop"; fail=1; }
show

# A host that dies: silent without a goodbye.
port2=$((port + 1)); spec2="udp:127.0.0.1:${port2}"
"$fissure" rt --transport "$spec2" --scene spatula-sphere --seconds 60 --quiet >"$log_dir/rt2.out" 2>"$log_dir/rt2.err" &
rt_pid=$!
"$fissure" host spatula-sphere --transport "$spec2" --seconds 60 --settle 0.2 --connect-timeout 20 --quiet \
  >"$log_dir/host2.out" 2>"$log_dir/host2.err" &
host_pid=$!
for _ in $(seq 1 300); do grep -q "link established" "$log_dir/rt2.err" && break; sleep 0.1; done
sleep 0.5
kill -KILL "$host_pid"; wait "$host_pid" 2>/dev/null
sleep 1
kill -INT "$rt_pid"
for _ in $(seq 1 100); do kill -0 "$rt_pid" 2>/dev/null || break; sleep 0.1; done
wait "$rt_pid"; rt2_rc=$?; rt_pid=
[ "$rt2_rc" -eq 1 ] || { echo "FAIL: after the host was killed fissure rt exited $rt2_rc, want 1"; fail=1; }
grep -q "host silent" "$log_dir/rt2.err" || { echo "FAIL: rt did not report the killed host silent"; fail=1; }
grep -q "link lost: the host went silent" "$log_dir/rt2.err" || { echo "FAIL: rt did not say the link was lost"; fail=1; }
echo "--- killed host: rt stdout"; cat "$log_dir/rt2.out"; echo "--- rt stderr"; tail -5 "$log_dir/rt2.err"

# An rt end that dies: the host says when the link was lost and exits 1.
port4=$((port + 3)); spec4="udp:127.0.0.1:${port4}"
"$fissure" host spatula-sphere --transport "$spec4" --seconds 60 --settle 0.2 --connect-timeout 20 --quiet \
  >"$log_dir/host4.out" 2>"$log_dir/host4.err" &
host_pid=$!
"$fissure" rt --transport "$spec4" --scene spatula-sphere --seconds 60 --quiet >"$log_dir/rt4.out" 2>"$log_dir/rt4.err" &
rt_pid=$!
for _ in $(seq 1 300); do grep -q "link established" "$log_dir/host4.err" && break; sleep 0.1; done
sleep 0.5
kill -KILL "$rt_pid"; wait "$rt_pid" 2>/dev/null; rt_pid=
sleep 1
kill -INT "$host_pid"
for _ in $(seq 1 100); do kill -0 "$host_pid" 2>/dev/null || break; sleep 0.1; done
wait "$host_pid"; host4_rc=$?
[ "$host4_rc" -eq 1 ] || { echo "FAIL: after rt was killed fissure host exited $host4_rc, want 1"; fail=1; }
grep -Eq "link established, LOST at [0-9]+\.[0-9]+ s" "$log_dir/host4.out" ||
  { echo "FAIL: the host summary does not say when the link was lost"; fail=1; }
grep -Eq "link lost: rt_core at .* went silent at [0-9]+\.[0-9]+ s" "$log_dir/host4.err" ||
  { echo "FAIL: the host did not say the link was lost, and when"; fail=1; }
echo "--- killed rt: host stdout"; cat "$log_dir/host4.out"; echo "--- host stderr"; tail -2 "$log_dir/host4.err"

# Mismatched scenes: refused at both ends, both scenes named.
port3=$((port + 2)); spec3="udp:127.0.0.1:${port3}"
timeout 30 "$fissure" rt --transport "$spec3" --scene clamp-vessel --seconds 20 --quiet >"$log_dir/rt3.out" 2>"$log_dir/rt3.err" &
rt_pid=$!
timeout 30 "$fissure" host spatula-sphere --transport "$spec3" --seconds 20 --settle 0.2 --connect-timeout 20 --quiet \
  >"$log_dir/host3.out" 2>"$log_dir/host3.err"
host3_rc=$?
wait "$rt_pid"; rt3_rc=$?; rt_pid=
[ "$host3_rc" -eq 1 ] || { echo "FAIL: mismatched host exited $host3_rc, want 1"; fail=1; }
[ "$rt3_rc" -eq 1 ] || { echo "FAIL: mismatched rt exited $rt3_rc, want 1"; fail=1; }
grep -q "session mismatch: this host runs scene 'spatula-sphere'.*the rt peer runs scene 'clamp-vessel'" "$log_dir/host3.err" ||
  { echo "FAIL: the host did not name both scenes"; fail=1; }
grep -q "session mismatch: this rt runs scene 'clamp-vessel'.*the host peer runs scene 'spatula-sphere'" "$log_dir/rt3.err" ||
  { echo "FAIL: the rt end did not name both scenes"; fail=1; }
echo "--- mismatch: host stderr"; tail -2 "$log_dir/host3.err"; echo "--- rt stderr"; tail -2 "$log_dir/rt3.err"
exit $fail
