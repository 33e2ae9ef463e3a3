#!/usr/bin/python3
"""Writes a hall divided by a pierced screen (a mashrabiya: a wall of square openings) for
checking lightcuts on an occlusion-heavy scene nobody tuned to (issue 20). The camera's half
holds a few pillars and benches; N point lights: half in the far half behind the screen
(eight lamp clusters and scattered lights), so that every cluster there reaches the near
half through a different pattern of openings, a quarter in lamp clusters in the near half,
a quarter scattered anywhere. Written after the visibility coin's weight was derived.

  /usr/bin/python3 scripts/gen_screen_hall.py SEED N OUT.ray
"""
import os
import sys

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
from gen_scenes import box, seeded_args, write_lines  # noqa: E402


def main(argv):
    rng, n, out = seeded_args(argv, __doc__)
    o = ["SBT-raytracer 1.0",
         "camera { position = (-4.6, 1.7, 5.4); look_at = (0.5, 1.2, -0.5); fov = 62; }",
         "material = { name = plaster; diffuse = (0.72, 0.7, 0.66); }",
         "material = { name = floor; diffuse = (0.5, 0.42, 0.34); specular = (0.25, 0.25, 0.25); shininess = 30; }",
         "material = { name = screen; diffuse = (0.55, 0.4, 0.28); }",
         "material = { name = stone; diffuse = (0.6, 0.6, 0.58); }"]

    W, H, D = 12.0, 4.0, 14.0
    o.append(box((0, -0.05, 0), (W, 0.1, D), "floor").rstrip())
    o.append(box((0, H + 0.05, 0), (W, 0.1, D), "plaster").rstrip())
    o.append(box((-W / 2 - 0.05, H / 2, 0), (0.1, H, D), "plaster").rstrip())
    o.append(box((W / 2 + 0.05, H / 2, 0), (0.1, H, D), "plaster").rstrip())
    o.append(box((0, H / 2, -D / 2 - 0.05), (W, H, 0.1), "plaster").rstrip())
    o.append(box((0, H / 2, D / 2 + 0.05), (W, H, 0.1), "plaster").rstrip())
    # The screen at z = 0: vertical and horizontal bars 0.08 thick, openings 0.22 wide.
    pitch, bar = 0.3, 0.08
    x = -W / 2
    while x <= W / 2 + 1e-6:
        o.append(box((x, 1.9, 0), (bar, 3.0, 0.12), "screen").rstrip())
        x += pitch
    y = 0.4
    while y <= 3.4 + 1e-6:
        o.append(box((0, y, 0), (W, bar, 0.12), "screen").rstrip())
        y += pitch
    o.append(box((0, 0.2, 0), (W, 0.4, 0.12), "stone").rstrip())  # plinth under the screen
    o.append(box((0, 3.7, 0), (W, 0.6, 0.12), "stone").rstrip())  # lintel above it
    for px in (-3.0, 0.5, 4.0):                      # pillars in the near half
        o.append(box((px, H / 2, 3.0 + rng.uniform(-0.5, 0.5)), (0.35, H, 0.35), "stone", rng.uniform(0, 45)).rstrip())
    for _ in range(4):                               # benches
        o.append(box((rng.uniform(-5, 5), 0.25, rng.uniform(1.5, 6)), (1.6, 0.1, 0.45), "screen", rng.uniform(-30, 30)).rstrip())
    lights = []
    far_lamps = [(rng.uniform(-5, 5), rng.uniform(1.0, 3.6), rng.uniform(-6.5, -1.0)) for _ in range(8)]
    near_lamps = [(rng.uniform(-5, 5), rng.uniform(2.8, 3.8), rng.uniform(1.0, 6.5)) for _ in range(4)]
    for i in range(n):
        r = i % 4
        if r in (0, 1):
            if r == 0:
                c = far_lamps[i % 8]
                p = (rng.gauss(c[0], 0.25), min(H - 0.05, rng.gauss(c[1], 0.15)), rng.gauss(c[2], 0.25))
            else:
                p = (rng.uniform(-5.8, 5.8), rng.uniform(0.2, 3.9), rng.uniform(-6.8, -0.3))
            col, k = (1.0, 0.85, 0.6), 1.0
        elif r == 2:
            c = near_lamps[i % 4]
            p = (rng.gauss(c[0], 0.15), min(H - 0.05, rng.gauss(c[1], 0.1)), rng.gauss(c[2], 0.15))
            col, k = (0.8, 0.9, 1.0), 0.4
        else:
            p = (rng.uniform(-5.8, 5.8), rng.uniform(0.2, 3.9), rng.uniform(0.3, 6.8))
            col, k = (1.0, 1.0, 0.95), 0.3
        p = (max(-5.9, min(5.9, p[0])), max(0.1, p[1]), max(-6.9, min(6.9, p[2])))
        if abs(p[2]) < 0.15:
            p = (p[0], p[1], 0.2 if p[2] >= 0 else -0.2)
        lights.append((p, col, k))
    scale = 120.0 / n
    for p, col, k in lights:
        o.append("point_light { position = (%.4f, %.4f, %.4f); colour = (%g, %g, %g); }"
                 % (p[0], p[1], p[2], scale * k * col[0], scale * k * col[1], scale * k * col[2]))
    write_lines(out, o)


if __name__ == "__main__":
    main(sys.argv)
