#!/usr/bin/python3
"""Writes a theatre seen from its balcony: raked stalls of seats, a stage behind a proscenium
wall with side curtains, a balustrade of 60 thin balusters, and N lights: about a third
spots on a truss over the stalls, aimed at random points of the stage with random cones of
8-25 degrees (each its own cone: one mixed tree), and footlights at the stage's lip, sconces
on the side walls and a chandelier of point lights. Written as an unseen check of spot
lights under reconstruction cuts (docs/LIGHTCUTS.md, "Spot clusters the samples summed"):
with 8,000 lights at 512x512 a block pattern 2-3.5% off on the stage and its curtain.

  /usr/bin/python3 scripts/gen_theatre.py SEED N OUT.ray   (the check: 404 8000)
"""
import os
import sys

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
from gen_scenes import box, cylinder_y, seeded_args, sphere, write_lines  # noqa: E402

def main(argv):
    rng, n, out = seeded_args(argv, __doc__)
    o = ["SBT-raytracer 1.0",
         "camera { position = (3.0, 5.4, 9.4); look_at = (-0.5, 0.8, -4.0); fov = 62; }",
         "material = { name = wall; diffuse = (0.55, 0.2, 0.18); }",
         "material = { name = cream; diffuse = (0.75, 0.7, 0.6); }",
         "material = { name = floor; diffuse = (0.35, 0.25, 0.18); specular = (0.1, 0.1, 0.1); shininess = 30; }",
         "material = { name = seat; diffuse = (0.5, 0.08, 0.08); }",
         "material = { name = stage; diffuse = (0.3, 0.22, 0.15); }",
         "material = { name = gold; diffuse = (0.6, 0.5, 0.2); specular = (0.3, 0.25, 0.1); shininess = 40; }",
         "material = { name = curtain; diffuse = (0.45, 0.05, 0.06); }"]
    # hall: x in [-6, 6], z in [-8, 10], y in [0, 7]
    o.append(box((0, -0.05, 1), (12, 0.1, 18), "floor"))
    o.append(box((0, 7.05, 1), (12, 0.1, 18), "cream"))
    o.append(box((-6.05, 3.5, 1), (0.1, 7, 18), "wall"))
    o.append(box((6.05, 3.5, 1), (0.1, 7, 18), "wall"))
    o.append(box((0, 3.5, 10.05), (12, 7, 0.1), "wall"))
    o.append(box((0, 3.5, -8.05), (12, 7, 0.1), "curtain"))
    # stage z in [-8, -3], height 1
    o.append(box((0, 0.5, -5.5), (12, 1, 5), "stage"))
    # proscenium wall at z = -3 with an opening x in [-4, 4], y in [1, 5.5]
    o.append(box((-5, 3.5, -3), (2, 7, 0.4), "cream"))
    o.append(box((5, 3.5, -3), (2, 7, 0.4), "cream"))
    o.append(box((0, 6.25, -3), (8, 1.5, 0.4), "cream"))
    # side curtains on stage
    for s in (-1, 1):
        o.append(box((s * 3.6, 3.0, -3.5), (0.8, 4, 0.15), "curtain"))
    # raked stalls: rows z from -1 to 6, rising
    for r in range(9):
        z = -1.0 + 0.85 * r
        yb = 0.12 * r
        o.append(box((0, yb / 2, z + 0.2), (12, yb + 0.001, 0.85), "floor"))
        for c in range(-7, 8):
            if c == 0:
                continue  # aisle
            x = 0.7 * c
            o.append(box((x, yb + 0.25, z), (0.55, 0.5, 0.5), "seat"))
            o.append(box((x, yb + 0.6, z + 0.25), (0.55, 0.7, 0.08), "seat"))
    # balcony: slab at y = 3.2 from z = 6.5 to 10, balustrade at z = 6.5
    o.append(box((0, 3.1, 8.25), (12, 0.2, 3.5), "cream"))
    o.append(box((0, 4.05, 6.5), (12, 0.08, 0.12), "gold"))
    for k in range(60):
        x = -5.9 + k * (11.8 / 59)
        o.append(cylinder_y((x, 3.2, 6.5), 0.035, 0.82, "gold"))
    # lights
    for k in range(n):
        u = rng.random()
        if u < 0.35:   # spots on a truss over the stalls at y = 6.4, z in {0, 2}, aimed at the stage
            p = (rng.uniform(-5, 5), 6.4, rng.choice((0.0, 2.0)) + rng.gauss(0, 0.05))
            tgt = (rng.uniform(-3.5, 3.5), 1.0, rng.uniform(-7, -3.5))
            d = (tgt[0] - p[0], tgt[1] - p[1], tgt[2] - p[2])
            dx, dz = d[0] / -d[1], d[2] / -d[1]
            cone = rng.uniform(8, 25)
            col = rng.choice(((1, 0.9, 0.7), (0.7, 0.8, 1), (1, 0.6, 0.6)))
            c3 = ", ".join("%g" % (v * 150.0 / n) for v in col)
            o.append("spot_light { position = (%.4f, %.4f, %.4f); direction = (%.4f, -1, %.4f); colour = (%s); cone_angle = %.3f; exponent = 2; }"
                     % (p + (dx, dz, c3, cone)))
            continue
        if u < 0.5:    # footlights along the stage lip
            p = (rng.uniform(-3.8, 3.8), 1.08, -3.25 + rng.gauss(0, 0.02))
            c = 8.0 / n
        elif u < 0.7:  # sconces on the side walls
            side = rng.choice((-5.85, 5.85))
            z = rng.choice((-1.5, 1.5, 4.5, 8.0))
            y = 2.4 if z < 6 else 5.2
            p = (side, y + rng.gauss(0, 0.06), z + rng.gauss(0, 0.06))
            c = 8.0 / n
        else:          # chandelier: a ball of lights hanging at (0, 5.3, 2.5)
            while True:
                q = (rng.uniform(-1, 1), rng.uniform(-1, 1), rng.uniform(-1, 1))
                if sum(x * x for x in q) <= 1:
                    break
            p = (0.7 * q[0], 5.3 + 0.4 * q[1], 2.5 + 0.7 * q[2])
            c = 16.0 / n
        o.append("point_light { position = (%.4f, %.4f, %.4f); colour = (%g, %g, %g); }" % (p + (c, c * 0.92, c * 0.8)))
    o.append(sphere((0, 5.3, 2.5), 0.15, "gold"))
    write_lines(out, o)

if __name__ == "__main__":
    main(sys.argv)
