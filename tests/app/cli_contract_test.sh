#!/usr/bin/env bash
# fissure's CLI contract (issue: foundation): --help lists the subcommands and exits 0;
# an unknown subcommand or a bad option prints exactly one line and exits 2.
set -u
fissure=${1:?usage: cli_contract_test.sh <path to fissure>}
fail() { echo "FAIL: $*"; exit 1; }

help=$("$fissure" --help) || fail "--help exited $?"
for sub in bench device; do
  grep -qE "^ +$sub( |$)" <<<"$help" || fail "--help does not list '$sub':"$'\n'"$help"
done

expect_usage_error() {
  local out rc
  out=$("$fissure" "$@" 2>&1); rc=$?
  [[ $rc -eq 2 ]] || fail "'fissure $*' exited $rc, want 2 (output: $out)"
  [[ $(wc -l <<<"$out") -eq 1 ]] || fail "'fissure $*' printed more than one line:"$'\n'"$out"
  grep -q '^fissure: error: ' <<<"$out" || fail "'fissure $*' error does not start with 'fissure: error:': $out"
}
expect_usage_error no-such-subcommand
expect_usage_error --no-such-option
expect_usage_error
expect_usage_error bench no-such-benchmark
# A value outside an option's choices is refused before anything runs, naming the choices.
expect_usage_error bench collision --json /dev/null --contact-response sideways
expect_usage_error bench collision --json /dev/null --in-solver-friction maybe
out=$("$fissure" bench collision --json /dev/null --in-solver-friction maybe 2>&1)
grep -q '{on,off}' <<<"$out" || fail "the refusal of --in-solver-friction does not name its choices: $out"
echo "cli contract holds"
