#!/usr/bin/python3
"""Writes a corner of a room with a finned radiator under a window, a slatted bench and a
shelf, lit by N point lights: a third in a warm cluster behind and above the radiator (the
window), the rest scattered under the ceiling. The radiator's thin fins, 0.035 apart, are
seen obliquely, and the bench's slats from above: surfaces close to each other that hide
different lights from points a fraction of a pixel apart. Written as an unseen check of
the antialiasing probe (docs/LIGHTCUTS.md, "Sub-samples beyond their samples"), after its
constants were chosen.

  /usr/bin/python3 scripts/gen_radiator.py SEED N OUT.ray
"""
import os
import sys

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
from gen_scenes import box, seeded_args, write_lines  # noqa: E402


def main(argv):
    rng, n, out = seeded_args(argv, __doc__)
    o = ["SBT-raytracer 1.0",
         "camera { position = (1.1, 1.25, 0.9); look_at = (-0.45, 0.5, -1.2); fov = 55; }",
         "material = { name = wall; diffuse = (0.74, 0.72, 0.68); }",
         "material = { name = floor; diffuse = (0.5, 0.42, 0.33); specular = (0.05, 0.05, 0.05); shininess = 20; }",
         "material = { name = metal; diffuse = (0.82, 0.82, 0.8); }",
         "material = { name = wood; diffuse = (0.55, 0.38, 0.22); }"]
    o.append(box((0, -0.05, 0), (6, 0.1, 6), "floor"))
    o.append(box((0, 1.4, -1.55), (6, 2.8, 0.1), "wall"))   # back wall
    o.append(box((-1.55, 1.4, 0), (0.1, 2.8, 6), "wall"))   # side wall
    # Radiator: 28 fins along x against the back wall, on two feet.
    for i in range(28):
        o.append(box((-0.9 + 0.035 * i, 0.45, -1.38), (0.008, 0.55, 0.12), "metal"))
    o.append(box((-0.43, 0.1, -1.38), (1.0, 0.2, 0.04), "metal"))
    # Bench: 9 slats along z, 0.05 wide with 0.02 gaps, on two legs.
    for i in range(9):
        o.append(box((0.5, 0.42, -0.35 + 0.07 * i), (1.2, 0.03, 0.05), "wood"))
    for x in (0.0, 1.0):
        o.append(box((x, 0.2, -0.07), (0.05, 0.4, 0.6), "wood"))
    # Shelf on the side wall with a row of upright books.
    o.append(box((-1.35, 1.2, -0.4), (0.3, 0.03, 1.2), "wood"))
    for i in range(22):
        h = rng.uniform(0.16, 0.26)
        o.append(box((-1.38, 1.215 + h / 2, -0.95 + 0.05 * i), (0.2, h, 0.035), "wood"))
    for k in range(n):
        if k < n // 3:   # the window: warm, above and behind the radiator
            p = (rng.uniform(-1.0, 0.1), rng.uniform(0.9, 1.8), rng.uniform(-1.45, -1.3))
            col, s = (1.0, 0.85, 0.65), 1.5
        else:
            p = (rng.uniform(-1.4, 2.5), rng.uniform(2.2, 2.7), rng.uniform(-1.4, 2.5))
            col, s = (0.85, 0.9, 1.0), 1.0
        c = [6.0 / n * s * v for v in col]
        o.append("point_light { position = (%.4f, %.4f, %.4f); colour = (%g, %g, %g); }" % (p + tuple(c)))
    write_lines(out, o)


if __name__ == "__main__":
    main(sys.argv)
