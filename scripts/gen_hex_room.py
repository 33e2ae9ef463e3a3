#!/usr/bin/python3
"""Writes a hexagonal room (walls meeting at 120 degrees, one orange, one blue) lit by a
luminous sphere on a pedestal and a luminous panel leaning at a slant near a wall, with
20,000 VPL paths: every light lies on a surface that other surfaces face at a slant. Written
as an unseen check of the shadow-ray fix (docs/LIGHTCUTS.md, "Shadow rays that end behind
their light"), after it was made.

  /usr/bin/python3 scripts/gen_hex_room.py OUT.ray
"""
import math
import os
import sys

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
from gen_scenes import box, write_lines  # noqa: E402


def main(argv):
    if len(argv) != 2:
        raise SystemExit(__doc__)
    r, h = 4.0, 3.0
    o = ["SBT-raytracer 1.0",
         "camera { position = (0, 1.6, 3.2); look_at = (0, 1.1, 0); fov = 70; }",
         "instant_radiosity { vpls = 20000; bounces = 1; }",
         "material = { name = w; diffuse = (0.7, 0.68, 0.64); }",
         "material = { name = o; diffuse = (0.75, 0.45, 0.2); }",
         "material = { name = b; diffuse = (0.2, 0.35, 0.7); }"]
    c = [(r * math.cos(math.radians(60 * k + 30)), r * math.sin(math.radians(60 * k + 30))) for k in range(6)]
    for k in range(6):
        (x0, z0), (x1, z1) = c[k], c[(k + 1) % 6]
        m = {1: "o", 4: "b"}.get(k, "w")
        o.append(f"trimesh {{ material = {m}; points = (({x0:g},0,{z0:g}), ({x1:g},0,{z1:g}), ({x1:g},{h:g},{z1:g}), "
                 f"({x0:g},{h:g},{z0:g})); faces = ((0,2,1), (0,3,2)); }}")
    for y, flip in ((0.0, False), (h, True)):  # floor and ceiling: fans about the centre
        pts = ", ".join(f"({x:g},{y:g},{z:g})" for x, z in c) + f", (0,{y:g},0)"
        faces = ", ".join(f"(6,{k},{(k + 1) % 6})" if flip else f"(6,{(k + 1) % 6},{k})" for k in range(6))
        o.append(f"trimesh {{ material = w; points = ({pts}); faces = ({faces}); }}")
    o.append("translate(0.8, 1.4, -0.6, scale(0.35, sphere { material = { diffuse = (0,0,0); "
             "luminosity = { colour = (1, 0.9, 0.7); intensity = 8; density = 400; }; }; }))")
    o.append(box((0.8, 0.5, -0.6), (0.3, 1.0, 0.3), "w"))
    o.append("translate(-2.2, 1.3, -1.2, rotate(0,1,0,0.8, rotate(1,0,0,-0.5, scale(1.2, 0.6, 1, square { "
             "material = { diffuse = (0,0,0); luminosity = { colour = (0.8, 0.9, 1); intensity = 6; density = 300; }; "
             "}; }))))")
    o.append(box((-0.6, 0.45, 0.4), (0.9, 0.9, 0.6), "o", rot_y=28.6))
    write_lines(argv[1], o)


if __name__ == "__main__":
    main(sys.argv)
