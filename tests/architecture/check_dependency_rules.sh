#!/usr/bin/env bash
# Fails (naming file and line) when a module includes something its rules forbid:
#   shared/             : standard library, Eigen, shared/ itself
#   falcon_hw/, rt_core/: no Bullet, no host_sim (rt_core must cross-compile for an RT box)
set -u
root=${1:?usage: check_dependency_rules.sh <source root>}
status=0
bullet='#include *[<"](bullet/|btBullet|BulletSoftBody|BulletCollision|BulletDynamics|LinearMath|Bullet3)|#include *[<"]fissure/host_sim/'
for module in shared falcon_hw rt_core; do
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
[[ $status -eq 0 ]] && echo "dependency rules hold for shared/, falcon_hw/, rt_core/"
exit $status
