#!/usr/bin/python3
"""Writes a three-storey atrium seen from a gallery on the middle floor: floor slabs around
a central well (one triangle mesh, non-convex, with arcaded galleries), balustrades of thin
balusters along each gallery's edge, square piers, and N lights: pendant lamp clusters
hanging in the well, lamps under each gallery's ceiling, and a quarter of them spot lights
aimed down from the top floor. Most lights are hidden from most points by the slabs, the
piers and the balustrades, and the rest are seen through rows of thin gaps. Written as an
unseen check of issue 20 after its methods were chosen (docs/BENCHMARKS.md).

  /usr/bin/python3 scripts/gen_atrium.py SEED N OUT.ray
"""
import os
import sys

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
from gen_scenes import Mesh, box_mesh, light_text, seeded_args, write_lines  # noqa: E402

W, D = 10.0, 10.0      # the building's footprint
WELL = 2.2             # half-width of the central well
STOREY = 3.2
SLAB = 0.25
FLOORS = 3


def main(argv):
    rng, n, out = seeded_args(argv, __doc__)
    o = ["SBT-raytracer 1.0",
         "camera { position = (4.7, 4.8, 1.7); look_at = (-2.0, 3.4, -0.9); fov = 70; }",
         "material = { name = plaster; diffuse = (0.74, 0.72, 0.68); }",
         "material = { name = stone; diffuse = (0.52, 0.5, 0.46); specular = (0.15, 0.15, 0.15); shininess = 24; }",
         "material = { name = iron; diffuse = (0.12, 0.12, 0.13); specular = (0.4, 0.4, 0.4); shininess = 60; }"]
    slabs, piers, rails = Mesh(), Mesh(), Mesh()
    hw, hd = W / 2, D / 2
    # The ground floor, the outer walls and the roof.
    box_mesh(slabs, (-hw, -SLAB, -hd), (hw, 0, hd))
    top = FLOORS * STOREY
    box_mesh(slabs, (-hw, top, -hd), (hw, top + SLAB, hd))
    for lo, hi in (((-hw - 0.2, 0, -hd), (-hw, top, hd)), ((hw, 0, -hd), (hw + 0.2, top, hd)),
                   ((-hw, 0, -hd - 0.2), (hw, top, -hd)), ((-hw, 0, hd), (hw, top, hd + 0.2))):
        box_mesh(slabs, lo, hi)
    for f in range(1, FLOORS):
        y = f * STOREY
        # A slab with a square hole: four boxes around the well.
        box_mesh(slabs, (-hw, y - SLAB, -hd), (hw, y, -WELL))
        box_mesh(slabs, (-hw, y - SLAB, WELL), (hw, y, hd))
        box_mesh(slabs, (-hw, y - SLAB, -WELL), (-WELL, y, WELL))
        box_mesh(slabs, (WELL, y - SLAB, -WELL), (hw, y, WELL))
        # The balustrade: a handrail and balusters 0.12 apart on the well's four edges.
        for side in range(4):
            for k in range(int(2 * WELL / 0.12)):
                t = -WELL + 0.06 + 0.12 * k
                x, z = ((t, -WELL - 0.05), (t, WELL + 0.05), (-WELL - 0.05, t), (WELL + 0.05, t))[side]
                box_mesh(rails, (x - 0.015, y, z - 0.015), (x + 0.015, y + 0.95, z + 0.015))
        for lo, hi in (((-WELL - 0.1, y + 0.95, -WELL - 0.1), (WELL + 0.1, y + 1.0, -WELL)),
                       ((-WELL - 0.1, y + 0.95, WELL), (WELL + 0.1, y + 1.0, WELL + 0.1)),
                       ((-WELL - 0.1, y + 0.95, -WELL), (-WELL, y + 1.0, WELL)),
                       ((WELL, y + 0.95, -WELL), (WELL + 0.1, y + 1.0, WELL))):
            box_mesh(rails, lo, hi)
    # Piers at the well's corners and along the galleries, every storey.
    for f in range(FLOORS):
        y0 = f * STOREY
        for x in (-WELL - 0.3, -0.9, 0.9, WELL + 0.3):
            for z in (-WELL - 0.3, WELL + 0.3):
                for px, pz in ((x, z), (z, x)):
                    box_mesh(piers, (px - 0.2, y0, pz - 0.2), (px + 0.2, y0 + STOREY - SLAB, pz + 0.2))
    o.append(slabs.text("slabs", "plaster"))
    o.append(piers.text("piers", "stone"))
    o.append(rails.text("balustrades", "iron"))
    power = 40.0
    for k in range(n):
        u = rng.random()
        if u < 0.35:      # pendant clusters hanging in the well, at three heights
            cx, cz = rng.choice(((-0.9, -0.9), (0.9, 0.9), (-0.9, 0.9), (0.9, -0.9)))
            p = (cx + rng.gauss(0, 0.15), rng.choice((2.2, 5.2, 8.0)) + rng.gauss(0, 0.12), cz + rng.gauss(0, 0.15))
        else:             # lamps under each gallery's ceiling, in the ring around the well
            f = rng.randrange(FLOORS)
            while True:
                x, z = rng.uniform(-hw + 0.3, hw - 0.3), rng.uniform(-hd + 0.3, hd - 0.3)
                if max(abs(x), abs(z)) > WELL + 0.6:
                    break
            p = (x, (f + 1) * STOREY - SLAB - 0.15 - abs(rng.gauss(0, 0.1)), z)
        col = (rng.uniform(0.8, 1.0), rng.uniform(0.75, 0.95), rng.uniform(0.6, 0.85))
        i = power / n
        spot = (rng.uniform(-0.3, 0.3), rng.uniform(-0.3, 0.3), 45, 6) if rng.random() < 0.25 else None
        o.append(light_text(p, col, i, spot))
    write_lines(out, o)


if __name__ == "__main__":
    main(sys.argv)
