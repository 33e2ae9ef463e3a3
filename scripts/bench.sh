#!/usr/bin/env bash
# `make bench`: installs what the benchmark driver needs (Debian packages, only those
# missing), then runs scripts/bench.py, which renders the scene suite and rewrites the
# generated section of docs/BENCHMARKS.md and docs/images/bench_*.png.
#   BUILD=build-bench ./scripts/bench.sh        # the build folder (default build)
#   BENCH_QUICK=1 ./scripts/bench.sh            # small sizes, one run each: out/bench-quick/
#   ./scripts/bench.sh --resume                 # extra arguments go to bench.py (see --help)
set -euo pipefail
cd "$(dirname "$0")/.."
# libmagickcore-6.q16-6-extra: ImageMagick's OpenEXR delegate (convert reads the .exr renders).
pkgs=(python3 python3-numpy python3-matplotlib python3-pil imagemagick libmagickcore-6.q16-6-extra)
scripts/install-deps.sh "${pkgs[@]}"
exec /usr/bin/python3 scripts/bench.py --build "${BUILD:-build}" "$@"
