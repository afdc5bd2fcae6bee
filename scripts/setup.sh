#!/usr/bin/env bash
# Install skinmesh's dependencies from Debian 12 packages and build it in Release.
# Run as root (or with sudo) from anywhere inside the repository:
#     bash scripts/setup.sh            # install + configure + build
#     SKINMESH_SKIP_INSTALL=1 bash scripts/setup.sh   # build only
set -euo pipefail
here=$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)

packages=(
  build-essential cmake pkg-config ccache
  libcgal-dev libgmp-dev libmpfr-dev libboost-dev   # regular triangulation, exact predicates, Skin_surface_3
  libeigen3-dev                                     # small dense linear algebra
  libopenmesh-dev                                   # surface mesh and local edits
  libtet1.5-dev                                     # TetGen library: volume meshes, self-intersection check
  catch2                                            # tests (v2)
  gemmi-dev tao-pegtl-dev zlib1g-dev                # PDB/mmCIF input (gemmi's cif.hpp needs PEGTL)
  libtbb-dev                                        # threads
  libcli11-dev                                      # command line
  nlohmann-json3-dev                                # JSON reports
  libpng-dev                                        # PNG pictures (skinmesh render)
  pybind11-dev python3-dev python3-numpy            # the Python module (docs/python.md)
  python3-pytest python3-meshio python3-mdanalysis  # its tests: pytest, meshio, MD trajectories
  snakemake                                         # many structures: workflows/Snakefile (docs/batch.md)
  chromium chromium-driver ffmpeg python3-pymol     # viewer tests (headless), movies, PyMOL reads our output
)
# Node.js runs the browser and glTF tests' tools (tests/js); a Node.js installed
# some other way is used as it is.
command -v npm >/dev/null || packages+=(nodejs npm)

source "$here/scripts/install-packages.sh"
[ "${SKINMESH_SKIP_INSTALL:-0}" != 1 ] && install_packages "${packages[@]}"

# The test tools from npm, at the versions tests/js/package-lock.json pins.
if [ "${SKINMESH_SKIP_INSTALL:-0}" != 1 ]; then
  npm ci --prefix "$here/tests/js" --no-audit --no-fund --loglevel=error
fi

launcher=()
command -v ccache >/dev/null && launcher=(-DCMAKE_CXX_COMPILER_LAUNCHER=ccache)
cmake -S "$here" -B "$here/build" -DCMAKE_BUILD_TYPE=Release "${launcher[@]}"
cmake --build "$here/build" -j "$(nproc)"

# /usr/bin/python3 finds the module built into build/python (docs/python.md).
if [ -d "$here/build/python/skinmesh" ] && [ -w /usr/lib/python3/dist-packages ]; then
  echo "$here/build/python" > /usr/lib/python3/dist-packages/skinmesh-build.pth
fi
