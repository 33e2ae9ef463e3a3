#!/usr/bin/python3
"""Writes a patio under a pergola for checking lightcuts on a scene nobody tuned to (issue
20): a lattice of thin beams and battens over a floor with a few tables, between two walls,
lit by N point lights: two thirds spread high above the lattice (sky light through it), the
rest in four lamp clusters under it. Every cluster of the lights above is partly hidden by
the lattice from every point below. Written after --reconstruct-split was chosen.

  /usr/bin/python3 scripts/gen_pergola.py [N] OUT.ray

N (default 6000) is the number of lights; deterministic (a fixed seed).
"""
import os
import random
import sys

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
from gen_scaling_scene import count_and_output  # noqa: E402
from gen_scenes import box, material, num  # noqa: E402


def main(argv):
    n, out = count_and_output(argv, 6000, __doc__)
    rng = random.Random(4242)
    stone = material(diffuse=(0.55, 0.5, 0.45))
    wood = material(diffuse=(0.45, 0.3, 0.2), specular=(0.2, 0.2, 0.2), shininess=20)
    lines = ["SBT-raytracer 1.0\n",
             "camera { position = (-5.5, 2.4, 6.0); look_at = (1.0, 0.6, -1.0); fov = 60; }\n"]
    lines.append(box((0, -0.05, 0), (14, 0.1, 14), stone))                 # floor
    lines.append(box((0, 1.5, -7), (14, 3, 0.2), stone))                   # back wall
    lines.append(box((7, 1.5, 0), (0.2, 3, 14), stone))                    # side wall
    for i in range(-6, 7):
        lines.append(box((i * 0.5, 3.0, 0), (0.06, 0.12, 12), wood))       # beams along z
    for k in range(-5, 6):
        lines.append(box((0, 3.15, k * 1.1), (12, 0.08, 0.05), wood))      # battens across
    for x in (-5.5, 5.5):
        for z in (-5.5, 0, 5.5):
            lines.append(box((x, 1.5, z), (0.2, 3, 0.2), wood))            # posts
    for _ in range(6):
        lines.append(box((rng.uniform(-4, 4), 0.4, rng.uniform(-4, 4)), (1.0, 0.05, 1.0), wood))  # table tops
    lamps = [(-3, -3), (3, -3), (-3, 3), (3, 3)]
    for i in range(n):
        if i % 3:
            p, c, s = (rng.uniform(-8, 8), rng.uniform(5, 9), rng.uniform(-8, 8)), (1.0, 0.95, 0.8), 1.0
        else:
            cx, cz = lamps[i % 4]
            p, c, s = (rng.gauss(cx, 0.2), rng.gauss(2.5, 0.1), rng.gauss(cz, 0.2)), (1.0, 0.7, 0.4), 0.3
        k = 60.0 / n * s
        lines.append("point_light { position = (%s, %s, %s); colour = (%s, %s, %s); }\n"
                     % (num(p[0], 3), num(p[1], 3), num(p[2], 3), num(k * c[0], 9), num(k * c[1], 9), num(k * c[2], 9)))
    with open(out, "w") as f:
        f.writelines(lines)


if __name__ == "__main__":
    main(sys.argv)
