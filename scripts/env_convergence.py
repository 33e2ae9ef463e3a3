#!/usr/bin/python3
"""Convergence of the environment-to-directional-lights conversion (issue 24): renders a scene
with brute force at --env-lights N for several N and at a reference count, and prints the
RMSE (and relative RMSE) of each against the reference, with the ratio between successive
rows. Brute force, so that the cut's own error does not enter.

  /usr/bin/python3 scripts/env_convergence.py [--scene S] [--size 48] [--ref 65536]
      [--counts 1024,2048,4096,8192,16384] [--build build] [--out out/env-convergence]
"""
import argparse
import json
import os
import subprocess

ROOT = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("--scene", default="scenes/courtyard_sunsky.ray")
    ap.add_argument("--size", type=int, default=48)
    ap.add_argument("--ref", type=int, default=65536)
    ap.add_argument("--counts", default="1024,2048,4096,8192,16384")
    ap.add_argument("--build", default=os.environ.get("BUILD", "build"))
    ap.add_argument("--out", default="out/env-convergence")
    ap.add_argument("--threads", type=int, default=0)
    a = ap.parse_args()
    exe = os.path.join(ROOT, a.build, "lightcuts")
    out = os.path.join(ROOT, a.out)
    os.makedirs(out, exist_ok=True)

    def render(n):
        path = os.path.join(out, f"n{n}.exr")
        cmd = [exe, "render", os.path.join(ROOT, a.scene), "-o", path, "--method", "brute", "--width", str(a.size),
               "--height", str(a.size), "--env-lights", str(n)]
        if a.threads:
            cmd += ["--threads", str(a.threads)]
        subprocess.run(cmd, check=True, stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL)
        return path

    ref = render(a.ref)
    print(f"scene {a.scene}, {a.size}x{a.size}, brute force, reference {a.ref} lights")
    print("| lights | RMSE | relative RMSE | ratio to the previous row |")
    print("|---|---|---|---|")
    prev = None
    for n in [int(x) for x in a.counts.split(",")]:
        m = json.loads(subprocess.run([exe, "compare", ref, render(n), "--json"], check=True,
                                      capture_output=True, text=True).stdout)
        ratio = f"{prev / m['rmse']:.2f}" if prev else ""
        print(f"| {n:,} | {m['rmse']:.5f} | {m['relative_rmse']:.4f} | {ratio} |")
        prev = m["rmse"]


if __name__ == "__main__":
    main()
