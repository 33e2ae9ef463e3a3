#!/usr/bin/python3
"""Writes an underground car park for checks on scenes nobody tuned to (issues 20 and 21,
written in December 2026 as an unseen check, docs/LIGHTCUTS.md): a low concrete hall of
30 x 26 m under a 2.6 m ceiling, with columns, ceiling beams, a ramp wall and a stair core;
parked cars in four rows (painted, glossy bodies and dark glossy cabins on four wheels,
boxes turned at random about the vertical); rows of luminous tube lights under the ceiling
and the beams (a few of them out) and three green exit signs, all object lights; and
instant radiosity. Seen from one end of an aisle: the cars, columns and beams hide most
lights from most points.

  /usr/bin/python3 scripts/gen_garage.py SEED OUT.ray

Seed 7 is the scene of the measurements (23,122 lights with its 20,000 VPL paths).
"""
import os
import random
import sys

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
from gen_scenes import box, material, room_shell  # noqa: E402


def main(argv):
    if len(argv) != 3:
        sys.exit(__doc__)
    rng = random.Random(int(argv[1]))
    W, H, D = 30.0, 2.6, 26.0
    L = ["SBT-raytracer 1.0\n",
         "camera { position = (-13.5, 1.6, 6.6); look_at = (6, 0.9, 1.5); aspectratio = 1.5; fov = 62; }\n"]
    conc = material(diffuse=(0.55, 0.55, 0.55))
    floor = material(diffuse=(0.35, 0.35, 0.36), specular=(0.15, 0.15, 0.15), shininess=30)
    L += room_shell(W, H, D, floor, conc)
    L.append(box((6, 0.6, -6.3), (10, 1.2, 0.25), conc))  # the ramp's wall
    L.append(box((-8, H / 2, -6.3), (3, H, 2.5), material(diffuse=(0.6, 0.5, 0.4))))  # stair core
    for i in range(-2, 3):  # columns
        for j in (-4.4, 4.4):
            L.append(box((i * 5.5 + 1, H / 2, j), (0.5, H, 0.5), conc))
    for j in (-4.4, 0, 4.4):  # beams
        L.append(box((0, H - 0.2, j), (W, 0.4, 0.4), conc))
    tube = material(diffuse=(0.9, 0.9, 0.9), luminosity=dict(colour=(1.0, 0.97, 0.9), intensity=1.2, density=150))
    sign = material(diffuse=(0.2, 0.8, 0.3), luminosity=dict(colour=(0.2, 1.0, 0.3), intensity=0.6, density=400))
    for i in range(-6, 7):
        for j in (-10, -6.3, -2, 2, 6.3, 10):
            if rng.random() < 0.15:
                continue  # a tube out
            L.append(box((i * 2.2 + 0.3, H - 0.45 if abs(j) < 0.5 else H - 0.06, j), (1.2, 0.05, 0.1), tube))
    for p in ((-14.9, 2.2, 6.3), (14.9, 2.2, -6.3), (3, 2.2, -12.9)):
        L.append(box(p, (0.05 if abs(p[0]) > 14 else 0.4, 0.15, 0.4 if abs(p[0]) > 14 else 0.05), sign))
    for j in (-10.5, -2.1, 2.1, 10.5):  # rows of parked cars
        for i in range(-12, 13, 3):
            if rng.random() < 0.35:
                continue
            x = i + rng.uniform(-0.3, 0.3)
            paint = material(diffuse=tuple(rng.uniform(0.1, 0.9) for _ in range(3)), specular=(0.4, 0.4, 0.4),
                             shininess=60)
            turn = rng.uniform(-8, 8)  # radians: any heading
            L.append(box((x, 0.65, j), (1.8, 0.7, 4.2), paint, rot_y=turn))
            L.append(box((x, 1.2, j + rng.uniform(-0.3, 0.3)), (1.5, 0.5, 2.2),
                         material(diffuse=(0.08, 0.08, 0.1), specular=(0.5, 0.5, 0.5), shininess=80), rot_y=turn))
            for dx in (-0.75, 0.75):
                for dz in (-1.4, 1.4):
                    L.append(box((x + dx, 0.3, j + dz), (0.22, 0.6, 0.6), material(diffuse=(0.05, 0.05, 0.05))))
    L.append("instant_radiosity { vpls = 20000; bounces = 1; }\n")
    tmp = argv[2] + ".tmp"
    with open(tmp, "w") as f:
        f.write("".join(L))
    os.replace(tmp, argv[2])


if __name__ == "__main__":
    main(sys.argv)
