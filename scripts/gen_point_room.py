#!/usr/bin/python3
"""Writes the "plain room" of issue 21: N omni point lights (default 100,000) in a closed room
with a few occluders. Seven tenths of the lights sit in 24 Gaussian clusters under the
ceiling (chandeliers), the rest are scattered through the upper half of the room. The total
power does not depend on N. A scene for measuring what one cut node costs against one
shadow ray: no object lights, no GI, nothing but point lights.

  /usr/bin/python3 scripts/gen_point_room.py [N] OUT.ray

N may be written 100000, 100k, 1M. Deterministic (a fixed seed). The room is bright: render
with --exposure -4 to look at it.
"""
import os
import random
import sys

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
from gen_scaling_scene import count_and_output  # noqa: E402
from gen_scenes import box, material, num  # noqa: E402

W, H, D = 12.0, 4.0, 12.0   # room: x in [-W/2, W/2], y in [0, H], z in [-D/2, D/2]
TOTAL_POWER = 400.0         # summed intensity of all lights (each channel)
CLUSTERS = 24


def main(argv):
    n, out = count_and_output(argv, 100000, __doc__)
    rng = random.Random(21)
    centres = [(rng.uniform(-W / 2 + 1, W / 2 - 1), rng.uniform(2.6, 3.5), rng.uniform(-D / 2 + 1, D / 2 - 1))
               for _ in range(CLUSTERS)]
    colours = [(rng.uniform(0.6, 1.0), rng.uniform(0.6, 1.0), rng.uniform(0.5, 1.0)) for _ in range(CLUSTERS)]
    wall = material(diffuse=(0.7, 0.7, 0.68))
    lines = ["SBT-raytracer 1.0\n",
             "camera { position = (0, 1.7, 5.8); viewdir = (0, -0.15, -1); updir = (0, 1, 0); fov = 70; }\n"]
    # The room: floor, ceiling and four walls as thin boxes.
    t = 0.1
    for c, s in (((0, -t / 2, 0), (W, t, D)), ((0, H + t / 2, 0), (W, t, D)),
                 ((-W / 2 - t / 2, H / 2, 0), (t, H, D)), ((W / 2 + t / 2, H / 2, 0), (t, H, D)),
                 ((0, H / 2, -D / 2 - t / 2), (W, H, t)), ((0, H / 2, D / 2 + t / 2), (W, H, t))):
        lines.append(box(c, s, wall))
    # A few occluders: a partition wall, two pillars, a table, a cabinet.
    grey = material(diffuse=(0.5, 0.5, 0.55), specular=(0.2, 0.2, 0.2), shininess=20)
    wood = material(diffuse=(0.55, 0.35, 0.2))
    lines.append(box((-2.5, 1.6, -1.5), (4.0, 3.2, 0.2), grey))
    lines.append(box((2.5, 2.0, -3.0), (0.5, 4.0, 0.5), grey))
    lines.append(box((3.0, 2.0, 1.5), (0.5, 4.0, 0.5), grey))
    lines.append(box((0.0, 0.75, 1.0), (2.0, 0.08, 1.0), wood))
    lines.append(box((-4.5, 1.0, 3.0), (1.0, 2.0, 2.0), wood))
    per = TOTAL_POWER / n
    for i in range(n):
        if i % 10 < 7:
            k = i % CLUSTERS
            cx, cy, cz = centres[k]
            x, y, z = rng.gauss(cx, 0.25), rng.gauss(cy, 0.15), rng.gauss(cz, 0.25)
            col = colours[k]
        else:
            x, y, z = rng.uniform(-W / 2, W / 2), rng.uniform(H / 2, H), rng.uniform(-D / 2, D / 2)
            col = (1.0, 1.0, 1.0)
        x = min(max(x, -W / 2 + 0.05), W / 2 - 0.05)
        y = min(max(y, 0.05), H - 0.05)
        z = min(max(z, -D / 2 + 0.05), D / 2 - 0.05)
        lines.append("point_light { position = (%s, %s, %s); colour = (%s, %s, %s); "
                     "constant_attenuation_coeff = 0.25; linear_attenuation_coeff = 0; "
                     "quadratic_attenuation_coeff = 1; }\n"
                     % (num(x, 3), num(y, 3), num(z, 3), num(per * col[0], 9), num(per * col[1], 9),
                        num(per * col[2], 9)))
    with open(out, "w") as f:
        f.writelines(lines)


if __name__ == "__main__":
    main(sys.argv)
