#!/usr/bin/env bash
# Reports what this box is missing to run Fissure's rt loop with hard real-time guarantees
# (see toolchain/RT_HOST.md for why each item matters and how to fix it).
# Exit status: 0 if every REQUIRED item is fine, 1 otherwise. WARN items only cost latency.
set -u
required_missing=0
row() {  # level name detail
  printf '%-5s %-34s %s\n' "$1" "$2" "$3"
  [[ $1 == FAIL ]] && required_missing=1
  return 0
}

# Kernel: PREEMPT_RT gives bounded wake-up latency (tens of µs); PREEMPT_DYNAMIC/voluntary do not.
kver=$(uname -v)
if [[ -r /sys/kernel/realtime && $(cat /sys/kernel/realtime) == 1 ]] || grep -q 'PREEMPT_RT' <<<"$kver"; then
  row OK "kernel PREEMPT_RT" "$(uname -r)"
else
  row WARN "kernel PREEMPT_RT" "not an RT kernel ($(uname -r): ${kver%% *}…); expect ms-scale worst cases — install linux-image-rt-*"
fi

# Scheduling rights: SCHED_FIFO at the loop's default priority 80, and unlimited memlock for mlockall.
rtprio=$(ulimit -r)
if [[ $(id -u) -eq 0 || $rtprio == unlimited || $rtprio -ge 80 ]]; then
  row OK "rtprio limit" "$( [[ $(id -u) -eq 0 ]] && echo root || echo "ulimit -r = $rtprio")"
else
  row FAIL "rtprio limit" "ulimit -r = $rtprio < 80: add '@realtime - rtprio 95' to /etc/security/limits.d/ and join group realtime"
fi
if command -v chrt >/dev/null && chrt -f 80 true 2>/dev/null; then
  row OK "SCHED_FIFO 80" "chrt -f 80 works"
else
  row FAIL "SCHED_FIFO 80" "chrt -f 80 fails (no rights, or RT throttling/cgroup forbids RT tasks)"
fi
memlock=$(ulimit -l)
if [[ $(id -u) -eq 0 || $memlock == unlimited ]]; then
  row OK "memlock limit" "$( [[ $(id -u) -eq 0 ]] && echo root || echo unlimited)"
else
  row FAIL "memlock limit" "ulimit -l = $memlock KiB: mlockall will fail; add '@realtime - memlock unlimited'"
fi
if [[ -r /proc/sys/kernel/sched_rt_runtime_us ]]; then
  rt_runtime=$(cat /proc/sys/kernel/sched_rt_runtime_us)
  [[ $rt_runtime == -1 ]] && row OK "RT throttling" "disabled" ||
    row WARN "RT throttling" "sched_rt_runtime_us=$rt_runtime: RT tasks are paused 5% of each second if they spin"
fi

# CPU isolation: keep the rt loop's core free of other work and of timer/RCU noise.
isolated=$(cat /sys/devices/system/cpu/isolated 2>/dev/null)
cmdline=$(cat /proc/cmdline 2>/dev/null)
if [[ -n $isolated ]]; then
  row OK "isolated CPUs" "$isolated ($(grep -oE '(nohz_full|rcu_nocbs)=[^ ]+' <<<"$cmdline" | tr '\n' ' '))"
else
  row WARN "isolated CPUs" "none: add isolcpus=N nohz_full=N rcu_nocbs=N to the kernel command line, run with --cpu N"
fi
if [[ -w /dev/cpu_dma_latency ]]; then
  row OK "/dev/cpu_dma_latency" "writable (the loop holds it at 0 to keep CPUs out of deep C-states)"
else
  row WARN "/dev/cpu_dma_latency" "not writable: deep C-state exits add wake-up latency"
fi
gov=$(cat /sys/devices/system/cpu/cpu0/cpufreq/scaling_governor 2>/dev/null || echo none)
[[ $gov == performance || $gov == none ]] && row OK "cpufreq governor" "$gov" ||
  row WARN "cpufreq governor" "$gov: use 'performance' (frequency ramps add latency)"

# Tools and the device.
command -v cyclictest >/dev/null && row OK "cyclictest" "$(command -v cyclictest)" ||
  row WARN "cyclictest" "missing (Debian rt-tests): fissure bench rt cannot compare against it"
if ls /etc/udev/rules.d/*falcon* >/dev/null 2>&1 || ls /lib/udev/rules.d/*falcon* >/dev/null 2>&1; then
  row OK "Falcon udev rule" "installed"
else
  row WARN "Falcon udev rule" "missing: sudo cp toolchain/udev/99-novint-falcon.rules /etc/udev/rules.d/"
fi
falcon=""
for d in /sys/bus/usb/devices/*; do
  [[ -r $d/idVendor && $(cat "$d/idVendor") == 0403 && $(cat "$d/idProduct" 2>/dev/null) == cb48 ]] && falcon=$d
done
[[ -n $falcon ]] && row OK "Novint Falcon" "attached at ${falcon##*/}" ||
  row WARN "Novint Falcon" "not attached (fine for simulated-device sessions)"

echo
if ((required_missing)); then
  echo "This box is missing REQUIRED real-time rights (FAIL above): 'fissure rt --rt-policy enforce' will refuse to run."
  exit 1
fi
echo "Required real-time rights are present; WARN items cost latency, see toolchain/RT_HOST.md."
