#!/usr/bin/python3
"""Writes a library: two rows of book stacks (oak uprights, slatted shelves, books of random
widths), four luminous window panels 1 cm in front of the back wall, and N point lights, a
third in lamp clusters over the aisles and the rest a grid-like scatter 5 cm under the
ceiling, which the ceiling sees at grazing angles. Written as an unseen check after the
hidden side of the visibility coin (docs/LIGHTCUTS.md); its ceiling is where lightcuts
still leaves ~2% of pixels over 2%.

  /usr/bin/python3 scripts/gen_library.py SEED N OUT.ray
"""
import os
import sys

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
from gen_scenes import box, seeded_args, write_lines  # noqa: E402


def main(argv):
    rng, n, out = seeded_args(argv, __doc__)
    o = ["SBT-raytracer 1.0",
         "camera { position = (-3.6, 1.6, 4.2); look_at = (1.0, 1.1, -1.5); fov = 60; }",
         "material = { name = wall; diffuse = (0.7, 0.68, 0.64); }",
         "material = { name = floor; diffuse = (0.4, 0.32, 0.25); }",
         "material = { name = oak; diffuse = (0.45, 0.3, 0.18); }",
         "material = { name = book; diffuse = (0.5, 0.2, 0.15); }",
         "material = { name = glow; diffuse = (0, 0, 0); "
         "luminosity = { colour = (0.8, 0.85, 1); intensity = 6; density = 40; }; }"]
    o.append(box((0, -0.05, 0), (10, 0.1, 10), "floor"))
    o.append(box((0, 3.05, 0), (10, 0.1, 10), "wall"))   # ceiling, its underside at y = 3
    o.append(box((-5, 1.5, 0), (0.1, 3, 10), "wall"))
    o.append(box((0, 1.5, -5), (10, 3, 0.1), "wall"))
    for i in range(4):   # window panels, 1 cm in front of the back wall
        o.append("translate(%g, 1.9, -4.94, scale(0.9, 1.2, 1, square { material = glow; }))" % (-3 + 2 * i))
    for r in range(4):
        z = 1.5 - 1.4 * r
        for xs in (-2.5, 0.5):
            o.append(box((xs - 1.2, 1.1, z), (0.04, 2.2, 0.4), "oak"))
            o.append(box((xs + 1.2, 1.1, z), (0.04, 2.2, 0.4), "oak"))
            for h in range(5):
                y = 0.1 + 0.5 * h
                for sl in range(3):
                    o.append(box((xs, y, z - 0.13 + 0.13 * sl), (2.4, 0.025, 0.08), "oak"))
                if h < 4:
                    for _ in range(rng.randint(6, 14)):
                        o.append(box((xs - 1.1 + 2.2 * rng.random(), y + 0.16, z), (0.05, 0.28, 0.3), "book"))
    for k in range(n):
        if k % 3 == 0:   # lamps over the aisles
            z = 2.2 - 1.4 * rng.randint(0, 4)
            x = rng.choice((-1.0, 2.2, -4.0))
            p = (x + rng.gauss(0, 0.1), 2.6 + rng.gauss(0, 0.05), z + rng.gauss(0, 0.1))
        else:            # under the ceiling
            p = (rng.uniform(-4.8, 4.8), 2.95, rng.uniform(-4.8, 4.8))
        c = 5.0 / n
        o.append("point_light { position = (%.4f, %.4f, %.4f); colour = (%g, %g, %g); }" % (p + (c, c * 0.95, c * 0.85)))
    write_lines(out, o)


if __name__ == "__main__":
    main(sys.argv)
