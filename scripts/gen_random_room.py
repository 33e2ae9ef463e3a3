#!/usr/bin/python3
"""Writes a random room for accuracy checks on scenes nobody tuned to (issues 20 and 21): a
closed room of random size with 2-4 partitions, 6-14 boxes (some glossy, rotated), 2-5
pillars and a glossy floor, lit by N lights: six tenths in 8-30 Gaussian clusters under the
ceiling, the rest anywhere in the room (some close to surfaces or inside boxes), a share of
them spot lights (cone 50 degrees, exponent 4, pointing down at random tilts). Each seed
gives another scene; nothing in the renderer is tuned to any of them.

  /usr/bin/python3 scripts/gen_random_room.py SEED N OUT.ray [SPOT_SHARE]

SPOT_SHARE defaults to 0.25. The room is bright: render with --exposure -1.5 to look at it.
"""
import os
import random
import sys

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
from gen_scenes import box, light_text, material, num, room_shell  # noqa: E402

TOTAL_POWER = 300.0  # summed intensity of the point lights (each channel), whatever N


def main(argv):
    if len(argv) not in (4, 5):
        sys.exit(__doc__)
    seed, n, out = int(argv[1]), int(argv[2]), argv[3]
    spot_share = float(argv[4]) if len(argv) == 5 else 0.25
    rng = random.Random(seed)
    W, H, D = rng.uniform(8, 14), rng.uniform(3, 5), rng.uniform(8, 14)
    L = ["SBT-raytracer 1.0\n",
         f"camera {{ position = ({num(-W * 0.42)}, {num(H * 0.55)}, {num(D * 0.45)}); "
         f"look_at = ({num(W * 0.2)}, {num(H * 0.3)}, {num(-D * 0.3)}); aspectratio = 1.5; fov = 60; }}\n"]
    wall = material(diffuse=(0.7, 0.68, 0.65))
    floor = material(diffuse=(0.45, 0.4, 0.35), specular=(0.3, 0.3, 0.3), shininess=40)
    L += room_shell(W, H, D, floor, wall)
    rgb = lambda lo, hi: tuple(rng.uniform(lo, hi) for _ in range(3))  # noqa: E731
    for _ in range(rng.randint(2, 4)):  # partitions, with gaps around them
        x = rng.uniform(-W / 3, W / 3)
        length = rng.uniform(D * 0.3, D * 0.6)
        z = rng.uniform(-D / 2 + length / 2, D / 2 - length / 2)
        L.append(box((x, H * 0.4, z), (0.15, H * 0.8, length), material(diffuse=rgb(0.3, 0.8))))
    for _ in range(rng.randint(6, 14)):
        s = (rng.uniform(0.3, 1.5), rng.uniform(0.3, 2.0), rng.uniform(0.3, 1.5))
        glossy = rng.random() < 0.4
        L.append(box((rng.uniform(-W / 2 + 1, W / 2 - 1), s[1] / 2, rng.uniform(-D / 2 + 1, D / 2 - 1)), s,
                     material(diffuse=rgb(0.2, 0.9), specular=(0.2, 0.2, 0.2) if glossy else None,
                              shininess=20 if glossy else None),
                     rot_y=rng.uniform(0, 3.14159)))
    for _ in range(rng.randint(2, 5)):  # pillars: unit cylinders along z, turned upright
        L.append(f"translate({num(rng.uniform(-W / 2 + 1, W / 2 - 1))}, 0, {num(rng.uniform(-D / 2 + 1, D / 2 - 1))}, "
                 f"scale(0.25, {num(H)}, 0.25, rotate(1, 0, 0, -1.5708, "
                 "cylinder { material = { diffuse = (0.6, 0.6, 0.6); }; })))\n")
    centres = [(rng.uniform(-W / 2 + 0.5, W / 2 - 0.5), rng.uniform(H * 0.6, H * 0.95),
                rng.uniform(-D / 2 + 0.5, D / 2 - 0.5)) for _ in range(rng.randint(8, 30))]
    for _ in range(n):
        if rng.random() < 0.6:
            c = rng.choice(centres)
            r = rng.uniform(0.1, 0.6)
            p = (c[0] + rng.gauss(0, r), min(H - 0.05, c[1] + rng.gauss(0, r * 0.5)), c[2] + rng.gauss(0, r))
        else:
            p = (rng.uniform(-W / 2 + 0.1, W / 2 - 0.1), rng.uniform(0.3, H - 0.1), rng.uniform(-D / 2 + 0.1, D / 2 - 0.1))
        col = rgb(0.5, 1.0)
        i = TOTAL_POWER / n
        spot = (rng.uniform(-0.5, 0.5), rng.uniform(-0.5, 0.5), 50, 4) if rng.random() < spot_share else None
        L.append(light_text(p, col, i, spot) + "\n")
    tmp = out + ".tmp"
    with open(tmp, "w") as f:
        f.write("".join(L))
    os.replace(tmp, out)


if __name__ == "__main__":
    main(sys.argv)
