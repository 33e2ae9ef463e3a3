#!/usr/bin/python3
"""Writes a large OBJ mesh: an N x N grid of quads (2 N^2 triangles) on a wavy surface, for
measuring what loading and building a big mesh costs (its read, tinyobj's parse, Embree's
hierarchy, the occluder index) and checking that those phases show progress. N = 1000 gives
2M triangles in 73 MB. Deterministic; no materials (the renderer adds a default camera and
lights to an OBJ).

  /usr/bin/python3 scripts/gen_wavy_obj.py N OUT.obj
"""
import math
import sys


def main(argv):
    if len(argv) != 3:
        sys.exit(__doc__)
    n = int(argv[1])
    if n < 1:
        sys.exit("N must be at least 1")
    with open(argv[2], "w") as f:
        f.write(f"# wavy grid, {n} x {n} quads\n")
        for j in range(n + 1):
            for i in range(n + 1):
                x, z = i / n * 10 - 5, j / n * 10 - 5
                f.write(f"v {x:.5f} {0.3 * math.sin(3 * x) * math.cos(2 * z):.5f} {z:.5f}\n")
        for j in range(n):
            for i in range(n):
                a = j * (n + 1) + i + 1
                f.write(f"f {a} {a + 1} {a + n + 2}\nf {a} {a + n + 2} {a + n + 1}\n")


if __name__ == "__main__":
    main(sys.argv)
