#!/usr/bin/env bash
# Sets up a fresh Debian bookworm machine for rtsim and builds it:
#   system packages (compiler, CMake, Ninja, SystemC, GLM, tinygltf, Embree, ...),
#   then `pip install .` (the C++ libraries, the C++ tests and the Python package with rtsim._core).
# Idempotent: re-running skips installed packages and rebuilds incrementally in build/py.
# Env: PYTHON (default: python), CMAKE_BUILD_PARALLEL_LEVEL (default: number of cores),
#      RTSIM_LTO (default ON: link-time optimisation of the Release build; CI sets OFF, whose
#      links take minutes on two cores, and tests the same code without it),
#      RTSIM_UNITY (default ON: unity batches, about half the compile time of a fresh build;
#      OFF for a tree you rebuild file by file, docs/dependencies.md "Build time").
set -euo pipefail
cd "$(dirname "${BASH_SOURCE[0]}")/.."

PYTHON="${PYTHON:-python}"
export PIP_ROOT_USER_ACTION=ignore PIP_DISABLE_PIP_VERSION_CHECK=1
SUDO=""
if [ "$(id -u)" -ne 0 ]; then
  SUDO="sudo"
fi

APT_PACKAGES=(
  cmake ninja-build g++ pkg-config
  libsystemc-dev libglm-dev libtinygltf-dev libembree-dev nlohmann-json3-dev libstb-dev
  libgtest-dev googletest zlib1g-dev libcli11-dev
  chromium  # headless, in the tests only: checks that sweep reports render
)

missing=()
for pkg in "${APT_PACKAGES[@]}"; do
  if ! dpkg-query -W -f='${Status}' "$pkg" 2>/dev/null | grep -q "install ok installed"; then
    missing+=("$pkg")
  fi
done
if [ "${#missing[@]}" -gt 0 ]; then
  echo "setup: installing ${missing[*]}"
  $SUDO apt-get update -qq
  DEBIAN_FRONTEND=noninteractive $SUDO apt-get install -y -qq --no-install-recommends \
    "${missing[@]}" >/dev/null
else
  echo "setup: system packages already installed"
fi

# Build tools first, then the package without build isolation: the persistent build tree
# (build/py) keeps the paths of these tools, so rebuilds are incremental and reliable.
echo "setup: installing Python build and test tools"
"$PYTHON" -m pip install -q \
  "scikit-build-core>=0.10" "pybind11>=2.12" pytest pytest-xdist hypothesis ruff

export CMAKE_BUILD_PARALLEL_LEVEL="${CMAKE_BUILD_PARALLEL_LEVEL:-$(nproc)}"
echo "setup: building and installing rtsim (C++ and Python; -j${CMAKE_BUILD_PARALLEL_LEVEL})"
build_args=(-C "cmake.define.CMAKE_UNITY_BUILD=${RTSIM_UNITY:-ON}")
if [ "${RTSIM_LTO:-ON}" = "OFF" ]; then
  build_args+=(-C cmake.define.CMAKE_INTERPROCEDURAL_OPTIMIZATION=OFF)
fi
"$PYTHON" -m pip install -q --no-build-isolation "${build_args[@]}" ".[test]"

# pyenv only creates the `rtsim` shim on a rehash (`python -m pip` does not trigger one).
if command -v pyenv >/dev/null 2>&1; then
  pyenv rehash || true
fi
if ! command -v rtsim >/dev/null 2>&1; then
  echo "setup: note: 'rtsim' is not on PATH; use '$PYTHON -m rtsim' or add pip's script folder" >&2
fi
echo "setup: done. Try: rtsim demo   (tests: bash scripts/test.sh)"
