#!/usr/bin/env python3
"""Scaling of a distributed render (issue 27; docs/DISTRIBUTED.md): one scene rendered by one
process with 1 and 2 threads and by 1..4 MPI ranks of 1 thread each, REPEAT times each; prints
a Markdown table of median times (wall clock of the whole command, and the render phase), the
load balance, the CPU time of the whole job (user + system, every rank and mpirun) and whether
every image is identical, byte for byte, to the one-process one. On a machine shared with
other work the wall clock follows the others' load; the CPU time does not.

  scripts/bench_mpi.py [--scene scenes/church.ray] [--width 256] [--repeat 3] [--ranks 4]

Run from the repository root after building (build/lightcuts). mpirun runs with
--oversubscribe (and --allow-run-as-root when root): on a machine with fewer cores than
ranks, ranks share cores.
"""
import argparse
import filecmp
import json
import os
import resource
import statistics
import subprocess
import sys
import tempfile
import time


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("--scene", default="scenes/church.ray")
    ap.add_argument("--width", type=int, default=256)
    ap.add_argument("--repeat", type=int, default=3)
    ap.add_argument("--ranks", type=int, default=4)
    ap.add_argument("--binary", default="build/lightcuts")
    ap.add_argument("--extra", default="", help="more render options, one string")
    ap.add_argument("--configs", default="", help="only these, e.g. '0x2,2x1' (ranks x threads; 0 = no mpirun)")
    a = ap.parse_args()

    env = dict(os.environ, OMPI_ALLOW_RUN_AS_ROOT="1", OMPI_ALLOW_RUN_AS_ROOT_CONFIRM="1")
    mpirun = ["mpirun", "--oversubscribe"] + (["--allow-run-as-root"] if os.geteuid() == 0 else [])
    tmp = tempfile.mkdtemp(prefix="bench-mpi-")
    configs = [("1 process", 0, 1), ("1 process", 0, 2)] + [(f"{k} ranks" if k > 1 else "1 rank", k, 1)
                                                          for k in range(1, a.ranks + 1)]
    if a.configs:
        want = [tuple(int(v) for v in c.split("x")) for c in a.configs.split(",")]
        configs = [c for c in configs if (c[1], c[2]) in want]
    reference = None
    # Round-robin over the configurations, so that a slow spell of a shared machine spreads
    # over all of them rather than one.
    results = {i: [] for i in range(len(configs))}
    for rep in range(a.repeat):
        for i, (label, ranks, threads) in enumerate(configs):
            out = os.path.join(tmp, f"c{i}.exr")
            stats = os.path.join(tmp, f"c{i}_{rep}.json")
            cmd = [a.binary, "render", a.scene, "-o", out, "--width", str(a.width), "--threads", str(threads),
                   "--stats", stats, "-q"] + a.extra.split()
            if ranks > 0:
                cmd = mpirun + ["-np", str(ranks)] + cmd
            r0 = resource.getrusage(resource.RUSAGE_CHILDREN)
            t0 = time.monotonic()
            subprocess.run(cmd, check=True, env=env)
            wall = time.monotonic() - t0
            r1 = resource.getrusage(resource.RUSAGE_CHILDREN)
            cpu = (r1.ru_utime - r0.ru_utime) + (r1.ru_stime - r0.ru_stime)
            j = json.load(open(stats))
            if reference is None:
                reference = os.path.join(tmp, "reference.exr")
                os.replace(out, reference)
                same = True
            else:
                same = filecmp.cmp(out, reference, shallow=False)
            lb = j.get("mpi", {}).get("load_balance")
            results[i].append((wall, j["time_render_s"], j["time_tree_s"] + j["time_lights_s"] + j["time_load_s"]
                               + j["time_accel_s"], lb, same, cpu))
            print(f"{label} x {threads} thread(s), run {rep + 1}: {wall:.2f} s wall, {cpu:.2f} s CPU, "
                  f"render {j['time_render_s']:.2f} s"
                  + (f", load balance {lb:.3f}" if lb is not None else "") + ("" if same else ", IMAGE DIFFERS"),
                  file=sys.stderr)
    basei = next((i for i, c in enumerate(configs) if c[1] == 0 and c[2] == 2), 0)  # 1 process x 2 threads
    base = statistics.median(r[0] for r in results[basei])
    basecpu = statistics.median(r[5] for r in results[basei])
    print(f"| Configuration | Wall clock (median of {a.repeat}) | vs 1 process x 2 threads | Render phase | "
          "Set-up (load, lights, tree) | CPU time | vs 1 process x 2 threads | Load balance | Image identical |")
    print("|---|---|---|---|---|---|---|---|---|")
    for i, (label, ranks, threads) in enumerate(configs):
        r = results[i]
        wall = statistics.median(x[0] for x in r)
        render = statistics.median(x[1] for x in r)
        setup = statistics.median(x[2] for x in r)
        lbs = [x[3] for x in r if x[3] is not None]
        lb = f"{100 * statistics.median(lbs):.0f}%" if lbs else "-"
        same = "yes" if all(x[4] for x in r) else "NO"
        cpu = statistics.median(x[5] for x in r)
        how = f"`mpirun -np {ranks}`" if ranks > 0 else "no mpirun"
        print(f"| {label} x {threads} thread{'s' if threads > 1 else ''} ({how}) | {wall:.1f} s | "
              f"{100 * (wall / base - 1):+.0f}% | {render:.1f} s | {setup:.2f} s | {cpu:.1f} s | "
              f"{100 * (cpu / basecpu - 1):+.0f}% | {lb} | {same} |")


if __name__ == "__main__":
    main()
