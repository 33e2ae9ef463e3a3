#!/usr/bin/python3
"""Writes a stairwell: five flights of box steps zig-zag up a closed shaft, each landing lit
by a cluster of small lamps (point lights) and a spot on the opposite wall; thin balusters
along the flights and a screen of slats against the back wall. Lights hang under the next
flight and between the steps, so most of them are hidden from most points. Written as an
unseen check of issues 20 and 21 (docs/BENCHMARKS.md, "An unseen stairwell"), after the
methods it checks were made; GI adds `instant_radiosity` (VPL paths from those lights).

  /usr/bin/python3 scripts/gen_stairwell.py SEED LIGHTS OUT.ray [VPL_PATHS]
"""
import os
import random
import sys

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
from gen_scenes import box, cylinder_y, light_text, write_lines  # noqa: E402


def main(argv):
    if len(argv) not in (4, 5):
        raise SystemExit(__doc__)
    seed, n, out = int(argv[1]), int(argv[2]), argv[3]
    vpls = int(argv[4]) if len(argv) == 5 else 0
    rng = random.Random(seed)
    w, d, h = 4.0, 3.0, 9.0  # the shaft: x, z, height
    o = ["SBT-raytracer 1.0",
         "camera { position = (0.3, 0.7, 1.4); look_at = (-0.3, 4.5, -0.8); fov = 80; }"]
    if vpls:
        o.append(f"instant_radiosity {{ vpls = {vpls}; bounces = 1; }}")
    o += ["material = { name = w; diffuse = (0.7, 0.7, 0.68); }",
          "material = { name = s; diffuse = (0.55, 0.45, 0.35); specular = (0.2,0.2,0.2); shininess = 20; }",
          "material = { name = r; diffuse = (0.15, 0.15, 0.18); specular = (0.5,0.5,0.5); shininess = 60; }"]
    o.append(box((0, -0.1, 0), (w + 0.4, 0.2, d + 0.4), "w"))
    o.append(box((0, h + 0.1, 0), (w + 0.4, 0.2, d + 0.4), "w"))
    o.append(box((-w / 2 - 0.1, h / 2, 0), (0.2, h, d + 0.4), "w"))
    o.append(box((w / 2 + 0.1, h / 2, 0), (0.2, h, d + 0.4), "w"))
    o.append(box((0, h / 2, -d / 2 - 0.1), (w + 0.4, h, 0.2), "w"))
    for k in range(12):  # slats against the back wall
        o.append(box((1.2, 2.5 + 0.22 * k, -d / 2 + 0.08), (1.2, 0.05, 0.06), "r"))
    groups = []
    flight_h, steps = 1.5, 9
    for f in range(5):
        y0 = f * flight_h
        up = 1 if f % 2 == 0 else -1  # the flight climbs along +x or -x
        zc = -0.6 if f % 2 == 0 else 0.6
        for s in range(steps):
            x = -up * 1.3 + up * (2.6 * (s + 0.5) / steps)
            y = y0 + flight_h * (s + 1) / steps
            o.append(box((x, y - 0.06, zc), (2.6 / steps + 0.01, 0.12, 1.1), "s"))
            if s % 2 == 0:  # balusters on the open side
                o.append(cylinder_y((x, y, zc + 0.55 * up), 0.02, 0.9, "r"))
        ly, lx = y0 + flight_h, up * 1.6
        o.append(box((lx, ly - 0.06, 0), (0.8, 0.12, d), "s"))  # the landing
        groups.append(("lamps", (lx + rng.uniform(-0.2, 0.2), ly + 1.2, rng.uniform(-0.8, 0.8))))
        groups.append(("spot", (-lx * 1.15, ly + 0.9, rng.uniform(-1, 1))))
    per = n // len(groups)
    for kind, (x, y, z) in groups:
        col = (rng.uniform(0.7, 1), rng.uniform(0.6, 0.9), rng.uniform(0.4, 0.8))
        for _ in range(per):
            if kind == "lamps":
                p = (x + rng.gauss(0, 0.12), y + rng.gauss(0, 0.05), z + rng.gauss(0, 0.12))
                o.append(light_text(p, col, 3.0 / per))
            else:
                p = (x + rng.uniform(-0.1, 0.1), y + rng.uniform(-0.1, 0.1), z + rng.uniform(-0.1, 0.1))
                o.append(light_text(p, col, 2.0 / per, spot=(rng.uniform(-0.5, 0.5), rng.uniform(-0.5, 0.5), 40, 4)))
    write_lines(out, o)


if __name__ == "__main__":
    main(sys.argv)
