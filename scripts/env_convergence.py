#!/usr/bin/python3
"""Convergence of the environment-to-directional-lights conversion (issue 24): renders each
scene with brute force at --env-lights N for several N and at a reference count, and prints
the RMSE (and relative RMSE) of each against the reference, the ratio between successive
rows and the exponent of a least-squares fit RMSE ~ N^-p. Brute force, so that the cut's own
error does not enter; the pixel centres only (--aa off), since antialiasing is the same at
every N.

  /usr/bin/python3 scripts/env_convergence.py [--scene S ...] [--size 40] [--ref 65536]
      [--counts 1024,2048,4096,8192,16384] [--threads 1] [--build build] [--out out/env-convergence]
      [--unoccluded | --unoccluded-only]

--unoccluded adds two scenes written on the fly: a diffuse sphere alone under the courtyard's
sun/sky and under the garden's HDR map (nothing casts a shadow; the only non-smooth part of
the integrand is the cosine's clamp at each point's horizon).
"""
import argparse
import json
import math
import os
import subprocess

ROOT = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))

SPHERE = """SBT-raytracer 1.0
// Written by scripts/env_convergence.py: a diffuse sphere alone under {what}.
camera {{ position = (0, 0, 3.2); look_at = (0, 0, 0); fov = 40; aspectratio = 1; }}
{light}
sphere {{ material = {{ diffuse = (0.7, 0.7, 0.7); }}; }}
"""
UNOCCLUDED = {
    "sphere_sunsky": ("the courtyard's sun and sky",
                      "sun_sky_light { direction = (-0.55, -0.6, -0.58); turbidity = 3; lights = 4096; "
                      "ground = (0.3, 0.28, 0.25); }"),
    "sphere_hdr": ("the garden's HDR map",
                   'environment_light { map = "MAP"; rotate = 20; lights = 4096; }'),
}


def fit_exponent(ns, errs):
    """p of the least-squares line log err = c - p log N."""
    pts = [(math.log(n), math.log(e)) for n, e in zip(ns, errs) if e > 0]
    if len(pts) < 2:
        return float("nan")
    mx = sum(x for x, _ in pts) / len(pts)
    my = sum(y for _, y in pts) / len(pts)
    sxx = sum((x - mx) ** 2 for x, _ in pts)
    sxy = sum((x - mx) * (y - my) for x, y in pts)
    return -sxy / sxx


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("--scene", action="append", help="scene file (repeatable; default the courtyard and the garden)")
    ap.add_argument("--unoccluded", action="store_true", help="also the two sphere-alone scenes (see above)")
    ap.add_argument("--unoccluded-only", action="store_true", help="only the two sphere-alone scenes")
    ap.add_argument("--size", type=int, default=40)
    ap.add_argument("--ref", type=int, default=65536)
    ap.add_argument("--counts", default="1024,2048,4096,8192,16384")
    ap.add_argument("--build", default=os.environ.get("BUILD", "build"))
    ap.add_argument("--out", default="out/env-convergence")
    ap.add_argument("--threads", type=int, default=0)
    ap.add_argument("--seeds", default="1", help="--seed values (comma-separated): each N is rendered with each, "
                    "against the reference at the first, and the RMSE is the root mean square over them")
    a = ap.parse_args()
    exe = os.path.join(ROOT, a.build, "lightcuts")
    out = os.path.join(ROOT, a.out)
    os.makedirs(out, exist_ok=True)
    scenes = []
    if a.unoccluded or a.unoccluded_only:
        for name, (what, light) in UNOCCLUDED.items():
            path = os.path.join(out, name + ".ray")
            light = light.replace("MAP", os.path.join(ROOT, "data/env/sky_sun_t3.exr"))
            with open(path, "w") as f:
                f.write(SPHERE.format(what=what, light=light))
            scenes.append(path)
    if not a.unoccluded_only:
        scenes += [os.path.join(ROOT, s) for s in (a.scene or ["scenes/courtyard_sunsky.ray", "scenes/garden_hdr.ray"])]
    counts = [int(x) for x in a.counts.split(",")]
    seeds = [int(x) for x in a.seeds.split(",")]

    for scene in scenes:
        name = os.path.splitext(os.path.basename(scene))[0]
        sub = os.path.join(out, name)
        os.makedirs(sub, exist_ok=True)

        def render(n, seed):
            path = os.path.join(sub, f"n{n}.exr" if seed == seeds[0] else f"n{n}_s{seed}.exr")
            cmd = [exe, "render", scene, "-o", path, "--method", "brute", "--width", str(a.size),
                   "--height", str(a.size), "--aa", "off", "--env-lights", str(n), "--seed", str(seed)]
            if a.threads:
                cmd += ["--threads", str(a.threads)]
            subprocess.run(cmd, check=True, stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL)
            return path

        ref = render(a.ref, seeds[0])
        over = f", RMS over seeds {a.seeds}" if len(seeds) > 1 else ""
        print(f"\nscene {os.path.relpath(scene, ROOT)}, {a.size}x{a.size}, brute force, pixel centres, "
              f"reference {a.ref:,} lights{over}")
        print("| lights | RMSE | relative RMSE | ratio to the previous row |")
        print("|---|---|---|---|")
        prev = None
        errs = []
        for n in counts:
            ms = [json.loads(subprocess.run([exe, "compare", ref, render(n, seed), "--json"], check=True,
                                            capture_output=True, text=True).stdout) for seed in seeds]
            m = {k: math.sqrt(sum(x[k] ** 2 for x in ms) / len(ms)) for k in ("rmse", "relative_rmse")}
            ratio = f"{prev / m['rmse']:.2f}" if prev and m["rmse"] > 0 else ""
            print(f"| {n:,} | {m['rmse']:.3g} | {m['relative_rmse']:.3g} | {ratio} |", flush=True)
            prev = m["rmse"]
            errs.append(m["rmse"])
        p = fit_exponent(counts, errs)
        print(f"least-squares fit: RMSE ~ N^-{p:.2f} ({2 ** p:.2f}x per doubling)", flush=True)


if __name__ == "__main__":
    main()
