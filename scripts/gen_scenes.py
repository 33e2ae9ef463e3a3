#!/usr/bin/python3
"""Generates the benchmark scenes of docs/BENCHMARKS.md (issue 7) under scenes/:

  cornell_water.ray              the Cornell box (scenes/cornell_box.ray, its object-light
                                 ceiling and instant_radiosity block) with a wavy, refractive
                                 water surface (index 1.33) filling its lower part
  church.ray                     a gothic church interior: nave, aisles, columns, pointed
                                 arcades, a pointed barrel vault with ribs, luminous stained
                                 glass windows (a textured rose window) and hanging lamps
  roman_hall.ray                 a Roman hall: colonnades with round arches, a coffered barrel
                                 vault with luminous oculi, bronze lamps, a lunette window
  rooms.ray                      six rooms joined by doorways, each lit by a ceiling panel of
                                 its own colour, with furniture: most lights hidden from most
                                 points (issue 20)
  column_hall.ray                a hall of 6 x 4 columns under beams, 35 hanging lamps and seven
                                 luminous windows: the columns hide most lamps (issue 20)
  green_light_emitter_dense.ray  the shipped emitter scenes with 25x the light density
  luminous_object_dense.ray      (tens of thousands of lights: where Lightcuts matters)
  green_light_emitter_seed.ray   the emitter scene with the seed's light count: 12 lights
                                 (the seed's brute force evaluated 11.8 lights per pixel)

plus their textures under scenes/textures/. Every scene has an instant_radiosity block;
render with --gi off for direct light only. Deterministic: running it again rewrites the
same files.

  /usr/bin/python3 scripts/gen_scenes.py [--out DIR] [NAME ...]

The helpers below (materials, meshes, arches, vaults) are also used by
scripts/gen_scaling_scene.py.
"""
import argparse
import math
import os
import random
import re
import sys

HERE = os.path.dirname(os.path.abspath(__file__))
ROOT = os.path.dirname(HERE)


def num(v, digits=5):
    """A float in short form: `digits` decimals, no exponent, no trailing zeros."""
    if abs(v) < 0.5 * 10 ** -digits:
        return "0"
    s = f"{v:.{digits}f}".rstrip("0").rstrip(".")
    return s if s not in ("-0", "") else "0"


def vec(v, digits=5):
    return "(" + ", ".join(num(x, digits) for x in v) + ")"


def material(name=None, diffuse=None, specular=None, shininess=None, reflective=None,
             transmissive=None, index=None, emissive=None, ambient=None, luminosity=None):
    """A material block's text. luminosity: dict(colour=, intensity=, density=, map=)."""
    parts = []
    if name:
        parts.append(f"name = {name};")
    for key, val in (("emissive", emissive), ("ambient", ambient), ("diffuse", diffuse),
                     ("specular", specular), ("reflective", reflective),
                     ("transmissive", transmissive)):
        if val is not None:
            parts.append(f"{key} = {val if isinstance(val, str) else vec(val)};")
    if shininess is not None:
        parts.append(f"shininess = {num(shininess)};")
    if index is not None:
        parts.append(f"index = {num(index)};")
    if luminosity:
        lum = luminosity
        col = f'map("{lum["map"]}")' if "map" in lum else vec(lum.get("colour", (1, 1, 1)))
        parts.append("luminosity = { colour = %s; intensity = %s; density = %s; };"
                     % (col, num(lum["intensity"]), num(lum["density"])))
    return "{ " + " ".join(parts) + " }"


def declare(name, **kw):
    """A top-level named material declaration."""
    return "material = " + material(name=name, **kw) + ";\n"


class Mesh:
    """A growing triangle mesh: points, optional per-point normals and uvs, triangles."""

    def __init__(self):
        self.p, self.n, self.uv, self.f = [], [], [], []
        self._index = {}

    def point(self, p, n=None, uv=None):
        """Adds a point (one without normal or uv is shared with an equal earlier one)."""
        if n is None and uv is None and not self.n and not self.uv:
            key = tuple(round(x, 5) for x in p)
            if key in self._index:
                return self._index[key]
            self._index[key] = len(self.p)
        self.p.append(tuple(p))
        if n is not None:
            self.n.append(tuple(n))
        if uv is not None:
            self.uv.append(tuple(uv))
        return len(self.p) - 1

    def tri(self, a, b, c):
        self.f.append((a, b, c))

    def quad(self, a, b, c, d):
        self.f.append((a, b, c))
        self.f.append((a, c, d))

    def add_quad(self, a, b, c, d):
        """Four new points (facing along (b - a) x (c - a))."""
        i = [self.point(x) for x in (a, b, c, d)]
        self.quad(*i)

    def extend(self, other):
        off = len(self.p)
        if not self.n and not self.uv and not other.n and not other.uv:
            remap = [self.point(p) for p in other.p]
            self.f += [(remap[a], remap[b], remap[c]) for a, b, c in other.f]
            return self
        self.p += other.p
        self.n += other.n
        self.uv += other.uv
        self.f += [(a + off, b + off, c + off) for a, b, c in other.f]
        return self

    def area(self):
        total = 0.0
        for a, b, c in self.f:
            pa, pb, pc = self.p[a], self.p[b], self.p[c]
            u = [pb[i] - pa[i] for i in range(3)]
            v = [pc[i] - pa[i] for i in range(3)]
            cx = (u[1] * v[2] - u[2] * v[1], u[2] * v[0] - u[0] * v[2], u[0] * v[1] - u[1] * v[0])
            total += 0.5 * math.sqrt(sum(x * x for x in cx))
        return total

    def text(self, name, mat, per_line=4, gennormals=False, digits=5):
        out = [f"trimesh {{\n  name = \"{name}\";\n  material = {mat};\n"]
        if gennormals:
            out.append("  gennormals;\n")

        def block(key, items, fmt):
            out.append(f"  {key} = (")
            for i, it in enumerate(items):
                if i % per_line == 0:
                    out.append("\n    ")
                out.append(fmt(it) + ("," if i + 1 < len(items) else ""))
                if i % per_line != per_line - 1 and i + 1 < len(items):
                    out.append(" ")
            out.append(");\n")

        block("points", self.p, lambda v: vec(v, digits))
        if self.n:
            assert len(self.n) == len(self.p)
            block("normals", self.n, lambda v: vec(v, 4))
        if self.uv:
            assert len(self.uv) == len(self.p)
            block("texture_uv", self.uv, lambda t: "(" + num(t[0]) + ", " + num(t[1]) + ")")
        block("faces", self.f, lambda t: "(%d, %d, %d)" % t)
        out.append("}\n")
        return "".join(out)


def seeded_args(argv, doc):
    """The arguments SEED N OUT of a random scene's generator: random.Random(SEED), N and OUT;
    exits with `doc` (its usage) for any other count."""
    if len(argv) != 4:
        sys.exit(doc)
    return random.Random(int(argv[1])), int(argv[2]), argv[3]


def write_lines(path, lines):
    """Writes `lines` to `path`, one per line."""
    with open(path, "w") as f:
        f.write("\n".join(lines) + "\n")


def light_text(p, col, power, spot=None):
    """A point light at p of colour col times power, or with spot = (dx, dz, cone_angle,
    exponent) a spot light aimed at (dx, -1, dz), of three times that colour."""
    pos = f"position = ({num(p[0])}, {num(p[1])}, {num(p[2])});"
    if spot:
        c3 = ", ".join(num(v * power * 3, 7) for v in col)
        return (f"spot_light {{ {pos} direction = ({num(spot[0])}, -1, {num(spot[1])}); colour = ({c3}); "
                f"cone_angle = {spot[2]}; exponent = {spot[3]}; }}")
    c3 = ", ".join(num(v * power, 7) for v in col)
    return f"point_light {{ {pos} colour = ({c3}); }}"


def box(center, size, mat, rot_y=0.0, rot_z=0.0):
    """An axis-aligned box quadric, or one rotated about z, then about y (radians, as the .ray
    format's rotate takes them: callers that wrote degrees get some other turn)."""
    s = f"scale({num(size[0])}, {num(size[1])}, {num(size[2])}, box {{ material = {mat}; }})"
    if rot_z:
        s = f"rotate(0, 0, 1, {num(rot_z)}, {s})"
    if rot_y:
        s = f"rotate(0, 1, 0, {num(rot_y)}, {s})"
    return f"translate({num(center[0])}, {num(center[1])}, {num(center[2])}, {s})\n"


def room_shell(W, H, D, floor, wall):
    """A closed room of W x H x D (x, y, z) around the origin, standing on y = 0: the floor,
    the ceiling and four walls as boxes 0.1 thick outside it, in that order."""
    out = [box((0, -0.05, 0), (W, 0.1, D), floor), box((0, H + 0.05, 0), (W, 0.1, D), wall)]
    for x in (-1, 1):
        out.append(box((x * (W / 2 + 0.05), H / 2, 0), (0.1, H, D), wall))
    for z in (-1, 1):
        out.append(box((0, H / 2, z * (D / 2 + 0.05)), (W, H, 0.1), wall))
    return out


def cylinder_y(base, radius, height, mat, capped=True):
    """A cylinder standing on `base`, along +y."""
    cap = "" if capped else " capped = false;"
    return (f"translate({num(base[0])}, {num(base[1])}, {num(base[2])}, rotate(1, 0, 0, -1.570796327, "
            f"scale({num(radius)}, {num(radius)}, {num(height)}, cylinder {{{cap} material = {mat}; }})))\n")


def sphere(center, radius, mat, name=None):
    nm = f' name = "{name}";' if name else ""
    return (f"translate({num(center[0])}, {num(center[1])}, {num(center[2])}, "
            f"scale({num(radius)}, sphere {{{nm} material = {mat}; }}))\n")


# --- profiles -------------------------------------------------------------------------

def arch_curve(a, b, spring, kind, k=16, radius=None):
    """Points (s, y) of an arch over the span [a, b] springing at height `spring`, from a to b.
    kind 'round': a semicircle; 'pointed': two arcs of `radius` (default the span: equilateral)
    centred on the springing line."""
    span = b - a
    pts = []
    if kind == "round":
        r, c = span / 2, (a + b) / 2
        for i in range(k + 1):
            t = math.pi * (1 - i / k)
            pts.append((c + r * math.cos(t), spring + r * math.sin(t)))
        return pts
    r = radius or span
    # left arc: centre (a + r), from angle pi to the apex; right arc: centre (b - r) mirrored
    apex_cos = ((a + b) / 2 - (a + r)) / r
    t_apex = math.acos(max(-1.0, min(1.0, apex_cos)))
    h = k // 2
    for i in range(h + 1):
        t = math.pi + (t_apex - math.pi) * i / h
        pts.append((a + r + r * math.cos(t), spring + r * math.sin(t)))
    for i in range(h - 1, -1, -1):
        s, y = pts[i]
        pts.append((a + b - s, y))
    return pts


def arch_apex(span, kind, radius=None):
    if kind == "round":
        return span / 2
    r = radius or span
    return math.sqrt(max(r * r - (r - span / 2) ** 2, 0.0))


def arch_wall(x0, thick, a, b, spring, top, kind, k=16, radius=None, axis="z"):
    """A wall of thickness `thick` centred on the plane x = x0 (axis 'z': the span runs along
    z) or z = x0 (axis 'x': along x), pierced by one arch over [a, b]: both faces of the
    spandrels up to `top`, and the arch's soffit."""
    m = Mesh()
    curve = arch_curve(a, b, spring, kind, k, radius)

    def P(off, s, y):
        return (x0 + off, y, s) if axis == "z" else (s, y, x0 + off)

    for off in (-thick / 2, thick / 2):
        for (s0, y0), (s1, y1) in zip(curve, curve[1:]):
            m.add_quad(P(off, s0, y0), P(off, s1, y1), P(off, s1, top), P(off, s0, top))
    for (s0, y0), (s1, y1) in zip(curve, curve[1:]):
        m.add_quad(P(-thick / 2, s0, y0), P(thick / 2, s0, y0), P(thick / 2, s1, y1), P(-thick / 2, s1, y1))
    return m


def polygon_fan(poly2d, origin, u, v, centre=None, uv_of=None):
    """A flat polygon (CCW in (u, v)), fanned from `centre` (default: the vertex mean), in
    the plane origin + s u + t v; it faces along u x v."""
    m = Mesh()
    if centre is None:
        centre = (sum(p[0] for p in poly2d) / len(poly2d), sum(p[1] for p in poly2d) / len(poly2d))

    def P(s, t):
        return tuple(origin[i] + s * u[i] + t * v[i] for i in range(3))

    c = m.point(P(*centre), uv=uv_of(*centre) if uv_of else None)
    idx = [m.point(P(s, t), uv=uv_of(s, t) if uv_of else None) for s, t in poly2d]
    for i in range(len(idx)):
        m.tri(c, idx[i], idx[(i + 1) % len(idx)])
    return m


def lancet(width, height, k=12, kind="pointed"):
    """The outline (CCW) of a window: a rectangle `height` high with an arch on top, centred
    on s = 0, from t = 0."""
    a, b = -width / 2, width / 2
    rect_h = height - arch_apex(width, kind)
    pts = [(a, 0.0), (b, 0.0)]
    curve = arch_curve(a, b, rect_h, kind, k)
    pts += [(s, y) for s, y in reversed(curve)]  # from b up over the apex down to a
    return pts


def disc(radius, k=48, start=0.0):
    return [(radius * math.cos(start + 2 * math.pi * i / k), radius * math.sin(start + 2 * math.pi * i / k))
            for i in range(k)]


def cross(a, b):
    return (a[1] * b[2] - a[2] * b[1], a[2] * b[0] - a[0] * b[2], a[0] * b[1] - a[1] * b[0])


def box_mesh(m, lo, hi):
    """Adds an axis-aligned box (outward faces) to mesh m."""
    x0, y0, z0 = lo
    x1, y1, z1 = hi
    c = [(x0, y0, z0), (x1, y0, z0), (x1, y1, z0), (x0, y1, z0),
         (x0, y0, z1), (x1, y0, z1), (x1, y1, z1), (x0, y1, z1)]
    for a, b, cc, d in ((0, 3, 2, 1), (4, 5, 6, 7), (0, 1, 5, 4), (3, 7, 6, 2), (0, 4, 7, 3), (1, 2, 6, 5)):
        m.add_quad(c[a], c[b], c[cc], c[d])
    return m


def vault(x_a, x_b, spring, z0, z1, kind, radius=None, k=24, nz=16):
    """A barrel vault over x in [x_a, x_b] from z0 to z1 (cross-section: arch_curve), facing
    down, with smooth per-point normals (a crease at a pointed apex)."""
    m = Mesh()
    span = x_b - x_a
    r = radius or (span if kind == "pointed" else span / 2)
    curve = arch_curve(x_a, x_b, spring, kind, k, radius)
    h = k // 2

    def normal(i, s, y):
        if kind == "round":
            cx = (x_a + x_b) / 2
        else:
            cx = x_a + r if i <= h else x_b - r
        d = (cx - s, spring - y)
        ln = math.hypot(*d)
        return (d[0] / ln, d[1] / ln, 0.0)

    cols = []
    for i, (s, y) in enumerate(curve):
        if kind == "pointed" and i == h:
            cols.append([(s, y, normal(i, s, y)), (s, y, normal(i + 1, s, y))])
        else:
            cols.append([(s, y, normal(i, s, y))])
    # rows of points along z; at the apex two copies (left normal, right normal)
    ids = []
    for j in range(nz + 1):
        z = z0 + (z1 - z0) * j / nz
        row = []
        for col in cols:
            row.append([m.point((s, y, z), n) for s, y, n in col])
        ids.append(row)
    for j in range(nz):
        for i in range(len(cols) - 1):
            a0 = ids[j][i][-1]
            b0 = ids[j][i + 1][0]
            a1 = ids[j + 1][i][-1]
            b1 = ids[j + 1][i + 1][0]
            # faces down/inward when z1 < z0 with this order; fixed below by the sign test
            m.quad(a0, b0, b1, a1)
    # orient the winding toward the inside (the springing line's middle, below)
    a, b, c = m.f[0]
    pa, pb, pc = m.p[a], m.p[b], m.p[c]
    nrm = cross([pb[i] - pa[i] for i in range(3)], [pc[i] - pa[i] for i in range(3)])
    if sum(nrm[i] * m.n[a][i] for i in range(3)) < 0:
        m.f = [(x, z, y) for x, y, z in m.f]
    return m


def rib(x_a, x_b, spring, z, width, depth, kind, radius=None, k=24):
    """A transverse rib: a band under the vault's cross-section at z (soffit and two sides)."""
    m = Mesh()
    outer = arch_curve(x_a, x_b, spring, kind, k, radius)
    span = x_b - x_a
    r = radius or (span if kind == "pointed" else span / 2)
    h = k // 2
    inner = []
    for i, (s, y) in enumerate(outer):
        cx = (x_a + x_b) / 2 if kind == "round" else (x_a + r if i <= h else x_b - r)
        d = (cx - s, spring - y)
        ln = math.hypot(*d) or 1.0
        inner.append((s + depth * d[0] / ln, y + depth * d[1] / ln))
    za, zb = z - width / 2, z + width / 2
    for i in range(len(outer) - 1):
        (s0, y0), (s1, y1) = inner[i], inner[i + 1]
        (o0, p0), (o1, p1) = outer[i], outer[i + 1]
        m.add_quad((s0, y0, za), (s1, y1, za), (s1, y1, zb), (s0, y0, zb))   # soffit
        m.add_quad((o0, p0, za), (o1, p1, za), (s1, y1, za), (s0, y0, za))   # sides
        m.add_quad((s0, y0, zb), (s1, y1, zb), (o1, p1, zb), (o0, p0, zb))
    return m


def write_png(path, img):
    os.makedirs(os.path.dirname(path), exist_ok=True)
    img.save(path, optimize=True)


# --- Cornell box with water --------------------------------------------------------------

def cornell_water(out):
    src = os.path.join(ROOT, "scenes", "cornell_box.ray")
    text = open(src).read()
    body = text.split("\n", 1)[1]
    # drop the source's header comment (the lines up to the camera)
    body = body[body.index("camera"):]
    # a higher camera looking down a little, so that the water surface fills the lower half
    cam_end = body.index("}") + 1
    body = ("camera {\n  position = (278, 470, -700);\n  viewdir = (0, -0.26, 1);\n  updir = (0, 1, 0);\n"
            "  fov = 39.3;\n  aspectratio = 1;\n}" + body[cam_end:])
    level, amp = 140.0, 4.0

    def height(x, z):
        return (level + 0.45 * amp * math.sin(0.045 * x + 0.8) * math.cos(0.03 * z)
                + 0.35 * amp * math.sin(0.028 * x - 0.052 * z + 1.9)
                + 0.2 * amp * math.cos(0.09 * x + 0.07 * z))

    def grad(x, z):
        e = 0.01
        return ((height(x + e, z) - height(x - e, z)) / (2 * e), (height(x, z + e) - height(x, z - e)) / (2 * e))

    x0, x1, z0, z1, nx, nz = 0.5, 555.5, 0.5, 558.5, 44, 44
    m = Mesh()
    ids = []
    for j in range(nz + 1):
        z = z0 + (z1 - z0) * j / nz
        row = []
        for i in range(nx + 1):
            x = x0 + (x1 - x0) * i / nx
            gx, gz = grad(x, z)
            ln = math.sqrt(gx * gx + 1 + gz * gz)
            row.append(m.point((x, height(x, z), z), (-gx / ln, 1 / ln, -gz / ln)))
        ids.append(row)
    for j in range(nz):
        for i in range(nx):
            # (x, z) -> (x, z + dz) -> (x + dx, z + dz): faces +y
            m.quad(ids[j][i], ids[j + 1][i], ids[j + 1][i + 1], ids[j][i + 1])
    # the tank's front: a vertical face at z = z0 facing the camera (-z), following the waves
    front = Mesh()
    top = [front.point((x0 + (x1 - x0) * i / nx, height(x0 + (x1 - x0) * i / nx, z0), z0), (0, 0, -1))
           for i in range(nx + 1)]
    bot = [front.point((x0 + (x1 - x0) * i / nx, 0.5, z0), (0, 0, -1)) for i in range(nx + 1)]
    for i in range(nx):
        # (b_i, t_i, t_i+1): (t - b) x (t' - b) = (+y) x (+x) = -z
        front.quad(bot[i], top[i], top[i + 1], bot[i + 1])
    water = material(diffuse=(0.01, 0.03, 0.04), specular=(0.8, 0.8, 0.8), shininess=200,
                     reflective=(0.08, 0.09, 0.09), transmissive=(0.78, 0.9, 0.95), index=1.33)
    hdr = (
        "SBT-raytracer 1.0\n\n"
        "// Generated by scripts/gen_scenes.py (do not edit): the Cornell box of\n"
        "// scenes/cornell_box.ray (its object-light ceiling panel and instant_radiosity block)\n"
        f"// filled to about {level:.0f} mm with water: a wavy triangle mesh (index 1.33, transmissive,\n"
        "// faintly reflective) whose front face closes the tank toward the camera, seen from a\n"
        "// camera higher than the box's own. Shadow rays pass the water attenuated by its\n"
        "// transmissive colour. Render with --gi off for direct light only.\n\n")
    out.write(hdr + body.rstrip() + "\n\n// The water surface and the tank's front face.\n")
    out.write(m.text("water_surface", water, per_line=3, digits=2))
    out.write(front.text("water_front", water, per_line=3, digits=2))
    out.write('\n// With --caustics N: vpl caustic lights, which measured about half the cut of spot ones\n// here (docs/LIGHTCUTS.md, "Caustics").\ninstant_radiosity { caustic_lights = "vpl"; }\n')


# --- church ------------------------------------------------------------------------------

def rose_texture(path, size=256):
    from PIL import Image, ImageDraw
    img = Image.new("RGB", (size, size), (40, 30, 60))
    d = ImageDraw.Draw(img)
    c = size / 2
    ring = [(0.95, 0.25, 0.2), (0.25, 0.4, 1.0), (1.0, 0.8, 0.3), (0.3, 0.75, 0.45)]
    for r_frac, n, phase in ((1.0, 16, 0.0), (0.72, 12, 0.5), (0.45, 8, 0.0)):
        r = r_frac * c
        for i in range(n):
            a0 = 360.0 * (i + phase) / n
            col = ring[(i + int(r_frac * 10)) % len(ring)]
            d.pieslice([c - r, c - r, c + r, c + r], a0, a0 + 360.0 / n,
                       fill=tuple(int(255 * v) for v in col), outline=(50, 40, 40), width=2)
    d.ellipse([c - 0.16 * c, c - 0.16 * c, c + 0.16 * c, c + 0.16 * c], fill=(255, 225, 120), outline=(50, 40, 40), width=2)
    write_png(path, img)


def church(out, tex_dir):
    L, bays = 32.0, 8
    bay = L / bays
    NX, WT, AX = 5.0, 0.6, 9.0           # arcade plane, wall thickness, outer walls
    inner = NX - WT / 2                   # nave side of the arcade walls
    spring, top, aisle_h = 6.0, 14.0, 10.0
    vault_r = 7.5
    apex = top + arch_apex(2 * inner, "pointed", vault_r)
    w = []
    w.append("SBT-raytracer 1.0\n\n"
             "// Generated by scripts/gen_scenes.py (do not edit): a gothic church interior, in\n"
             "// metres. A nave 32 m long under a pointed barrel vault with transverse ribs, two\n"
             "// aisles behind arcades of pointed arches on round columns, pews, an altar. Lit only\n"
             "// by luminous materials (object lights): stained-glass lancet windows in the aisles\n"
             "// and the clerestory, a rose window whose lights take their colours from a texture,\n"
             "// and four hanging lamps; instant radiosity adds one bounce. --gi off: direct only.\n\n")
    w.append("camera {\n  position = (0, 1.7, -0.8);\n  look_at = (0, 7.2, -32);\n  updir = (0, 1, 0);\n"
             "  fov = 64;\n  aspectratio = 1;\n}\n\n")
    w.append("instant_radiosity { vpls = 20000; bounces = 1; }\n\n")
    w.append(declare("stone", diffuse=(0.74, 0.70, 0.62)))
    w.append(declare("column", diffuse=(0.66, 0.64, 0.6), specular=(0.15, 0.15, 0.15), shininess=25))
    w.append(declare("floor", diffuse=(0.52, 0.5, 0.46), specular=(0.2, 0.2, 0.2), shininess=40))
    w.append(declare("carpet", diffuse=(0.5, 0.07, 0.07)))
    w.append(declare("wood", diffuse=(0.34, 0.2, 0.1), specular=(0.12, 0.1, 0.08), shininess=20))
    w.append(declare("altar", diffuse=(0.85, 0.82, 0.75), specular=(0.2, 0.2, 0.2), shininess=30))
    w.append(declare("gold", diffuse=(0.6, 0.45, 0.15), specular=(0.7, 0.6, 0.3), shininess=60))
    w.append(declare("iron", diffuse=(0.06, 0.06, 0.06)))
    glass = {
        "blue": (0.35, 0.5, 1.0), "red": (1.0, 0.3, 0.22), "gold": (1.0, 0.78, 0.4),
        "green": (0.35, 0.85, 0.5), "violet": (0.7, 0.4, 1.0),
    }
    aisle_i, clere_i, lancet_i, lamp_i = 35.0, 14.0, 18.0, 14.0
    dens_window, dens_lamp = 28.0, 160.0
    for nm, col in glass.items():
        w.append(declare("aisle_" + nm, diffuse=(0, 0, 0),
                         luminosity=dict(colour=col, intensity=aisle_i, density=dens_window)))
        w.append(declare("clere_" + nm, diffuse=(0, 0, 0),
                         luminosity=dict(colour=col, intensity=clere_i, density=dens_window)))
    w.append(declare("lancet", diffuse=(0, 0, 0),
                     luminosity=dict(colour=(0.55, 0.6, 1.0), intensity=lancet_i, density=25.0)))
    w.append(declare("lamp", diffuse=(0.9, 0.8, 0.6),
                     luminosity=dict(colour=(1.0, 0.78, 0.5), intensity=lamp_i, density=dens_lamp)))
    w.append("\n")

    # floor, carpet, ceilings of the aisles
    fl = Mesh()
    fl.add_quad((-AX, 0, 0), (AX, 0, 0), (AX, 0, -L), (-AX, 0, -L))
    w.append(fl.text("floor", "floor"))
    cp = Mesh()
    cp.add_quad((-0.9, 0.004, -1.0), (0.9, 0.004, -1.0), (0.9, 0.004, -27.5), (-0.9, 0.004, -27.5))
    w.append(cp.text("carpet", "carpet"))
    ceil = Mesh()
    for sgn in (-1, 1):
        xa, xb = sgn * (NX + WT / 2), sgn * AX
        ceil.add_quad((xa, aisle_h, 0), (xa, aisle_h, -L), (xb, aisle_h, -L), (xb, aisle_h, 0))
    w.append(ceil.text("aisle_ceilings", "stone"))

    # outer walls and end walls
    walls = Mesh()
    walls.add_quad((-AX, 0, 0), (-AX, 0, -L), (-AX, aisle_h, -L), (-AX, aisle_h, 0))
    walls.add_quad((AX, 0, -L), (AX, 0, 0), (AX, aisle_h, 0), (AX, aisle_h, -L))
    gable = arch_curve(-inner, inner, top, "pointed", 24, vault_r)
    outline = [(-AX, 0), (AX, 0), (AX, aisle_h), (inner, aisle_h), (inner, top)]
    outline += [(s, y) for s, y in reversed(gable)][1:-1]
    outline += [(-inner, top), (-inner, aisle_h), (-AX, aisle_h)]
    walls.extend(polygon_fan(outline, (0, 0, -L), (1, 0, 0), (0, 1, 0), centre=(0, 9)))
    walls.extend(polygon_fan(outline, (0, 0, 0), (-1, 0, 0), (0, 1, 0), centre=(0, 9)))  # mirrored: CCW seen from inside
    w.append(walls.text("walls", "stone", per_line=3))

    # arcades: walls pierced by pointed arches springing from the columns
    arc = Mesh()
    for sgn in (-1, 1):
        for b in range(bays):
            za, zb = -L + b * bay, -L + (b + 1) * bay
            arc.extend(arch_wall(sgn * NX, WT, za, zb, spring, top, "pointed", 16))
    w.append(arc.text("arcades", "stone", per_line=3))

    # columns: shaft, base and capital
    caps = Mesh()
    for sgn in (-1, 1):
        for b in range(1, bays):
            z = -L + b * bay
            w.append(cylinder_y((sgn * NX, 0.35, z), 0.42, spring - 0.35 - 0.45, "column"))
            box_mesh(caps, (sgn * NX - 0.55, 0, z - 0.55), (sgn * NX + 0.55, 0.35, z + 0.55))
            box_mesh(caps, (sgn * NX - 0.5, spring - 0.45, z - 0.5), (sgn * NX + 0.5, spring, z + 0.5))
    w.append(caps.text("bases_and_capitals", "column", per_line=3))

    # the vault and its ribs
    w.append(vault(-inner, inner, top, 0.0, -L, "pointed", vault_r, 28, 16).text("vault", "stone", per_line=3))
    ribs = Mesh()
    for b in range(1, bays):
        ribs.extend(rib(-inner, inner, top, -L + b * bay, 0.35, 0.22, "pointed", vault_r, 28))
    w.append(ribs.text("ribs", "column", per_line=3))

    # windows: aisle lancets on the outer walls, clerestory on the nave side of the arcades
    names = list(glass)
    for sgn in (-1, 1):
        for b in range(bays):
            zc = -L + (b + 0.5) * bay
            col = names[(b + (sgn > 0) * 2) % len(names)]
            u = (0, 0, -1) if sgn < 0 else (0, 0, 1)           # u x up faces into the church
            wm = polygon_fan(lancet(1.6, 5.0), (sgn * (AX - 0.01), 2.8, zc), u, (0, 1, 0), centre=(0, 2.0))
            w.append(wm.text(f"aisle_window_{'l' if sgn < 0 else 'r'}{b}", "aisle_" + col))
            u2 = (0, 0, 1) if sgn < 0 else (0, 0, -1)          # faces the nave (away from the wall)
            cm = polygon_fan(lancet(1.4, 2.9), (sgn * (inner - 0.01), 10.6, zc), u2, (0, 1, 0), centre=(0, 1.2))
            w.append(cm.text(f"clerestory_{'l' if sgn < 0 else 'r'}{b}", "clere_" + names[(b + 1) % len(names)]))
    # the east end: three lancets and a rose window textured with stained glass
    for i, (x, hgt) in enumerate(((-2.3, 5.0), (0.0, 6.0), (2.3, 5.0))):
        lm = polygon_fan(lancet(1.2, hgt), (x, 3.6, -L + 0.01), (1, 0, 0), (0, 1, 0), centre=(0, 2.0))
        w.append(lm.text(f"east_lancet{i}", "lancet"))
    rose_texture(os.path.join(tex_dir, "church_rose.png"))
    R, cy = 2.3, 16.4
    rm = polygon_fan(disc(R, 48), (0, cy, -L + 0.01), (1, 0, 0), (0, 1, 0), centre=(0, 0),
                     uv_of=lambda s, t: (0.5 + 0.5 * s / R, 0.5 + 0.5 * t / R))
    w.append(rm.text("rose_window", material(diffuse=(0, 0, 0), luminosity=dict(
        map="textures/church_rose.png", intensity=40.0, density=40.0))))

    # hanging lamps on chains from the vault
    for i, z in enumerate((-6.0, -12.0, -18.0, -24.0)):
        w.append(sphere((0, 7.6, z), 0.3, "lamp", name=f"lamp{i}"))
        w.append(cylinder_y((0, 7.9, z), 0.025, apex - 7.9 - 0.05, "iron"))

    # pews, the altar and its step
    pews = Mesh()
    for sgn in (-1, 1):
        xa, xb = sorted((sgn * 1.3, sgn * 4.2))
        for r in range(14):
            z = -5.0 - 1.3 * r
            box_mesh(pews, (xa, 0.42, z - 0.22), (xb, 0.48, z + 0.22))
            box_mesh(pews, (xa, 0.48, z + 0.18), (xb, 1.0, z + 0.24))
            for xe in (xa, xb - 0.06):
                box_mesh(pews, (xe, 0, z - 0.25), (xe + 0.06, 0.9, z + 0.25))
    w.append(pews.text("pews", "wood", per_line=3))
    w.append(box((0, 0.15, -29.6), (10.0, 0.3, 4.6), "stone"))
    w.append(box((0, 0.8, -30.2), (3.0, 1.0, 1.2), "altar"))
    w.append(box((0, 1.32, -30.2), (3.1, 0.04, 1.3), "gold"))
    for x in (-1.1, 1.1):
        w.append(cylinder_y((x, 1.34, -30.2), 0.05, 0.55, "gold"))
    out.write("".join(w))


# --- Roman hall --------------------------------------------------------------------------

def floor_texture(path, size=256):
    from PIL import Image, ImageDraw
    img = Image.new("RGB", (size, size), (205, 198, 182))
    d = ImageDraw.Draw(img)
    h = size // 2
    for (x, y) in ((0, 0), (h, h)):
        d.rectangle([x, y, x + h - 1, y + h - 1], fill=(150, 128, 102))
        d.ellipse([x + h * 0.18, y + h * 0.18, x + h * 0.82, y + h * 0.82], fill=(122, 40, 36))
    for (x, y) in ((h, 0), (0, h)):
        d.rectangle([x, y, x + h - 1, y + h - 1], fill=(205, 198, 182))
        d.polygon([(x + h / 2, y + h * 0.12), (x + h * 0.88, y + h / 2), (x + h / 2, y + h * 0.88), (x + h * 0.12, y + h / 2)],
                  fill=(70, 96, 80))
    d.rectangle([0, 0, size - 1, size - 1], outline=(235, 230, 215), width=3)
    d.line([(h, 0), (h, size)], fill=(235, 230, 215), width=3)
    d.line([(0, h), (size, h)], fill=(235, 230, 215), width=3)
    write_png(path, img)


def coffered_vault(R, cy, z0, z1, n_theta, n_z, depth, margin, skip=lambda i, j: False):
    """A semicircular barrel vault (radius R, axis along z at height cy) divided into coffers:
    each cell is a frame at radius R, four walls, and a panel recessed by `depth`."""
    m = Mesh()

    def P(theta, z, r):
        return (r * math.cos(theta), cy + r * math.sin(theta), z)

    for i in range(n_theta):
        t0, t1 = math.pi * i / n_theta, math.pi * (i + 1) / n_theta
        dt = margin / R
        for j in range(n_z):
            za, zb = z0 + (z1 - z0) * j / n_z, z0 + (z1 - z0) * (j + 1) / n_z
            dz = math.copysign(margin, zb - za)
            if skip(i, j):
                m.add_quad(P(t0, za, R), P(t0, zb, R), P(t1, zb, R), P(t1, za, R))
                continue
            o = [P(t0, za, R), P(t0, zb, R), P(t1, zb, R), P(t1, za, R)]
            ia = [P(t0 + dt, za + dz, R), P(t0 + dt, zb - dz, R), P(t1 - dt, zb - dz, R), P(t1 - dt, za + dz, R)]
            ib = [P(t0 + dt * 1.6, za + dz * 1.6, R + depth), P(t0 + dt * 1.6, zb - dz * 1.6, R + depth),
                  P(t1 - dt * 1.6, zb - dz * 1.6, R + depth), P(t1 - dt * 1.6, za + dz * 1.6, R + depth)]
            for k in range(4):
                m.add_quad(o[k], o[(k + 1) % 4], ia[(k + 1) % 4], ia[k])
                m.add_quad(ia[k], ia[(k + 1) % 4], ib[(k + 1) % 4], ib[k])
            m.add_quad(*ib)
    return m


def roman_hall(out, tex_dir):
    L, W = 36.0, 8.0                 # length, half width (side walls)
    CX, AW = 5.6, 0.7                # colonnade plane, arcade thickness
    spring, ent, wall_h = 6.4, 9.0, 11.0
    n_col = 8
    pitch = L / (n_col + 1)
    w = []
    w.append("SBT-raytracer 1.0\n\n"
             "// Generated by scripts/gen_scenes.py (do not edit): a Roman hall, in metres. Two\n"
             "// colonnades joined by round arches under an entablature, Pompeian-red walls, a\n"
             "// coffered semicircular barrel vault pierced by three luminous oculi, sixteen bronze\n"
             "// lamps with luminous flames, a lunette window over a statue in the end wall, and an\n"
             "// opus sectile floor (texture). Lit only by luminous materials; instant radiosity\n"
             "// adds one bounce. --gi off: direct light only.\n\n")
    w.append("camera {\n  position = (0, 1.8, -1.0);\n  look_at = (0, 7.5, -36);\n  updir = (0, 1, 0);\n"
             "  fov = 62;\n  aspectratio = 1;\n}\n\n")
    w.append("instant_radiosity { vpls = 20000; bounces = 1; }\n\n")
    floor_texture(os.path.join(tex_dir, "roman_floor.png"))
    w.append(declare("floor", diffuse='map("textures/roman_floor.png")', specular=(0.25, 0.25, 0.25), shininess=60))
    w.append(declare("marble", diffuse=(0.86, 0.83, 0.76), specular=(0.3, 0.3, 0.3), shininess=50))
    w.append(declare("ochre", diffuse=(0.82, 0.66, 0.44)))
    w.append(declare("pompeian", diffuse=(0.6, 0.14, 0.1), specular=(0.1, 0.1, 0.1), shininess=15))
    w.append(declare("vault", diffuse=(0.8, 0.76, 0.68)))
    w.append(declare("bronze", diffuse=(0.35, 0.22, 0.1), specular=(0.6, 0.45, 0.25), shininess=40))
    w.append(declare("statue", diffuse=(0.9, 0.9, 0.88), specular=(0.2, 0.2, 0.2), shininess=30))
    w.append(declare("oculus", diffuse=(0, 0, 0),
                     luminosity=dict(colour=(1.0, 0.97, 0.9), intensity=90.0, density=60.0)))
    w.append(declare("flame", diffuse=(1.0, 0.7, 0.3),
                     luminosity=dict(colour=(1.0, 0.62, 0.28), intensity=5.0, density=600.0)))
    w.append(declare("lunette", diffuse=(0, 0, 0),
                     luminosity=dict(colour=(1.0, 0.9, 0.75), intensity=50.0, density=30.0)))
    w.append("\n")

    fl = Mesh()
    for p in ((-W, 0, 0), (W, 0, 0), (W, 0, -L), (-W, 0, -L)):
        fl.point(p, uv=(p[0] / 4.0, -p[2] / 4.0))
    fl.quad(0, 1, 2, 3)
    w.append(fl.text("floor", "floor"))

    # side walls: a red dado below, ochre above; end walls up to the vault
    dado = Mesh()
    upper = Mesh()
    for sgn in (-1, 1):
        x = sgn * W
        za, zb = (0, -L) if sgn < 0 else (-L, 0)
        dado.add_quad((x, 0, za), (x, 0, zb), (x, 3.0, zb), (x, 3.0, za))
        upper.add_quad((x, 3.0, za), (x, 3.0, zb), (x, wall_h, zb), (x, wall_h, za))
    vault_curve = arch_curve(-W, W, wall_h, "round", 32)
    outline = [(-W, 0), (W, 0)] + [(s, y) for s, y in reversed(vault_curve)][:-1]
    upper.extend(polygon_fan(outline, (0, 0, -L), (1, 0, 0), (0, 1, 0), centre=(0, 8)))
    upper.extend(polygon_fan(outline, (0, 0, 0), (-1, 0, 0), (0, 1, 0), centre=(0, 8)))
    w.append(dado.text("dado", "pompeian"))
    w.append(upper.text("walls", "ochre", per_line=3))
    # pilasters along the side walls and a cornice at the springing of the vault
    pil = Mesh()
    for sgn in (-1, 1):
        for k in range(1, n_col + 1):
            z = -k * pitch
            x0, x1 = sorted((sgn * W, sgn * (W - 0.25)))
            box_mesh(pil, (x0, 0, z - 0.4), (x1, wall_h, z + 0.4))
        x0, x1 = sorted((sgn * W, sgn * (W - 0.45)))
        box_mesh(pil, (x0, wall_h - 0.5, -L), (x1, wall_h, 0))
    w.append(pil.text("pilasters_cornice", "marble", per_line=3))

    # the coffered vault, with three oculi at the crown
    n_theta, n_z = 14, 18
    oculi_z = (-9.0, -18.0, -27.0)
    crown = (n_theta // 2 - 1, n_theta // 2)

    def skip(i, j):
        zc = -(j + 0.5) * L / n_z
        return i in crown and any(abs(zc - z) < 1.2 for z in oculi_z)

    w.append(coffered_vault(W, wall_h, 0.0, -L, n_theta, n_z, 0.3, 0.16, skip).text("vault", "vault", per_line=3))
    for i, z in enumerate(oculi_z):
        om = polygon_fan(disc(1.3, 32), (0, wall_h + W - 0.12, z), (1, 0, 0), (0, 0, 1), centre=(0, 0))
        w.append(om.text(f"oculus{i}", "oculus"))

    # colonnades: column shafts with bases and capitals, round arches, entablature
    parts = Mesh()
    arches = Mesh()
    for sgn in (-1, 1):
        zs = [-k * pitch for k in range(n_col + 2)]
        for k in range(1, n_col + 1):
            z = zs[k]
            w.append(cylinder_y((sgn * CX, 0.5, z), 0.4, spring - 0.5 - 0.5, "marble"))
            box_mesh(parts, (sgn * CX - 0.55, 0, z - 0.55), (sgn * CX + 0.55, 0.5, z + 0.55))
            box_mesh(parts, (sgn * CX - 0.55, spring - 0.5, z - 0.55), (sgn * CX + 0.55, spring, z + 0.55))
        for k in range(n_col + 1):
            za, zb = sorted((zs[k], zs[k + 1]))
            arches.extend(arch_wall(sgn * CX, AW, za, zb, spring, ent, "round", 16))
        x0, x1 = sorted((sgn * (CX - 0.5), sgn * (CX + 0.5)))
        box_mesh(parts, (x0, ent, -L), (x1, ent + 0.7, 0))
    w.append(arches.text("arcades", "ochre", per_line=3))
    w.append(parts.text("bases_capitals_entablature", "marble", per_line=3))

    # bronze lamps between the columns on the nave side
    for sgn in (-1, 1):
        for k in range(n_col):
            z = -(k + 1.5) * pitch
            x = sgn * (CX - 1.1)
            w.append(cylinder_y((x, 0, z), 0.05, 1.35, "bronze"))
            w.append(cylinder_y((x, 0, z), 0.28, 0.08, "bronze"))
            w.append(f"translate({num(x)}, 1.35, {num(z)}, rotate(1, 0, 0, -1.570796327, "
                     f"cone {{ height = 0.22; bottom_radius = 0.06; top_radius = 0.3; material = bronze; }}))\n")
            w.append(sphere((x, 1.62, z), 0.16, "flame", name=f"flame_{'l' if sgn < 0 else 'r'}{k}"))

    # the end wall: a lunette window over a statue on a pedestal
    lu = [(3.2 * math.cos(math.pi * i / 24), 3.2 * math.sin(math.pi * i / 24)) for i in range(25)]
    lm = polygon_fan(lu, (0, wall_h + 0.3, -L + 0.01), (1, 0, 0), (0, 1, 0), centre=(0, 1.0))
    w.append(lm.text("lunette", "lunette"))
    w.append(box((0, 1.0, -L + 1.2), (1.6, 2.0, 1.6), "marble"))
    w.append(cylinder_y((0, 2.0, -L + 1.2), 0.45, 1.6, "statue"))
    w.append(sphere((0, 4.0, -L + 1.2), 0.42, "statue"))
    w.append(f"translate(0, 3.6, {num(-L + 1.2)}, rotate(1, 0, 0, -1.570796327, "
             "cone { height = 0.5; bottom_radius = 0.8; top_radius = 0.45; material = statue; }))\n")
    # statues in the side aisles
    for sgn in (-1, 1):
        for k in (2, 5, 8):
            z = -(k + 0.5) * pitch
            x = sgn * (W - 1.0)
            w.append(box((x, 0.6, z), (0.9, 1.2, 0.9), "marble"))
            w.append(sphere((x, 1.75, z), 0.5, "statue"))
    out.write("".join(w))


# --- rooms -------------------------------------------------------------------------------

def wall_boxes(m, axis, c, a, b, doors, height, thick):
    """A straight wall of `thick` centred on x = c (axis 'z': it runs along z from a to b) or
    z = c (axis 'x': along x), `height` high, with doorways (centre, width, door height)."""
    lo, hi = min(a, b), max(a, b)

    def add(s0, s1, y0, y1):
        if s1 - s0 < 1e-6:
            return
        if axis == "z":
            box_mesh(m, (c - thick / 2, y0, s0), (c + thick / 2, y1, s1))
        else:
            box_mesh(m, (s0, y0, c - thick / 2), (s1, y1, c + thick / 2))

    s = lo
    for centre, width, dh in sorted(doors):
        add(s, centre - width / 2, 0.0, height)
        add(centre - width / 2, centre + width / 2, dh, height)   # the lintel
        s = centre + width / 2
    add(s, hi, 0.0, height)
    return m


def table_mesh(m, cx, cz, w, d, h=0.75, top=0.05, leg=0.06):
    box_mesh(m, (cx - w / 2, h - top, cz - d / 2), (cx + w / 2, h, cz + d / 2))
    for sx in (-1, 1):
        for sz in (-1, 1):
            x = cx + sx * (w / 2 - leg)
            z = cz + sz * (d / 2 - leg)
            box_mesh(m, (x - leg / 2, 0, z - leg / 2), (x + leg / 2, h - top, z + leg / 2))
    return m


def shelf_mesh(m, books, lo, hi, n, axis="x", seed=0):
    """A bookcase over the footprint lo..hi (x, z) and up to height hi[1]: two sides, a back on
    the far side of its depth, `n` shelves, and rows of books (into `books`)."""
    (x0, y0, z0), (x1, y1, z1) = lo, hi
    b = 0.03
    if axis == "x":                      # runs along x, open toward +z (back at z0)
        box_mesh(m, (x0, y0, z0), (x0 + b, y1, z1))
        box_mesh(m, (x1 - b, y0, z0), (x1, y1, z1))
        box_mesh(m, (x0, y0, z0), (x1, y1, z0 + b))
    else:                                # runs along z, open toward +x (back at x0)
        box_mesh(m, (x0, y0, z0), (x1, y1, z0 + b))
        box_mesh(m, (x0, y0, z1 - b), (x1, y1, z1))
        box_mesh(m, (x0, y0, z0), (x0 + b, y1, z1))
    step = (y1 - y0) / n
    r = seed * 7 + 3
    for k in range(n + 1):
        y = y0 + k * step
        box_mesh(m, (x0, y - b / 2 if k else y, z0), (x1, y + b / 2 if k < n else y, z1))
        if k == n:
            break
        # books: a run of blocks of pseudo-random widths and heights on this shelf
        length = (x1 - x0) if axis == "x" else (z1 - z0)
        s = 2 * b
        while s < length - 2 * b - 0.1:
            r = (r * 1103515245 + 12345) % 2147483648
            wdt = 0.05 + 0.07 * ((r >> 8) % 100) / 100
            hgt = step * (0.55 + 0.3 * ((r >> 16) % 100) / 100)
            if (r >> 4) % 7 == 0:
                s += wdt                  # a gap
                continue
            s1 = min(s + wdt, length - 2 * b)
            if axis == "x":
                box_mesh(books, (x0 + s, y + b / 2, z0 + b), (x0 + s1, y + b / 2 + hgt, z1 - 0.04))
            else:
                box_mesh(books, (x0 + b, y + b / 2, z0 + s), (x1 - 0.04, y + b / 2 + hgt, z0 + s1))
            s = s1 + 0.004
    return m


def rooms(out, tex_dir):
    RW, H, T = 5.0, 2.8, 0.2          # room size (x and z), ceiling height, wall thickness
    X0, X1, Z0, Z1 = -7.5, 7.5, 0.0, -10.0
    DH = 2.1                          # door height
    w = []
    w.append("SBT-raytracer 1.0\n\n"
             "// Generated by scripts/gen_scenes.py (do not edit): six rooms in metres (a 3 x 2\n"
             "// block of 5 m x 5 m rooms, 2.8 m high) joined by doorways, with tables, bookcases,\n"
             "// crates, a sofa and cabinets. Lit only by luminous materials (object lights): each\n"
             "// room has a ceiling panel of its own colour (warm white, blue, green, red, violet,\n"
             "// amber), two rooms a lamp too; walls and furniture hide most of the lights from most\n"
             "// points, and light reaches the other rooms only through the doorways. Instant\n"
             "// radiosity adds one bounce. --gi off: direct light only.\n\n")
    w.append("camera {\n  position = (-7.15, 1.6, -0.35);\n  look_at = (-3.6, 0.9, -4.35);\n  updir = (0, 1, 0);\n"
             "  fov = 72;\n  aspectratio = 1;\n}\n\n")
    w.append("instant_radiosity { vpls = 20000; bounces = 1; }\n\n")
    w.append(declare("plaster", diffuse=(0.78, 0.76, 0.72)))
    w.append(declare("ceiling", diffuse=(0.82, 0.82, 0.8)))
    w.append(declare("floor", diffuse=(0.46, 0.3, 0.18), specular=(0.18, 0.16, 0.14), shininess=40))
    w.append(declare("wood", diffuse=(0.3, 0.18, 0.09), specular=(0.12, 0.1, 0.08), shininess=25))
    w.append(declare("pale_wood", diffuse=(0.62, 0.5, 0.34), specular=(0.1, 0.1, 0.1), shininess=20))
    w.append(declare("books", diffuse=(0.45, 0.16, 0.12), specular=(0.05, 0.05, 0.05), shininess=10))
    w.append(declare("fabric", diffuse=(0.2, 0.32, 0.42)))
    w.append(declare("white", diffuse=(0.85, 0.85, 0.83), specular=(0.3, 0.3, 0.3), shininess=60))
    w.append(declare("metal", diffuse=(0.1, 0.1, 0.1), specular=(0.5, 0.5, 0.5), shininess=50))
    panel_i, panel_d = 8.0, 200.0
    colours = [  # by room: (column, row) -> colour; row 0 is the front (z > -5)
        ("warm", (1.0, 0.86, 0.68)), ("blue", (0.45, 0.6, 1.0)), ("green", (0.45, 1.0, 0.5)),
        ("red", (1.0, 0.42, 0.3)), ("violet", (0.75, 0.45, 1.0)), ("amber", (1.0, 0.75, 0.3)),
    ]
    for nm, col in colours:      # the camera's room (warm) dimmer, so the others show
        w.append(declare("panel_" + nm, diffuse=(0, 0, 0), luminosity=dict(
            colour=col, intensity=panel_i * (0.35 if nm == "warm" else 1.0), density=panel_d)))
    w.append(declare("lamp", diffuse=(0.9, 0.8, 0.6),
                     luminosity=dict(colour=(1.0, 0.72, 0.42), intensity=2.5, density=500.0)))
    w.append("\n")

    fl = Mesh()
    fl.add_quad((X0, 0, Z0), (X1, 0, Z0), (X1, 0, Z1), (X0, 0, Z1))
    w.append(fl.text("floor", "floor"))
    ce = Mesh()
    ce.add_quad((X0, H, Z0), (X0, H, Z1), (X1, H, Z1), (X1, H, Z0))
    w.append(ce.text("ceiling", "ceiling"))

    walls = Mesh()
    for x in (X0, X1):
        wall_boxes(walls, "z", x, Z0 - T / 2, Z1 + T / 2, [], H, T)
    for z in (Z0, Z1):
        wall_boxes(walls, "x", z, X0 + T / 2, X1 - T / 2, [], H, T)
    # interior walls: doorways placed so that the camera sees through two of them in a line
    wall_boxes(walls, "z", -2.5, Z0 - T / 2, Z1 + T / 2, [(-3.2, 1.3, DH), (-7.0, 1.1, DH)], H, T)
    wall_boxes(walls, "z", 2.5, Z0 - T / 2, Z1 + T / 2, [(-2.0, 1.1, DH), (-7.8, 1.1, DH)], H, T)
    wall_boxes(walls, "x", -5.0, X0 + T / 2, -2.5 - T / 2, [(-5.8, 1.3, DH)], H, T)
    wall_boxes(walls, "x", -5.0, -2.5 + T / 2, 2.5 - T / 2, [(0.5, 1.3, DH)], H, T)
    wall_boxes(walls, "x", -5.0, 2.5 + T / 2, X1 - T / 2, [(5.0, 1.1, DH)], H, T)
    w.append(walls.text("walls", "plaster", per_line=3))

    # a ceiling panel in the middle of every room
    for i, (nm, _) in enumerate(colours):
        cx, cz = X0 + RW * (i % 3 + 0.5), Z0 - RW * (i // 3 + 0.5)
        pm = polygon_fan([(-0.8, -0.8), (0.8, -0.8), (0.8, 0.8), (-0.8, 0.8)], (cx, H - 0.01, cz),
                         (1, 0, 0), (0, 0, 1), centre=(0, 0))       # faces along x cross z = -y
        w.append(pm.text(f"panel_{nm}", "panel_" + nm))

    wood, pale, books, white, metal = Mesh(), Mesh(), Mesh(), Mesh(), Mesh()
    fabric = Mesh()
    # front left (the camera's room, warm): a table, a bookcase by the back wall, crates, a lamp
    table_mesh(wood, -5.2, -2.3, 1.6, 0.9)
    shelf_mesh(wood, books, (-4.8, 0, -4.9), (-2.8, 2.0, -4.5), 5, "x", seed=1)
    box_mesh(pale, (-7.3, 0, -4.8), (-6.6, 0.6, -4.1))
    box_mesh(pale, (-7.25, 0.6, -4.7), (-6.7, 1.1, -4.2))
    # front middle (blue): a free-standing double bookcase and crates
    shelf_mesh(wood, books, (-1.2, 0, -1.6), (1.4, 2.1, -1.25), 5, "x", seed=2)
    shelf_mesh(wood, books, (-1.2, 0, -1.95), (1.4, 2.1, -1.6), 5, "x", seed=3)
    box_mesh(pale, (1.0, 0, -4.6), (2.2, 0.8, -3.6))
    box_mesh(pale, (1.2, 0.8, -4.4), (2.0, 1.4, -3.8))
    box_mesh(pale, (-2.2, 0, -4.7), (-1.4, 0.7, -3.9))
    # front right (green): stacks of crates
    for (x, z, n) in ((4.0, -1.0, 3), (5.2, -3.5, 2), (6.5, -1.5, 1), (3.6, -4.0, 2)):
        for k in range(n):
            box_mesh(pale, (x - 0.45 + 0.05 * k, 0.7 * k, z - 0.45), (x + 0.45 + 0.05 * k, 0.7 * (k + 1), z + 0.45))
    # back left (red): a long table, a bookcase along the left wall
    table_mesh(wood, -4.8, -7.6, 2.2, 1.0)
    shelf_mesh(wood, books, (-7.4, 0, -9.4), (-7.0, 2.2, -6.0), 6, "z", seed=4)
    # back middle (violet): tall white cabinets in a row, a table
    for x in (-1.8, -0.9, 1.0, 1.9):
        box_mesh(white, (x - 0.42, 0, -9.85), (x + 0.42, 2.2, -9.3))
    table_mesh(pale, 0.4, -7.4, 1.4, 1.4)
    # back right (amber): a sofa, a low table, a bookcase
    box_mesh(fabric, (3.4, 0, -9.8), (6.2, 0.45, -8.9))
    box_mesh(fabric, (3.4, 0.45, -9.8), (6.2, 0.9, -9.55))
    box_mesh(fabric, (3.2, 0, -9.8), (3.45, 0.65, -8.9))
    box_mesh(fabric, (6.15, 0, -9.8), (6.4, 0.65, -8.9))
    table_mesh(pale, 4.8, -7.8, 1.2, 0.6, h=0.42)
    shelf_mesh(wood, books, (7.0, 0, -7.5), (7.4, 2.0, -5.4), 5, "z", seed=5)
    w.append(wood.text("wood_furniture", "wood", per_line=3))
    w.append(pale.text("crates_tables", "pale_wood", per_line=3))
    w.append(books.text("books", "books", per_line=3))
    w.append(white.text("cabinets", "white", per_line=3))
    w.append(fabric.text("sofa", "fabric", per_line=3))

    # a floor lamp in the camera's room, a table lamp on the amber room's low table
    w.append(cylinder_y((-3.0, 0, -0.6), 0.2, 0.03, "metal"))
    w.append(cylinder_y((-3.0, 0.03, -0.6), 0.02, 1.45, "metal"))
    w.append(sphere((-3.0, 1.62, -0.6), 0.17, "lamp", name="floor_lamp"))
    w.append(cylinder_y((4.8, 0.42, -7.8), 0.02, 0.3, "metal"))
    w.append(sphere((4.8, 0.84, -7.8), 0.13, "lamp", name="table_lamp"))
    out.write("".join(w))


# --- column hall -------------------------------------------------------------------------

def column_hall(out, tex_dir):
    HX, L, H = 12.0, 20.0, 7.0               # half width, length, ceiling height
    xs = [-10.0, -6.0, -2.0, 2.0, 6.0, 10.0]   # column grid: 6 x 4
    zs = [-4.0, -8.0, -12.0, -16.0]
    cap_y, beam_y = 6.0, 6.35
    lamp_xs = [-11.0, -8.0, -4.0, 0.0, 4.0, 8.0, 11.0]
    lamp_zs = [-2.0, -6.0, -10.0, -14.0, -18.0]
    w = []
    w.append("SBT-raytracer 1.0\n\n"
             "// Generated by scripts/gen_scenes.py (do not edit): a hall of columns, in metres.\n"
             "// 24 m x 20 m, 7 m high, a 6 x 4 grid of round columns with bases and capitals\n"
             "// carrying a grid of beams under a flat ceiling, a chequered floor of two stones.\n"
             "// Lit only by luminous materials (object lights): 35 small lamps hanging on chains\n"
             "// between the columns and seven tall round-headed windows of pale daylight in the\n"
             "// right and far walls; the columns hide most lamps from most points. Instant\n"
             "// radiosity adds one bounce. --gi off: direct light only.\n\n")
    w.append("camera {\n  position = (-11.2, 1.7, -0.6);\n  look_at = (3.0, 3.0, -16.0);\n  updir = (0, 1, 0);\n"
             "  fov = 66;\n  aspectratio = 1;\n}\n\n")
    w.append("instant_radiosity { vpls = 20000; bounces = 1; }\n\n")
    w.append(declare("floor_light", diffuse=(0.74, 0.71, 0.64), specular=(0.25, 0.25, 0.25), shininess=60))
    w.append(declare("floor_dark", diffuse=(0.3, 0.27, 0.24), specular=(0.25, 0.25, 0.25), shininess=60))
    w.append(declare("walls", diffuse=(0.74, 0.66, 0.54)))
    w.append(declare("ceiling", diffuse=(0.7, 0.67, 0.62)))
    w.append(declare("column", diffuse=(0.84, 0.82, 0.77), specular=(0.25, 0.25, 0.25), shininess=40))
    w.append(declare("beam", diffuse=(0.36, 0.23, 0.13), specular=(0.1, 0.08, 0.06), shininess=20))
    w.append(declare("iron", diffuse=(0.05, 0.05, 0.05), specular=(0.3, 0.3, 0.3), shininess=30))
    w.append(declare("lamp", diffuse=(0.9, 0.8, 0.6),
                     luminosity=dict(colour=(1.0, 0.74, 0.45), intensity=4.0, density=220.0)))
    w.append(declare("window", diffuse=(0, 0, 0),
                     luminosity=dict(colour=(0.72, 0.84, 1.0), intensity=22.0, density=30.0)))
    w.append("\n")

    tiles = (Mesh(), Mesh())          # a chequered floor of 1 m tiles in two stones
    for i in range(int(2 * HX)):
        for j in range(int(L)):
            x, z = -HX + i, -j
            tiles[(i + j) % 2].add_quad((x, 0, z), (x + 1, 0, z), (x + 1, 0, z - 1), (x, 0, z - 1))
    w.append(tiles[0].text("floor_light", "floor_light", per_line=3))
    w.append(tiles[1].text("floor_dark", "floor_dark", per_line=3))
    ce = Mesh()
    ce.add_quad((-HX, H, 0), (-HX, H, -L), (HX, H, -L), (HX, H, 0))
    w.append(ce.text("ceiling", "ceiling"))
    walls = Mesh()
    walls.add_quad((-HX, 0, 0), (-HX, 0, -L), (-HX, H, -L), (-HX, H, 0))      # left, faces +x
    walls.add_quad((HX, 0, -L), (HX, 0, 0), (HX, H, 0), (HX, H, -L))          # right, faces -x
    walls.add_quad((-HX, 0, -L), (HX, 0, -L), (HX, H, -L), (-HX, H, -L))      # far, faces +z
    walls.add_quad((HX, 0, 0), (-HX, 0, 0), (-HX, H, 0), (HX, H, 0))          # near, faces -z
    w.append(walls.text("walls", "walls"))

    # columns: shafts (quadrics), square bases and capitals; beams over the column lines
    parts = Mesh()
    for x in xs:
        for z in zs:
            w.append(cylinder_y((x, 0.4, z), 0.42, cap_y - 0.4, "column"))
            box_mesh(parts, (x - 0.6, 0, z - 0.6), (x + 0.6, 0.4, z + 0.6))
            box_mesh(parts, (x - 0.55, cap_y, z - 0.55), (x + 0.55, beam_y, z + 0.55))
    w.append(parts.text("bases_capitals", "column", per_line=3))
    beams = Mesh()
    for z in zs:
        box_mesh(beams, (-HX, beam_y, z - 0.3), (HX, H, z + 0.3))
    for x in xs:
        for z0, z1 in zip([0.0] + zs, zs + [-L]):
            za, zb = sorted((z0, z1))
            lo, hi = za + (0.3 if za > -L else 0), zb - (0.3 if zb < 0 else 0)
            box_mesh(beams, (x - 0.3, beam_y, lo), (x + 0.3, H, hi))
    w.append(beams.text("beams", "beam", per_line=3))

    # windows: round-headed luminous panels in the right wall (between the column rows) and
    # the far wall (between the column lines)
    for i, z in enumerate((-2.0, -6.0, -10.0, -14.0)):
        wm = polygon_fan(lancet(1.5, 3.8, 12, "round"), (HX - 0.01, 1.6, z), (0, 0, 1), (0, 1, 0), centre=(0, 1.8))
        w.append(wm.text(f"window_right{i}", "window"))
    for i, x in enumerate((-4.0, 0.0, 4.0)):
        wm = polygon_fan(lancet(1.5, 3.8, 12, "round"), (x, 1.6, -L + 0.01), (1, 0, 0), (0, 1, 0), centre=(0, 1.8))
        w.append(wm.text(f"window_far{i}", "window"))

    # hanging lamps between the columns, on chains from the ceiling, at two heights
    for j, z in enumerate(lamp_zs):
        for i, x in enumerate(lamp_xs):
            y = 3.4 if (i + j) % 2 == 0 else 4.2
            w.append(sphere((x, y, z), 0.18, "lamp", name=f"lamp_{j}_{i}"))
            w.append(f"translate({num(x)}, {num(y + 0.1)}, {num(z)}, rotate(1, 0, 0, -1.570796327, "
                     "cone { height = 0.16; bottom_radius = 0.2; top_radius = 0.03; material = iron; }))\n")
            w.append(cylinder_y((x, y + 0.26, z), 0.012, H - y - 0.26, "iron", capped=False))
    out.write("".join(w))


# --- dense variants of the emitter scenes --------------------------------------------------

def dense(src_name, factor, why=None):
    def write(out):
        src = os.path.join(ROOT, "scenes", src_name)
        text = open(src).read()
        n = [0]

        def bump(mo):
            n[0] += 1
            return f"{mo.group(1)}{float(mo.group(2)) * factor:g}"

        body = re.sub(r"(density\s*=\s*)([0-9.]+)", bump, text)
        if n[0] == 0:
            raise SystemExit(f"gen_scenes: no density in {src}")
        head, rest = body.split("\n", 1)
        note = why or f"the same power in {factor:g}x as many lights"
        out.write(head + "\n\n// Generated by scripts/gen_scenes.py (do not edit): scenes/" + src_name +
                  f" with every\n// luminosity density multiplied by {factor:g} ({note}).\n" + rest)
    return write


SCENES = {
    "cornell_water": lambda out, tex: cornell_water(out),
    "church": church,
    "roman_hall": roman_hall,
    "rooms": rooms,
    "column_hall": column_hall,
    "green_light_emitter_dense": lambda out, tex: dense("green_light_emitter.ray", 25)(out),
    "luminous_object_dense": lambda out, tex: dense("luminous_object.ray", 25)(out),
    # 250 * 0.006 = 1.5 lights per m^2 on the 8.04 m^2 sphere: 12 lights, the count the seed's
    # table implies (its brute force evaluated 11.8 lights per pixel, against the 8,638 of its
    # 8,638-VPL Cornell box), so lights per shading point compare at equal light counts.
    "green_light_emitter_seed": lambda out, tex: dense(
        "green_light_emitter.ray", 0.006,
        "the same power in 12 lights,\n// the seed's count")(out),
}


def main(argv=None):
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--out", default=os.path.join(ROOT, "scenes"), help="output folder (default scenes/)")
    ap.add_argument("names", nargs="*", help="scenes to write (default all): " + ", ".join(SCENES))
    a = ap.parse_args(argv)
    names = a.names or list(SCENES)
    for nm in names:
        if nm not in SCENES:
            ap.error(f"unknown scene '{nm}'")
    os.makedirs(a.out, exist_ok=True)
    tex = os.path.join(a.out, "textures")
    for nm in names:
        path = os.path.join(a.out, nm + ".ray")
        tmp = path + ".tmp"
        with open(tmp, "w") as f:
            SCENES[nm](f, tex)
        os.replace(tmp, path)
        print(f"wrote {os.path.relpath(path)}")


if __name__ == "__main__":
    main()
