# Shared set-up for tools/demo and tools/test (sourced, not run): install the
# Debian packages pyrolume needs when any is missing, then configure and build.
set -euo pipefail

PYROLUME_ROOT="$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)"
PYROLUME_BUILD="${PYROLUME_BUILD:-$PYROLUME_ROOT/build}"

# Build tools (clang + compiler-rt: the sanitizer and libFuzzer build; lld: links
# in a third of GNU ld's time), Vulkan (loader, headers, lavapipe, validation layers, glslang;
# spirv-tools: its optimizer library specialises shaders before pipeline creation),
# and the libraries the host uses.
PYROLUME_PACKAGES=(
  build-essential cmake ninja-build pkg-config lld
  libvulkan-dev mesa-vulkan-drivers vulkan-tools vulkan-validationlayers glslang-tools spirv-tools
  libopenvdb-dev libboost-iostreams-dev libnanovdb-dev libtbb-dev
  libglfw3-dev xvfb xauth python3 python3-matplotlib libtinyobjloader-dev
  libopenexr-dev libglm-dev nlohmann-json3-dev libcli11-dev libstb-dev libgtest-dev
  clang libclang-rt-14-dev
)

pyrolume_install_packages() {
  local missing=()
  for p in "${PYROLUME_PACKAGES[@]}"; do
    if ! dpkg-query -W -f='${Status}' "$p" 2>/dev/null | grep -q "install ok installed"; then
      missing+=("$p")
    fi
  done
  [ ${#missing[@]} -eq 0 ] && return 0
  echo "pyrolume: installing missing Debian packages: ${missing[*]}" >&2
  local sudo=""
  if [ "$(id -u)" -ne 0 ]; then
    if command -v sudo >/dev/null 2>&1; then sudo="sudo"; else
      echo "pyrolume: need root to install: apt-get install ${missing[*]}" >&2; exit 1
    fi
  fi
  $sudo env DEBIAN_FRONTEND=noninteractive apt-get update -q >&2
  $sudo env DEBIAN_FRONTEND=noninteractive apt-get install -y -q --no-install-recommends "${missing[@]}" >&2
}

# pyrolume_build [TARGET...]: configure and build build/ (gcc, Release):
# everything, or only the targets named.
pyrolume_build() {
  local jobs targets=()
  jobs="$(nproc 2>/dev/null || echo 2)"
  [ $# -gt 0 ] && targets=(--target "$@")
  cmake -S "$PYROLUME_ROOT" -B "$PYROLUME_BUILD" -G Ninja -DCMAKE_BUILD_TYPE=Release >&2
  cmake --build "$PYROLUME_BUILD" -j "$jobs" "${targets[@]}" >&2
}

# The clang ASan+UBSan+libFuzzer build (tools/sanitize, tools/fuzz; one build
# dir serves both): pyrolume_core, the CLI and tests/fuzz. The unit tests are
# linked from the test files the gcc build compiled (they are not
# instrumented either way), so that build makes those first.
# -O2 keeps the Monte Carlo unit tests quick; no NDEBUG, so asserts are on.
# No debug info by default: line tables cost about a sixth of the build
# (the OpenVDB batch 156 s with -g1, 129 s without); reports still name each
# frame's function. PYROLUME_SANITIZE_G=-g1 puts file:line back.
PYROLUME_FUZZ_BUILD="${PYROLUME_FUZZ_BUILD:-$PYROLUME_ROOT/build-fuzz}"
pyrolume_build_fuzz() {
  local jobs
  jobs="$(nproc 2>/dev/null || echo 2)"
  pyrolume_build pyrolume_test_support unit_test_cases
  cmake -S "$PYROLUME_ROOT" -B "$PYROLUME_FUZZ_BUILD" -G Ninja -DCMAKE_CXX_COMPILER=clang++ \
    -DCMAKE_BUILD_TYPE=RelWithDebInfo -DCMAKE_CXX_FLAGS_RELWITHDEBINFO="-O2 ${PYROLUME_SANITIZE_G:--g0}" \
    -DPYROLUME_FUZZ=ON -DPYROLUME_TEST_OBJECTS_FROM="$PYROLUME_BUILD" >&2
  cmake --build "$PYROLUME_FUZZ_BUILD" -j "$jobs" >&2
}
