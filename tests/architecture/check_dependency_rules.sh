#!/usr/bin/env bash
# Fails (naming file and line) when a module includes something its rules forbid:
#   shared/                               : standard library, Eigen, shared/ itself
#   falcon_hw/, rt_core/, config/, rt_box/: no Bullet, no host_sim (they cross-compile for the RT box)
#   session/, eval/                       : never the command-line program (app/)
#   session/'s Bullet-free core           : the files fissure_session_core compiles, no Bullet/host_sim
set -u
root=${1:?usage: check_dependency_rules.sh <source root>}
status=0
bullet='#include *[<"](bullet/|btBullet|BulletSoftBody|BulletCollision|BulletDynamics|LinearMath|Bullet3)|#include *[<"]fissure/host_sim/'
for module in shared falcon_hw rt_core config rt_box; do
  if hits=$(grep -rnE "$bullet" "$root/$module" 2>/dev/null); then
    echo "dependency rule broken: $module/ must not include Bullet or host_sim:"; echo "$hits"; status=1
  fi
done
# shared/: every non-standard include must be Eigen, a POSIX/Linux system header (the UDP and
# SocketCAN carriers), or shared's own header.
posix='#include *<(sys|net|netinet|arpa|linux|linux/can)/[a-z_]+\.h>|#include *<(unistd|fcntl|netdb|poll)\.h>'
if hits=$(grep -rnE '#include *[<"]' "$root/shared" | grep -vE "#include *<[a-z_]+>|#include *<Eigen/|#include *\"fissure/shared/|$posix"); then
  echo "dependency rule broken: shared/ may include only the standard library, Eigen, POSIX/Linux system headers and itself:"; echo "$hits"; status=1
fi
# rt_core/: nothing of the app layer (logging, CLI, JSON) in the RT library.
if hits=$(grep -rnE '#include *[<"](spdlog|CLI/|nlohmann|toml)' "$root/rt_core" 2>/dev/null); then
  echo "dependency rule broken: rt_core/ must not include app-layer libraries:"; echo "$hits"; status=1
fi
# session/ and eval/ are libraries the commands use: nothing of app/ (its headers are plain
# "name.hpp" includes of files that live in app/).
for module in session eval; do
  [[ -d $root/$module ]] || continue
  for header in "$root"/app/*.hpp; do
    name=$(basename "$header")
    if hits=$(grep -rnE "#include *\"$name\"" "$root/$module" 2>/dev/null); then
      echo "dependency rule broken: $module/ must not include the app's $name:"; echo "$hits"; status=1
    fi
  done
done
# session/'s core (fissure_session_core in session/CMakeLists.txt) runs on the RT box: no Bullet.
core_sources=$(awk '/add_library\(fissure_session_core/,/\)/' "$root/session/CMakeLists.txt" | grep -oE 'src/[a-z_]+\.cpp')
for source in $core_sources; do
  files="$root/session/$source"
  header="$root/session/include/fissure/session/$(basename "${source%.cpp}").hpp"
  [[ -f $header ]] && files="$files $header"
  # shellcheck disable=SC2086
  if hits=$(grep -nE "$bullet|#include *[<\"]fissure/(viewer|host_sim)/" $files); then
    echo "dependency rule broken: session/$source is in the Bullet-free fissure_session_core:"; echo "$hits"; status=1
  fi
done
[[ $status -eq 0 ]] && echo "dependency rules hold for shared/, falcon_hw/, rt_core/, config/, rt_box/, session/, eval/"
exit $status
