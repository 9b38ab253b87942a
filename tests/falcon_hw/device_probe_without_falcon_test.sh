#!/usr/bin/env bash
# `fissure device probe` with no Falcon attached: exactly one line naming the USB id and
# the udev rule, exit code ≠ 0. Skipped (exit 77) when a Falcon is attached.
set -u
fissure=${1:?usage: device_probe_without_falcon_test.sh <path to fissure>}
fail() { echo "FAIL: $*"; exit 1; }

for dev in /sys/bus/usb/devices/*; do
  if [[ -r $dev/idVendor && $(cat "$dev/idVendor") == 0403 && $(cat "$dev/idProduct" 2>/dev/null) == cb48 ]]; then
    echo "SKIP: a Novint Falcon is attached ($dev)"; exit 77
  fi
done

for cmd in "device probe" "device home"; do
  out=$("$fissure" $cmd 2>&1); rc=$?
  [[ $rc -ne 0 ]] || fail "'fissure $cmd' exited 0 without a Falcon: $out"
  [[ $(wc -l <<<"$out") -eq 1 ]] || fail "'fissure $cmd' printed more than one line:"$'\n'"$out"
  grep -q 'no Novint Falcon found (USB 0403:cb48)' <<<"$out" || fail "'fissure $cmd' does not name the device: $out"
  grep -q 'toolchain/udev/99-novint-falcon.rules' <<<"$out" || fail "'fissure $cmd' does not point at the udev rule: $out"
done
echo "device probe without a Falcon: one line, exit ≠ 0"
