#!/usr/bin/python3
"""Writes a porch seen from inside: a diagonal garden lattice (two layers of thin laths at
+-45 degrees) across an opening, a staircase with a row of thin balusters, and a slatted
table, lit by N point lights: half outside beyond the lattice, the rest in two lamp
clusters inside. The lattice's crossings and the balusters' faces are seen at many angles,
and the light through the lattice's diamonds changes within a fraction of a pixel. Written
as an unseen check of antialiasing under reconstruction cuts (docs/LIGHTCUTS.md, "Samples
inside a pixel"), after its constants were chosen.

  /usr/bin/python3 scripts/gen_lattice.py SEED N OUT.ray
"""
import os
import sys

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
from gen_scenes import box, seeded_args, write_lines  # noqa: E402


def main(argv):
    rng, n, out = seeded_args(argv, __doc__)
    o = ["SBT-raytracer 1.0",
         "camera { position = (1.6, 1.5, 2.4); look_at = (-0.3, 0.8, -1.0); fov = 55; }",
         "material = { name = wall; diffuse = (0.72, 0.7, 0.66); }",
         "material = { name = floor; diffuse = (0.45, 0.4, 0.35); }",
         "material = { name = lath; diffuse = (0.8, 0.78, 0.7); }",
         "material = { name = wood; diffuse = (0.5, 0.34, 0.2); }"]
    o.append(box((0, -0.05, 0), (8, 0.1, 8), "floor"))
    o.append(box((0, 2.9, 0), (8, 0.1, 8), "wall"))           # ceiling
    # Back wall with an opening 2.4 wide and 2.0 high, filled by the lattice.
    o.append(box((-2.6, 1.4, -1.6), (2.8, 2.8, 0.1), "wall"))
    o.append(box((2.6, 1.4, -1.6), (2.8, 2.8, 0.1), "wall"))
    o.append(box((0, 2.5, -1.6), (2.4, 0.8, 0.1), "wall"))
    for layer, (angle, z) in enumerate(((45.0, -1.57), (-45.0, -1.61))):
        for i in range(-14, 15):
            c = 0.12 * i
            o.append(box((c, 1.05, z), (0.025, 2.9, 0.02), "lath", rot_z=angle))
    # Clip the lattice to the opening: wall strips hide the laths' ends.
    o.append(box((0, 0.02, -1.59), (2.6, 0.08, 0.12), "wall"))
    o.append(box((-1.25, 1.05, -1.54), (0.1, 2.1, 0.04), "wall"))
    o.append(box((1.25, 1.05, -1.54), (0.1, 2.1, 0.04), "wall"))
    # Staircase along the left wall, with balusters 0.09 apart on the open side.
    o.append(box((-2.0, 1.4, 0.5), (0.1, 2.8, 4.0), "wall"))
    for s in range(10):
        o.append(box((-1.6, 0.09 * (s + 1), 2.0 - 0.28 * s), (0.7, 0.18 * (s + 1), 0.28), "wood"))
        for b in range(3):
            z = 2.0 - 0.28 * s - 0.09 + 0.09 * b
            o.append(box((-1.27, 0.18 * (s + 1) + 0.45, z), (0.025, 0.9, 0.025), "wood"))
    # Slatted table: 12 slats 0.04 wide with 0.02 gaps.
    for i in range(12):
        o.append(box((0.6, 0.74, 0.0 + 0.06 * i), (1.1, 0.03, 0.04), "wood"))
    for x in (0.1, 1.1):
        for z in (0.02, 0.64):
            o.append(box((x, 0.36, z), (0.05, 0.72, 0.05), "wood"))
    for k in range(n):
        if k < n // 2:   # outside, beyond the lattice
            p = (rng.uniform(-2.5, 2.5), rng.uniform(0.3, 2.6), rng.uniform(-3.5, -1.8))
            col, s = (1.0, 0.9, 0.75), 2.0
        else:            # two lamp clusters inside
            cx, cz = ((0.6, 0.3), (-0.6, 1.6))[k % 2]
            p = (cx + rng.gauss(0, 0.12), 2.3 + rng.gauss(0, 0.08), cz + rng.gauss(0, 0.12))
            col, s = (0.9, 0.92, 1.0), 1.0
        c = [6.0 / n * s * v for v in col]
        o.append("point_light { position = (%.4f, %.4f, %.4f); colour = (%g, %g, %g); }" % (p + tuple(c)))
    write_lines(out, o)


if __name__ == "__main__":
    main(sys.argv)
