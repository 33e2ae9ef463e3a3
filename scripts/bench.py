#!/usr/bin/python3
"""The benchmark driver behind `make bench` (issue 7): renders the scene suite with brute
force, Lightcuts and the seed's method, measures time, lights per shading point and error,
runs the scaling sweep, the 100k-light accuracy check and the ray/tree micro benchmarks,
and writes the generated section of docs/BENCHMARKS.md and the images docs/images/bench_*.png.

  /usr/bin/python3 scripts/bench.py [--build DIR] [--quick] [--resume] [--only PART ...]
      [--work DIR] [--no-docs] [--threads N]

Environment: BUILD (build folder, default `build`), BENCH_QUICK=1 (same as --quick).

Full mode writes docs/BENCHMARKS.md and docs/images/ (about an hour on 2 cores);
quick mode (small images, one run each; about half an hour on 2 cores) writes
out/bench-quick/BENCHMARKS.md and out/bench-quick/images/ and leaves docs/ alone unless --docs
is given. Raw renders, --stats
files, logs and results.json go to out/bench/ (or out/bench-quick/); --resume reuses the parts
already in results.json (same commit) instead of measuring them again; --write-only
regenerates the Markdown and images from results.json. A partial run (--only ROW ...) at full
size without touching docs/: --only courtyard_sunsky garden_hdr --work out/bench-env --no-docs.

Times: the render phase plus the light-tree build (`time_render_s + time_tree_s` of --stats),
wall clock on all cores, median of repeated runs. Loading, Embree's BVH and VPL generation are
common to every method and left out. Brute force runs at full resolution when the estimate
from --reference-pixels is under BRUTE_LIMIT seconds; otherwise its time is the estimate
(brute force at K pixels, scaled to the image) and is marked "~", and errors are measured at
those K pixels instead of over the whole image.
"""
import argparse
import os

from bench_parts import accuracy, micro, scaling, table_row
from bench_runs import Driver, now
from bench_scenes import ROWS
from bench_tables import write

# The modules beside this one: bench_scenes.py (the scene rows), bench_runs.py (the Driver:
# settings, the binary, results.json), bench_parts.py (the measured parts), bench_images.py
# (tone mapping, montages, the scaling plot), bench_tables.py (the generated Markdown).


def run_parts(drv):
    """Measures the parts not yet done (all of them, or those named by --only)."""
    a = drv.a
    if not os.path.exists(drv.lc):
        raise SystemExit(f"bench: {drv.rel(drv.lc)} not found: build first (make build BUILD=...)")
    env = drv.environment()
    old = drv.results.get("env")
    if old and old.get("commit") == env["commit"] and a.resume:
        env["loadavg_start"] = old.get("loadavg_start", env["loadavg_start"])
    drv.results["env"] = env
    only = set(a.only or [])
    parts = [("row:" + r["key"], lambda r=r: table_row(drv, r)) for r in ROWS]
    parts += [("scaling", lambda: scaling(drv)), ("accuracy", lambda: accuracy(drv)), ("micro", lambda: micro(drv))]
    t0 = now()
    for key, fn in parts:
        short = key.split(":")[-1]
        if only and short not in only and key not in only and not (key.startswith("row:") and "table" in only):
            continue
        t = now()
        print(f"bench: {short} ...", flush=True)
        fn()
        print(f"bench: {short} done in {now() - t:.0f} s (total {(now() - t0) / 60:.1f} min)", flush=True)


def main():
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--build", default=os.environ.get("BUILD", "build"), help="build folder (default $BUILD or build)")
    ap.add_argument("--quick", action="store_true", default=os.environ.get("BENCH_QUICK", "") not in ("", "0"),
                    help="small sizes, one run each (also BENCH_QUICK=1)")
    ap.add_argument("--work", help="folder for renders and results.json (default out/bench or out/bench-quick)")
    ap.add_argument("--docs", action="store_true", help="in quick mode, write docs/ too")
    ap.add_argument("--no-docs", action="store_true",
                    help="in full mode, write the Markdown and images to the work folder, not docs/ (for a partial "
                         "run with --only)")
    ap.add_argument("--threads", type=int, default=0,
                    help="--threads for every render (default: the binary's, all cores)")
    ap.add_argument("--resume", action="store_true", help="reuse parts already measured at this commit")
    ap.add_argument("--write-only", action="store_true", help="only rewrite the Markdown and images from results.json")
    ap.add_argument("--only", nargs="*", help="parts to run: row keys (" + ", ".join(r["key"] for r in ROWS) +
                    "), table, scaling, accuracy, micro")
    a = ap.parse_args()
    drv = Driver(a)
    drv.check_exr_reader()
    if not a.write_only:
        run_parts(drv)
    write(drv)


if __name__ == "__main__":
    main()
