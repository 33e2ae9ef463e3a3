#!/usr/bin/env bash
# Installs the Debian packages lightcuts builds with, only when one is missing.
# Idempotent: a second run with everything present touches nothing.
#   scripts/install-deps.sh            # the build's packages (below)
#   scripts/install-deps.sh PKG ...    # these packages instead (bench.sh, fuzz.sh, make report)
set -euo pipefail
pkgs=(
  build-essential cmake pkg-config
  libembree-dev        # Embree 3: every ray query (BVH build, intersection, occlusion)
  libtbb-dev           # oneTBB: parallel tiles, parallel light placement and VPLs
  libpng-dev           # libpng: PNG textures and images (decoding)
  libjpeg62-turbo-dev  # libjpeg-turbo: JPEG textures (decoding)
  libstb-dev           # stb_image / stb_image_write / stb_easy_font: BMP/TGA/PNM/HDR textures, PNG/BMP output, legends
  libcli11-dev         # CLI11: the command line
  libfmt-dev           # fmt: formatting of messages and reports
  libopenexr-dev       # OpenEXR: float images (reference renders, partial output)
  libtinyobjloader-dev # tinyobjloader: OBJ/MTL input
  nlohmann-json3-dev   # nlohmann/json: --stats and --json output
  libgtest-dev         # GoogleTest: the test suite
  libbenchmark-dev     # Google Benchmark: micro benchmarks under bench/
  help2man             # the man page (lightcuts.1) from `lightcuts --help-all`; skipped without it
  libopenmpi-dev       # Open MPI: distributed rendering over MPI (mpirun -np K lightcuts render ...; CMake LC_MPI)
  openmpi-bin          # Open MPI's mpirun: launching those jobs, and the MPI tests (src/app/distributed_test.cpp)
  python3-markdown     # Python-Markdown: `make report` (scripts/report.py) turns docs/BENCHMARKS.md into HTML
)
if [ $# -gt 0 ]; then pkgs=("$@"); fi
missing=()
for p in "${pkgs[@]}"; do
  dpkg-query -W -f='${Status}' "$p" 2>/dev/null | grep -q "install ok installed" || missing+=("$p")
done
if [ ${#missing[@]} -eq 0 ]; then
  exit 0
fi
echo "install-deps: installing ${missing[*]}" >&2
SUDO=""
if [ "$(id -u)" -ne 0 ]; then SUDO="sudo"; fi
export DEBIAN_FRONTEND=noninteractive
$SUDO apt-get update
$SUDO apt-get install -y --no-install-recommends "${missing[@]}"
