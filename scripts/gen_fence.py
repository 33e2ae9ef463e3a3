#!/usr/bin/python3
"""Writes a fence of thin upright boards standing on a floor, seen from above, lit by N low
point lights: the boards' side faces are seen nearly edge on, the case antialiasing under
reconstruction cuts does not solve (docs/LIGHTCUTS.md, "Sub-samples cut off from their
samples"). Defaults: 300 lights, 25 boards 0.06 apart (6.2% of pixels over 2% at 512 x 512).

  /usr/bin/python3 scripts/gen_fence.py [N [PITCH [BOARDS]]] OUT.ray
"""
import random
import sys


def main(argv):
    if len(argv) < 2 or len(argv) > 5:
        sys.exit(__doc__)
    args = argv[1:-1]
    n = int(args[0]) if len(args) > 0 else 300
    pitch = float(args[1]) if len(args) > 1 else 0.06
    boards = int(args[2]) if len(args) > 2 else 25
    rng = random.Random(11)
    t = "SBT-raytracer 1.0\ncamera { position = (0, 3, 0.01); look_at = (0, 0, 0); fov = 45; }\n"

    def box(x, y, z, sx, sy, sz, m):
        return "translate(%g,%g,%g, scale(%g,%g,%g, box { material = %s; }))\n" % (x, y, z, sx, sy, sz, m)

    t += box(0, -0.05, 0, 4, 0.1, 4, "{ diffuse = (0.6, 0.6, 0.6); }")
    for i in range(boards):
        t += box(-pitch * (boards - 1) / 2 + pitch * i, 0.1, 0, pitch / 5, 0.2, 3, "{ diffuse = (0.3, 0.3, 0.3); }")
    for _ in range(n):
        t += "point_light { position = (%g,%g,%g); colour = (0.01,0.01,0.01); }\n" % (
            rng.uniform(-2, 2), rng.uniform(0.1, 0.6), rng.uniform(-1.5, 1.5))
    with open(argv[-1], "w") as f:
        f.write(t)


if __name__ == "__main__":
    main(sys.argv)
