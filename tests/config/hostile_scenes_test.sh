#!/usr/bin/env bash
# One hostile scene file (tests/config/hostile_scenes/NAME.toml) through `fissure run --lockstep`:
# it must be refused with exit 1 or 2 (never a signal, never 0), in exactly one line
# "fissure: error: …" containing the file's "# expect:" text, and must write nothing.
set -u
fissure=${1:?usage: hostile_scenes_test.sh <path to fissure> <scene file>}
scene=${2:?usage: hostile_scenes_test.sh <path to fissure> <scene file>}
fail() { echo "FAIL ($(basename "$scene")): $*"; exit 1; }

expect=$(sed -n 's/^# expect: //p' "$scene" | head -1)
[[ -n $expect ]] || fail "no '# expect:' line"
work=$(mktemp -d)
trap 'rm -rf "$work"' EXIT
out=$("$fissure" run "$scene" --lockstep --settle 1 --duration 0.05 --no-plot --quiet --out "$work/out" 2>&1 >/dev/null); rc=$?
[[ $rc -eq 1 || $rc -eq 2 ]] || fail "exit $rc, want 1 or 2 (output: $out)"
[[ $(wc -l <<<"$out") -eq 1 ]] || fail "more than one line:"$'\n'"$out"
[[ $out == "fissure: error: "* ]] || fail "does not start with 'fissure: error: ': $out"
grep -qF -- "$expect" <<<"$out" || fail "expected text not found"$'\n'"  want: $expect"$'\n'"  got:  $out"
[[ ! -e $work/out ]] || fail "a refused run wrote into its output directory: $(ls -A "$work/out")"
echo "refused as expected: $out"
