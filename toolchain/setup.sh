#!/usr/bin/env bash
# Installs the Debian packages Fissure needs, and nothing when they are all present.
# Idempotent: `apt-get update` runs only when something is missing.
#
#   toolchain/setup.sh            build + run + test dependencies
#   toolchain/setup.sh --ci       also the CI extras (aarch64 cross compiler, qemu-user)
set -euo pipefail

packages=(
  # build
  cmake g++ ninja-build pkg-config
  # libraries (BRIEF §2: shared/ uses only Eigen; host_sim adds Bullet; tools add the rest)
  libeigen3-dev libbullet-dev libgtest-dev libgmock-dev libbenchmark-dev
  libfcl-dev  # tests/host_sim only: the independent triangle–convex oracle of the contact metrics (fcl_oracle.hpp)
  libusb-1.0-0-dev libcli11-dev libtomlplusplus-dev nlohmann-json3-dev libspdlog-dev
  libtinyobjloader-dev
  tetgen  # tests/host_sim: a real TetGen run of a closed STL into a volumetric body (skipped, saying so, without it)
  libegl-dev libopengl-dev libgl-dev libegl-mesa0 libgl1-mesa-dri libglfw3-dev libpng-dev  # viewer/: headless EGL (llvmpipe), GL 3.3, GLFW window, PNG
  # session plot (Debian's interpreter, not whatever python3 is first on PATH)
  python3 python3-matplotlib
  # the fissure Python module (python/) and its tests: pybind11 against Debian's python3, NumPy, pytest
  python3-dev pybind11-dev python3-numpy python3-pytest
  # cyclictest, the OS-latency reference of `fissure bench rt`
  rt-tests
)
if [[ "${1:-}" == "--ci" ]]; then
  packages+=(g++-aarch64-linux-gnu qemu-user clang libclang-rt-14-dev)
fi

missing=()
for p in "${packages[@]}"; do
  status=$(dpkg-query -W -f='${Status}' "$p" 2>/dev/null || true)
  [[ "$status" == "install ok installed" ]] || missing+=("$p")
done

if ((${#missing[@]} == 0)); then
  echo "toolchain/setup.sh: all ${#packages[@]} packages present"
  exit 0
fi

sudo=""
if [[ $(id -u) -ne 0 ]]; then
  command -v sudo >/dev/null || { echo "toolchain/setup.sh: need root or sudo to install: ${missing[*]}" >&2; exit 1; }
  sudo="sudo"
fi
echo "toolchain/setup.sh: installing ${missing[*]}"
export DEBIAN_FRONTEND=noninteractive
$sudo apt-get update -qq
$sudo apt-get install -y -qq --no-install-recommends "${missing[@]}" >/dev/null
echo "toolchain/setup.sh: done"
