#!/usr/bin/env bash
# fissure-rt runs on the RT box: neither Bullet nor host_sim (nor the viewer) may reach it.
# Checks the link line the build uses (build.ninja) and the symbols of the linked program.
#   check_rt_box_link.sh <build dir> <fissure-rt> <nm>
set -u
build=${1:?usage: check_rt_box_link.sh <build dir> <fissure-rt> <nm>}
program=${2:?}
nm_tool=${3:-nm}
status=0
forbidden='[Bb]ullet|LinearMath|fissure_host_sim|fissure_viewer|fissure_session\.a|libGL|libEGL|tinyobjloader'
# The link statement of fissure-rt and its variables (LINK_LIBRARIES, LINK_FLAGS) up to the next blank line.
link=$(awk '/^build [^ ]*fissure-rt: /{on=1} on{print} on&&/^$/{exit}' "$build/build.ninja")
if [[ -z $link ]]; then
  echo "no link statement for fissure-rt in $build/build.ninja"; exit 1
fi
if hits=$(grep -oE "$forbidden[^ ]*" <<<"$link"); then
  echo "fissure-rt's link line names what the RT box must not need:"; echo "$hits" | sort -u; status=1
fi
# Bullet's classes all start with bt (btSoftBody, btCollisionWorld, btAlignedAllocInternal …).
if symbols=$("$nm_tool" -C "$program" 2>/dev/null | grep -E ' (btSoftBody|btCollisionWorld|btAlignedAlloc|fissure::host::)' | head -5) && [[ -n $symbols ]]; then
  echo "fissure-rt contains Bullet or host_sim code:"; echo "$symbols"; status=1
fi
[[ $status -eq 0 ]] && echo "fissure-rt: no Bullet, host_sim or viewer in its link line or its symbols"
exit $status
