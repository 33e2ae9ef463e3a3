#!/usr/bin/python3
"""Writes a room lit through venetian blinds, for checking lightcuts on an occlusion-heavy
scene nobody tuned to (issue 20): a window wall with a row of tilted slats, N point lights
outside spread over a large bright patch (sky and sun), a quarter of them in two table
lamps inside; a desk, a shelf and a chair stand in the striped light. Written during the
review of the coin and separation changes.

  /usr/bin/python3 scripts/gen_blinds.py SEED N OUT.ray
"""
import os
import sys

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
from gen_scenes import box, seeded_args, write_lines  # noqa: E402


def main(argv):
    rng, n, out = seeded_args(argv, __doc__)
    o = ["SBT-raytracer 1.0",
         "camera { position = (2.6, 1.5, -2.2); look_at = (-2.0, 1.0, 0.3); fov = 60; }",
         "material = { name = wall; diffuse = (0.75, 0.73, 0.7); }",
         "material = { name = floor; diffuse = (0.45, 0.33, 0.22); specular = (0.2, 0.2, 0.2); shininess = 40; }",
         "material = { name = slat; diffuse = (0.85, 0.85, 0.82); }",
         "material = { name = wood; diffuse = (0.5, 0.35, 0.2); }"]

    W, H, D = 6.0, 2.8, 6.0
    o.append(box((0, -0.05, 0), (W, 0.1, D), "floor").rstrip())
    o.append(box((0, H + 0.05, 0), (W, 0.1, D), "wall").rstrip())
    o.append(box((W / 2 + 0.05, H / 2, 0), (0.1, H, D), "wall").rstrip())
    o.append(box((0, H / 2, D / 2 + 0.05), (W, H, 0.1), "wall").rstrip())
    o.append(box((0, H / 2, -D / 2 - 0.05), (W, H, 0.1), "wall").rstrip())
    # The window wall at x = -3, an opening from y 0.8 to 2.4, z -1.5 to 1.5.
    o.append(box((-W / 2 - 0.05, 0.4, 0), (0.1, 0.8, D), "wall").rstrip())
    o.append(box((-W / 2 - 0.05, 2.6, 0), (0.1, 0.4, D), "wall").rstrip())
    o.append(box((-W / 2 - 0.05, 1.6, -2.25), (0.1, 1.6, 1.5), "wall").rstrip())
    o.append(box((-W / 2 - 0.05, 1.6, 2.25), (0.1, 1.6, 1.5), "wall").rstrip())
    y = 0.84
    while y < 2.4:                                           # slats tilted 30 degrees
        o.append(box((-W / 2 + 0.08, y, 0), (0.05, 0.004, 3.0), "slat", rot_z=-30).rstrip())
        y += 0.04
    o.append(box((-1.6, 0.74, -0.4), (0.8, 0.04, 1.6), "wood").rstrip())  # desk top
    for dx in (-0.35, 0.35):
        for dz in (-0.75, 0.75):
            o.append(box((-1.6 + dx, 0.36, -0.4 + dz), (0.04, 0.72, 0.04), "wood").rstrip())
    o.append(box((1.0, 0.9, -2.8), (1.6, 1.8, 0.35), "wood").rstrip())  # shelf
    o.append(box((-0.8, 0.45, 0.6), (0.45, 0.05, 0.45), "wood", rot_y=20).rstrip())  # chair seat
    o.append(box((-0.8, 0.85, 0.82), (0.45, 0.8, 0.04), "wood", rot_y=20).rstrip())  # chair back
    lamps = [(-1.9, 0.95, -0.9), (1.6, 1.9, -2.7)]
    for i in range(n):
        if i % 4 == 0:
            c = lamps[i % 8 // 4]
            p = (rng.gauss(c[0], 0.04), rng.gauss(c[1], 0.03), rng.gauss(c[2], 0.04))
            col, k = (1.0, 0.75, 0.45), 0.15
        elif i % 4 == 1:                                     # the sun: a small bright patch
            p = (rng.gauss(-9, 0.3), rng.gauss(6, 0.3), rng.gauss(1.5, 0.3))
            col, k = (1.0, 0.95, 0.85), 2.0
        else:                                                # the sky
            p = (rng.uniform(-14, -5), rng.uniform(1, 12), rng.uniform(-8, 8))
            col, k = (0.6, 0.75, 1.0), 1.0
        o.append("point_light { position = (%.4f, %.4f, %.4f); colour = (%g, %g, %g); }"
                 % (p[0], p[1], p[2], 150.0 / n * k * col[0], 150.0 / n * k * col[1], 150.0 / n * k * col[2]))
    write_lines(out, o)


if __name__ == "__main__":
    main(sys.argv)
