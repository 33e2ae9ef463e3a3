#!/usr/bin/env bash
# `make bench`: installs what the benchmark driver needs (Debian packages, only those
# missing), then runs scripts/bench.py, which renders the scene suite and rewrites the
# generated section of docs/BENCHMARKS.md and docs/images/bench_*.png.
#   BUILD=build-bench ./scripts/bench.sh        # the build folder (default build)
#   BENCH_QUICK=1 ./scripts/bench.sh            # small sizes, one run each: out/bench-quick/
#   ./scripts/bench.sh --resume                 # extra arguments go to bench.py (see --help)
set -euo pipefail
cd "$(dirname "$0")/.."
pkgs=(python3 python3-numpy python3-matplotlib python3-pil imagemagick)
missing=()
for p in "${pkgs[@]}"; do
  dpkg-query -W -f='${Status}' "$p" 2>/dev/null | grep -q "install ok installed" || missing+=("$p")
done
if [ ${#missing[@]} -gt 0 ]; then
  echo "bench: installing ${missing[*]}" >&2
  SUDO=""
  if [ "$(id -u)" -ne 0 ]; then SUDO="sudo"; fi
  export DEBIAN_FRONTEND=noninteractive
  $SUDO apt-get update
  $SUDO apt-get install -y --no-install-recommends "${missing[@]}"
fi
exec /usr/bin/python3 scripts/bench.py --build "${BUILD:-build}" "$@"
