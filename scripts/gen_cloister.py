#!/usr/bin/python3
"""Writes a cloister walk for checking lightcuts on a scene nobody tuned to (issue 20): a
vaulted-ceiling corridor whose one side is an arcade of square piers open to a courtyard,
the other a wall with deep niches. The courtyard's light comes through the arcade from a
field of point lights above it (a low sun's bounce, as many small lights); inside, each bay
has a lamp cluster, and each niche a candle cluster that only points near it see. Written
after the reconstruction probes' thresholds were set, and not tuned to them.

  /usr/bin/python3 scripts/gen_cloister.py [N] OUT.ray

N (default 12000) is the number of lights; deterministic (a fixed seed). Add GI with
`--vpls`.
"""
import os
import random
import sys

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
from gen_scaling_scene import count_and_output  # noqa: E402
from gen_scenes import box, material, num  # noqa: E402

L, W, H = 24.0, 4.0, 4.5   # corridor: z in [-L/2, L/2], x in [0, W], y in [0, H]
BAYS = 8


def light(x, y, z, c):
    return ("point_light { position = (%s, %s, %s); colour = (%s, %s, %s); constant_attenuation_coeff = 0.3; "
            "linear_attenuation_coeff = 0; quadratic_attenuation_coeff = 1; }\n"
            % (num(x, 3), num(y, 3), num(z, 3), num(c[0], 9), num(c[1], 9), num(c[2], 9)))


def main(argv):
    n, out = count_and_output(argv, 12000, __doc__)
    rng = random.Random(1207)
    stone = material(diffuse=(0.62, 0.58, 0.5))
    floor = material(diffuse=(0.45, 0.4, 0.35), specular=(0.1, 0.1, 0.1), shininess=30)
    grass = material(diffuse=(0.3, 0.45, 0.2))
    lines = ["SBT-raytracer 1.0\n",
             "camera { position = (2.6, 1.6, 11.5); viewdir = (-0.12, -0.05, -1); updir = (0, 1, 0); fov = 60; }\n"]
    t = 0.2
    lines.append(box((W / 2, -t / 2, 0), (W, t, L), floor))               # corridor floor
    lines.append(box((W / 2, H + t / 2, 0), (W + 0.4, t, L), stone))       # ceiling
    lines.append(box((-1.0 - t / 2, H / 2, 0), (t, H, L), stone))         # back wall behind the niches
    lines.append(box((W / 2, H / 2, -L / 2 - t / 2), (W + 2, H, t), stone))  # far end
    lines.append(box((W / 2, H / 2, L / 2 + t / 2), (W + 2, H, t), stone))   # near end (behind the camera)
    lines.append(box((W + 6, -t / 2, 0), (12, t, L + 8), grass))          # courtyard
    lines.append(box((W + 12, H, 0), (t, 2 * H, L + 8), stone))          # courtyard's far wall
    bay = L / BAYS
    wall_pieces = []
    for b in range(BAYS + 1):
        z = -L / 2 + b * bay
        lines.append(box((W, H / 2, z), (0.6, H, 0.6), stone))              # arcade piers
        lines.append(box((0.5 / 2 - 1.0 + 0.5, H / 2, z), (1.0, H, 0.9), stone))  # walls between niches
        wall_pieces.append(z)
    lines.append(box((W, H - 0.4, 0), (0.6, 0.8, L), stone))              # the arcade's lintel
    for b in range(BAYS):
        zc = -L / 2 + (b + 0.5) * bay
        lines.append(box((W / 2, H - 0.15, zc), (W, 0.3, 0.25), stone))     # transverse rib
        lines.append(box((-0.3, 0.45, zc), (1.2, 0.9, 1.6), stone))        # a bench in each niche
    # Lights: 55% over the courtyard, 30% in lamp clusters under each bay, 15% as candles in
    # the niches.
    total = 300.0
    per = total / n
    for i in range(n):
        r = i % 20
        if r < 11:
            x, y, z = rng.uniform(W + 2, W + 11), rng.uniform(5.5, 9.0), rng.uniform(-L / 2, L / 2)
            c = (1.0, 0.95, 0.85)
            s = 1.6
        elif r < 17:
            b = i % BAYS
            zc = -L / 2 + (b + 0.5) * bay
            x, y, z = rng.gauss(W / 2, 0.15), rng.gauss(H - 1.0, 0.1), rng.gauss(zc, 0.15)
            c = (1.0, 0.8, 0.55)
            s = 0.8
        else:
            b = i % BAYS
            zc = -L / 2 + (b + 0.5) * bay
            x, y, z = rng.uniform(-0.8, -0.2), rng.uniform(1.0, 1.4), rng.uniform(zc - 0.5, zc + 0.5)
            c = (1.0, 0.6, 0.3)
            s = 0.3
        lines.append(light(x, y, z, tuple(per * s * k for k in c)))
    with open(out, "w") as f:
        f.writelines(lines)


if __name__ == "__main__":
    main(sys.argv)
