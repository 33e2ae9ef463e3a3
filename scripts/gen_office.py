#!/usr/bin/python3
"""Writes an open-plan office for accuracy checks on a scene nobody tuned to (issues 20 and
21; written after the clear clusters were): two rooms joined by two doorways in a partition
wall. The left room: twelve desks with monitors under six luminous ceiling panels (object
lights). The right room: filing cabinets, two pillars and six pendant clusters of 400 point
lights each. Instant radiosity (6,000 VPL paths, one bounce) lights the rest.

  /usr/bin/python3 scripts/gen_office.py OUT.ray

Deterministic (a fixed seed).
"""
import os
import random
import sys
sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
from gen_scenes import box, cylinder_y, material, num  # noqa: E402
rng = random.Random(4242)
L = ["SBT-raytracer 1.0\n",
     "camera { position = (-7.5, 1.6, 5.5); look_at = (3, 1.0, -3); aspectratio = 1.5; fov = 62; }\n"]
wall = material(diffuse=(0.72, 0.7, 0.66))
floor = material(diffuse=(0.35, 0.33, 0.3), specular=(0.15, 0.15, 0.15), shininess=30)
desk = material(diffuse=(0.5, 0.38, 0.25), specular=(0.2, 0.2, 0.2), shininess=15)
metal = material(diffuse=(0.3, 0.3, 0.32), specular=(0.5, 0.5, 0.5), shininess=60)
panel = material(diffuse=(0.9, 0.9, 0.9), luminosity=dict(colour=(1.0, 0.95, 0.85), intensity=2.0, density=300))
W, H, D = 18.0, 3.0, 14.0
t = 0.1
for c, s in (((0, -t/2, 0), (W, t, D)), ((0, H + t/2, 0), (W, t, D)), ((-W/2 - t/2, H/2, 0), (t, H, D)),
             ((W/2 + t/2, H/2, 0), (t, H, D)), ((0, H/2, -D/2 - t/2), (W, H, t)), ((0, H/2, D/2 + t/2), (W, H, t))):
    L.append(box(c, s, floor if c[1] < 0 else wall))
# a glass-less partition wall with two doorways at x = 2
for z0, z1 in ((-7, -4.5), (-3.3, 2.0), (3.2, 7)):
    L.append(box((2, H/2, (z0 + z1)/2), (0.15, H, z1 - z0), wall))
L.append(box((2, H - 0.4, -3.9), (0.15, 0.8, 1.2), wall)); L.append(box((2, H - 0.4, 2.6), (0.15, 0.8, 1.2), wall))
# rows of desks with monitors, and filing cabinets
for i in range(4):
    for j in range(3):
        x, z = -7 + i * 2.2, -5 + j * 3.5
        L.append(box((x, 0.74, z), (1.6, 0.04, 0.8), desk))
        for dx in (-0.75, 0.75):
            L.append(box((x + dx, 0.37, z), (0.05, 0.72, 0.75), metal))
        L.append(box((x, 1.0, z - 0.25), (0.55, 0.35, 0.03), metal))
for k in range(5):
    L.append(box((8.3, 0.65, -6 + k * 1.2), (0.6, 1.3, 0.5), metal, rot_y=rng.uniform(-5, 5)))
L.append(cylinder_y((5.5, 0, -2), 0.25, H, metal)); L.append(cylinder_y((5.5, 0, 3), 0.25, H, metal))
# ceiling light panels (object lights) in the left room, recessed just below the ceiling
for i in range(3):
    for j in range(2):
        L.append(box((-6 + i * 3.5, H - 0.03, -3 + j * 5), (1.2, 0.04, 0.6), panel))
# many point lights in the right room: pendant clusters
for c in range(6):
    cx, cz = rng.uniform(3, 8.5), rng.uniform(-6, 6)
    for _ in range(400):
        x, y, z = rng.gauss(cx, 0.15), rng.gauss(2.4, 0.08), rng.gauss(cz, 0.15)
        L.append("point_light { position = (%s, %s, %s); colour = (%s, %s, %s); constant_attenuation_coeff = 0.3; linear_attenuation_coeff = 0; quadratic_attenuation_coeff = 1; }\n"
                 % (num(x, 3), num(y, 3), num(z, 3), num(0.004, 5), num(0.0036, 5), num(0.003, 5)))
L.append("instant_radiosity { vpls = 6000; bounces = 1; }\n")
open(sys.argv[1], 'w').writelines(L)
