#!/usr/bin/python3
"""The benchmark driver behind `make bench` (issue 7): renders the scene suite with brute
force, Lightcuts and the seed's method, measures time, lights per shading point and error,
runs the scaling sweep, the 100k-light accuracy check and the ray/tree micro benchmarks,
and writes the generated section of docs/BENCHMARKS.md and the images docs/images/bench_*.png.

  /usr/bin/python3 scripts/bench.py [--build DIR] [--quick] [--resume] [--only PART ...]

Environment: BUILD (build folder, default `build`), BENCH_QUICK=1 (same as --quick).

Full mode writes docs/BENCHMARKS.md and docs/images/ (about an hour on 2 cores);
quick mode (small images, one run each, a few minutes) writes out/bench-quick/BENCHMARKS.md and
out/bench-quick/images/ and leaves docs/ alone unless --docs is given. Raw renders, --stats
files, logs and results.json go to out/bench/ (or out/bench-quick/); --resume reuses the parts
already in results.json (same commit) instead of measuring them again; --write-only
regenerates the Markdown and images from results.json.

Times: the render phase plus the light-tree build (`time_render_s + time_tree_s` of --stats),
wall clock on all cores, median of repeated runs. Loading, Embree's BVH and VPL generation are
common to every method and left out. Brute force runs at full resolution when the estimate
from --reference-pixels is under BRUTE_LIMIT seconds; otherwise its time is the estimate
(brute force at K pixels, scaled to the image) and is marked "~", and errors are measured at
those K pixels instead of over the whole image.
"""
import argparse
import datetime
import json
import math
import os
import re
import shlex
import shutil
import statistics
import subprocess
import sys
import time

HERE = os.path.dirname(os.path.abspath(__file__))
ROOT = os.path.dirname(HERE)
PY = sys.executable or "/usr/bin/python3"

BEGIN, END = "<!-- BEGIN GENERATED -->", "<!-- END GENERATED -->"

# The seed's published figures (docs/SEED.md).
SEED_EMITTER = "43 s → 7 s (6.1×); 11.8 → 1.5 lights/pixel"
SEED_EMITTER_LIGHTS = "11.8 → 1.5 lights/pixel"
SEED_CORNELL = "2 s / 2031 s / 95 s (21.4×); 8,638 → 273.6 VPLs/pixel"

# The table's rows. vpls: target number of VPLs (the path count is found by `info`);
# gi: the scene has VPLs (no-extra-lights column = --gi off); brute: 'auto' (full resolution
# when the estimate allows) or 'reference' (always extrapolated).
ROWS = [
    dict(key="green", name="Green light emitter", scene="scenes/green_light_emitter.ray", seed=SEED_EMITTER),
    # The seed's light count (12): its brute force evaluated 11.8 lights per pixel, so this is the
    # row where lights per shading point compare with the seed's 1.5 at equal light counts.
    dict(key="green12", name="Green light emitter, the seed's 12 lights", scene="scenes/green_light_emitter_seed.ray",
         seed=SEED_EMITTER_LIGHTS),
    dict(key="green_dense", name="Green light emitter, 25× density", scene="scenes/green_light_emitter_dense.ray"),
    dict(key="luminous", name="Luminous object", scene="scenes/luminous_object.ray"),
    dict(key="luminous_dense", name="Luminous object, 25× density", scene="scenes/luminous_object_dense.ray"),
    dict(key="cornell", name="Cornell box, object light + GI", scene="scenes/cornell_box.ray", gi=True,
         vpls=8638, seed=SEED_CORNELL),
    dict(key="cornell_100k", name="Cornell box, 100,000 VPLs", scene="scenes/cornell_box.ray", gi=True,
         vpls=100000, brute="reference", pair=False),
    dict(key="cornell_1m", name="Cornell box, 1,000,000 VPLs", scene="scenes/cornell_box.ray", gi=True,
         vpls=1000000, brute="reference", pair=False),
    dict(key="cornell_water", name="Cornell water", scene="scenes/cornell_water.ray", gi=True),
    dict(key="church", name="Church", scene="scenes/church.ray", gi=True),
    dict(key="roman_hall", name="Roman hall", scene="scenes/roman_hall.ray", gi=True),
    # Occlusion-heavy scenes (issue 20): most lights are hidden from most points.
    dict(key="rooms", name="Rooms", scene="scenes/rooms.ray", gi=True),
    dict(key="column_hall", name="Column hall", scene="scenes/column_hall.ray", gi=True),
    # Environment light (issue 24): thousands of directional lights from a sky model or a map.
    dict(key="courtyard_sunsky", name="Courtyard, sun and sky", scene="scenes/courtyard_sunsky.ray"),
    dict(key="garden_hdr", name="Garden, HDR map", scene="scenes/garden_hdr.ray"),
    # Caustics (issue 25): each scene without caustic lights (light through glass by the
    # kt-weighted shadow ray; mirrors cast plain shadows) and with them (extra: render flags).
    dict(key="ball_lens", name="Ball lens, no caustics", scene="scenes/ball_lens.ray", extra=["--caustics", "0"]),
    dict(key="ball_lens_caustics", name="Ball lens, caustics (1M paths)", scene="scenes/ball_lens.ray"),
    dict(key="mirror_ring", name="Mirror ring, no caustics", scene="scenes/mirror_ring.ray", extra=["--caustics", "0"]),
    dict(key="mirror_ring_caustics", name="Mirror ring, caustics (1M paths)", scene="scenes/mirror_ring.ray"),
    dict(key="cornell_water_caustics", name="Cornell water, caustics (100k paths)", scene="scenes/cornell_water.ray",
         gi=True, extra=["--caustics", "100000"]),
]

# One sentence per with/without-GI pair, written after looking at the images.
GI_DESCRIPTIONS = {
    "cornell": "Without GI the ceiling, the upper corners and every box face turned away from the panel are "
               "black; with one bounce the ceiling is lit, the red and green walls bleed onto the boxes' sides "
               "and the shadows on the floor soften.",
    "cornell_water": "Without GI the ceiling is black and the water a dark green layer over a shadowed floor; "
                     "with GI the ceiling and the box fronts light up, the tall box's side turns red from the "
                     "wall, and the floor seen through the water brightens.",
    "church": "Without GI only what a window or lamp sees directly is lit and the vault above the clerestory "
              "stays dark; with GI the coloured window light spreads over the vault, the columns and the floor "
              "as a soft violet fill.",
    "roman_hall": "Without GI the coffers, the walls above the cornice and the far end stay a dim brown under the "
                  "oculi and the lamps; with GI the vault, the walls and the floor brighten to a warm ochre, the "
                  "coffers' sides lit by light bounced from the floor.",
    "rooms": "Without GI the ceiling around the camera room's dim warm panel, the upper corners and the underside "
             "of the table are black, and the rooms beyond show only what their own coloured panels see; with GI "
             "the ceiling and walls fill in and the floor by the left doorway warms with red light bounced from "
             "the room beyond.",
    "column_hall": "Without GI the ceiling between the beams, the beams' sides and the columns' far sides are "
                   "near black and each lamp leaves sharp column shadows on the floor; with GI the ceiling and "
                   "beams light up warm from the floor and the columns' shadowed sides fill in.",
}

SCALING_N = [1000, 10000, 100000, 1000000]


def now():
    return time.monotonic()


def fmt_time(s, approx=False):
    if s is None:
        return "—"
    if s < 1:
        t = f"{s:.2f} s"
    elif s < 100:
        t = f"{s:.1f} s"
    elif s < 3600:
        t = f"{s:.0f} s ({s / 60:.1f} min)"
    else:
        t = f"{s / 3600:.1f} h"
    return ("~" + t) if approx else t


def fmt_pct(x, digits=2):
    return "—" if x is None else f"{100 * x:.{digits}f}%"


def fmt_int(x):
    return "—" if x is None else f"{int(round(x)):,}"


def median(xs):
    xs = [x for x in xs if x is not None]
    return statistics.median(xs) if xs else None


class Driver:
    def __init__(self, a):
        self.a = a
        self.quick = a.quick
        self.build = a.build if os.path.isabs(a.build) else os.path.join(ROOT, a.build)
        self.lc = os.path.join(self.build, "lightcuts")
        self.work = os.path.join(ROOT, a.work or ("out/bench-quick" if self.quick else "out/bench"))
        if a.docs or not self.quick:
            self.md = os.path.join(ROOT, "docs", "BENCHMARKS.md")
            self.images = os.path.join(ROOT, "docs", "images")
        else:
            self.md = os.path.join(self.work, "BENCHMARKS.md")
            self.images = os.path.join(self.work, "images")
        os.makedirs(self.work, exist_ok=True)
        os.makedirs(self.images, exist_ok=True)
        self.width = 128 if self.quick else 512
        self.scaling_width = 64 if self.quick else 256
        self.repeats = 1 if self.quick else 3
        self.k_probe = 64 if self.quick else 256
        self.k_ref = 256 if self.quick else 1024
        self.brute_limit = 60 if self.quick else 600
        self.scaling_n = SCALING_N
        self.log = open(os.path.join(self.work, "bench.log"), "a")
        self.results_path = os.path.join(self.work, "results.json")
        self.results = {}
        if os.path.exists(self.results_path):
            self.results = json.load(open(self.results_path))
        self.results.setdefault("parts", {})

    # --- running things ----------------------------------------------------------------

    def rel(self, p):
        p = str(p)
        return os.path.relpath(p, ROOT) if os.path.isabs(p) and p.startswith(ROOT) else p

    def run(self, cmd, commands=None, capture=False, timeout=None):
        shown = " ".join(shlex.quote(self.rel(c)) for c in cmd)
        if commands is not None:
            commands.append(shown)
        self.log.write(f"[{datetime.datetime.now():%H:%M:%S}] {shown}\n")
        self.log.flush()
        t0 = now()
        p = subprocess.run(cmd, cwd=ROOT, stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True, timeout=timeout)
        self.log.write(p.stderr[-4000:])
        if p.returncode != 0:
            self.log.write(p.stdout[-4000:])
            self.log.flush()
            raise RuntimeError(f"command failed ({p.returncode}): {shown}\n{p.stderr[-2000:]}")
        self.log.write(f"  ({now() - t0:.1f} s)\n")
        self.log.flush()
        return p.stdout if capture else None

    def render(self, scene, base, method="lightcuts", width=None, extra=(), ref=0, cut_heatmap=False,
               commands=None):
        """One render with --stats; returns the stats dict (with 'exr' and 'cut_png')."""
        width = width or self.width
        stats = base + ".json"
        cmd = [self.lc, "render", scene, "-o", base + ".exr", "--width", str(width), "--method", method,
               "-q", "--stats", stats] + list(extra)
        if ref:
            cmd += ["--reference-pixels", str(ref)]
        if cut_heatmap:
            cmd += ["--cut-heatmap", base + "_cut.png"]
        self.run(cmd, commands)
        s = json.load(open(stats))
        s["exr"] = base + ".exr"
        if cut_heatmap:
            s["cut_png"] = base + "_cut.png"
        return s

    def cost(self, s):
        return s["time_render_s"] + s.get("time_tree_s", 0.0)

    def compare(self, ref_exr, test_exr, heatmap=None, commands=None):
        cmd = [self.lc, "compare", ref_exr, test_exr, "--json"]
        if heatmap:
            cmd += ["--heatmap", heatmap]
        return json.loads(self.run(cmd, commands, capture=True))

    def info(self, scene, extra=()):
        return json.loads(self.run([self.lc, "info", scene, "--json"] + list(extra), capture=True))

    def save(self):
        tmp = self.results_path + ".tmp"
        json.dump(self.results, open(tmp, "w"), indent=1, sort_keys=True)
        os.replace(tmp, self.results_path)

    def done(self, key):
        r = self.results["parts"].get(key)
        return r is not None and (self.a.write_only or (self.a.resume and
                                                         r.get("commit") == self.results.get("env", {}).get("commit")))

    # --- environment -------------------------------------------------------------------

    def environment(self):
        def git(*args):
            try:
                return subprocess.run(["git"] + list(args), cwd=ROOT, capture_output=True, text=True).stdout.strip()
            except OSError:
                return ""
        cpu = ""
        try:
            for line in open("/proc/cpuinfo"):
                if line.startswith("model name"):
                    cpu = line.split(":", 1)[1].strip()
                    break
        except OSError:
            pass
        dirty = subprocess.run(["git", "status", "--porcelain", "--untracked-files=no"], cwd=ROOT,
                               capture_output=True, text=True).stdout.rstrip()
        env = dict(commit=git("rev-parse", "--short", "HEAD"), dirty=bool(dirty),
                   dirty_files=[l[3:] for l in dirty.splitlines()][:20],
                   nproc=os.cpu_count(), cpu=cpu, date=datetime.datetime.utcnow().strftime("%Y-%m-%d %H:%M UTC"),
                   build=self.rel(self.build), mode="quick" if self.quick else "full",
                   width=self.width, repeats=self.repeats, k_probe=self.k_probe, k_ref=self.k_ref,
                   brute_limit=self.brute_limit, loadavg_start=os.getloadavg()[0])
        return env

    # --- the seed's table ----------------------------------------------------------------

    def vpl_paths(self, scene, target):
        """The path count (--vpls) that deposits about `target` VPLs in this scene."""
        base = self.info(scene)["vpls"]
        block = re.search(r"vpls\s*=\s*(\d+)", open(os.path.join(ROOT, scene)).read())
        paths = int(block.group(1)) if block else target
        if abs(base - target) <= 0.005 * target:
            return None, base  # the scene's own block is close enough
        ratio = base / paths if base else 0.8
        guess = int(round(target / ratio))
        for _ in range(3):
            got = self.info(scene, ["--vpls", str(guess)])["vpls"]
            if got == target or abs(got - target) <= max(1, target // 2000):
                return guess, got
            guess = max(1, int(round(guess * target / max(got, 1))))
        return guess, self.info(scene, ["--vpls", str(guess)])["vpls"]

    def table_row(self, row):
        key = "row:" + row["key"]
        if self.done(key):
            return
        t_row = now()
        scene = row["scene"]
        base = os.path.join(self.work, row["key"])
        cmds = []
        extra = list(row.get("extra", []))
        res = dict(key=row["key"], name=row["name"], scene=scene, width=self.width, gi=bool(row.get("gi")),
                   loadavg=os.getloadavg()[0])
        if row.get("vpls"):
            paths, got = self.vpl_paths(scene, row["vpls"])
            extra += ["--vpls", str(paths)] if paths else []
            res["vpl_paths"] = paths
        # lightcuts, first with a probe of brute force at a few pixels
        lc = [self.render(scene, base + "_lc", extra=extra, ref=self.k_probe, cut_heatmap=True, commands=cmds)]
        est = lc[0]["reference"]["brute_seconds_estimate"]
        full = row.get("brute", "auto") == "auto" and est <= self.brute_limit
        ref_stats = lc[0]["reference"]
        if not full and self.k_ref > self.k_probe:
            lc.append(self.render(scene, base + "_lcref", extra=extra, ref=self.k_ref, commands=cmds))
            ref_stats = lc[-1]["reference"]
        reps = self.repeats if self.cost(lc[0]) < 60 else max(1, self.repeats - 1)
        while len(lc) < reps:
            lc.append(self.render(scene, base + "_rep", extra=extra, commands=cmds))
        # the seed's method
        sd = [self.render(scene, base + "_seed", method="seed", extra=extra,
                          ref=0 if full else self.k_ref, commands=cmds)]
        reps_s = self.repeats if self.cost(sd[0]) < 60 else max(1, self.repeats - 1)
        while len(sd) < reps_s:
            sd.append(self.render(scene, base + "_rep", method="seed", extra=extra, commands=cmds))
        # no extra lights: direct light only
        ne = []
        if row.get("gi"):
            ne = [self.render(scene, base + "_nogi", extra=extra + ["--gi", "off"], commands=cmds)]
            reps_n = self.repeats if self.cost(ne[0]) < 60 else max(1, self.repeats - 1)
            while len(ne) < reps_n:
                ne.append(self.render(scene, base + "_rep", extra=extra + ["--gi", "off"], commands=cmds))
        # brute force
        br = None
        if full:
            br = self.render(scene, base + "_brute", method="brute", extra=extra, commands=cmds)
            res["err_lc"] = self.compare(br["exr"], lc[0]["exr"], base + "_err.png", cmds)
            res["err_seed"] = self.compare(br["exr"], sd[0]["exr"], base + "_seed_err.png", cmds)
            res["brute_time"] = br["time_render_s"]
            res["brute_approx"] = False
        else:
            res["brute_time"] = ref_stats["brute_seconds_estimate"]
            res["brute_approx"] = True
            res["err_lc"] = dict(mean_relative_error=ref_stats["mean_relative_error"],
                                 p99_relative_error=ref_stats["p99_relative_error"],
                                 fraction_over_2pct=ref_stats["fraction_over_2pct"],
                                 max_relative_error=ref_stats.get("max_relative_error"), pixels=ref_stats["pixels"])
            rs = sd[0].get("reference", {})
            res["err_seed"] = dict(mean_relative_error=rs.get("mean_relative_error"),
                                   p99_relative_error=rs.get("p99_relative_error"),
                                   fraction_over_2pct=rs.get("fraction_over_2pct"), pixels=rs.get("pixels"))
        res["brute_estimate"] = est
        res["brute_probe_pixels"] = lc[0]["reference"]["pixels"]
        res["lights"] = lc[0]["lights"]
        res["vpls"] = (lc[0].get("vpls") or {}).get("count", 0)
        res["object_lights"] = sum(o["lights"] for o in lc[0].get("object_lights", []))
        res["lc_time"] = median(self.cost(s) for s in lc)
        res["lc_times"] = [self.cost(s) for s in lc]
        res["lc_tree"] = median(s.get("time_tree_s", 0) for s in lc)
        res["lc_lights"] = lc[0]["avg_lights_per_shading_point"]
        res["lc_shadow_rays"] = lc[0]["avg_shadow_rays_per_shading_point"]
        res["seed_time"] = median(self.cost(s) for s in sd)
        res["seed_times"] = [self.cost(s) for s in sd]
        res["seed_lights"] = sd[0]["avg_lights_per_shading_point"]
        res["brute_lights"] = ref_stats.get("brute_lights_per_shading_point") or res["lights"]["total"]
        res["noextra_time"] = median(self.cost(s) for s in ne) if ne else None
        res["noextra_times"] = [self.cost(s) for s in ne]
        res["noextra_lights"] = ne[0]["lights"]["total"] if ne else None
        res["speedup"] = res["brute_time"] / res["lc_time"] if res["lc_time"] else None
        res["seed_speedup"] = res["brute_time"] / res["seed_time"] if res["seed_time"] else None
        res["vpl_clamped_fraction"] = lc[0].get("vpl_clamped_fraction")
        res["files"] = dict(lc=lc[0]["exr"], cut=lc[0]["cut_png"], seed=sd[0]["exr"],
                            brute=br["exr"] if br else None, err=base + "_err.png" if full else None,
                            nogi=ne[0]["exr"] if ne else None)
        res["commands"] = cmds
        res["seconds"] = now() - t_row
        res["commit"] = self.results["env"]["commit"]
        self.results["parts"][key] = res
        self.save()

    # --- scaling, accuracy ---------------------------------------------------------------

    def scaling(self):
        key = "scaling"
        if self.done(key):
            return
        t0 = now()
        out = dict(width=self.scaling_width, points=[], commands=[])
        for n in self.scaling_n:
            scene = os.path.join(self.work, f"scaling_{n}.ray")
            self.run([PY, os.path.join(HERE, "gen_scaling_scene.py"), str(n), scene], out["commands"])
            base = os.path.join(self.work, f"scaling_{n}")
            lc = [self.render(scene, base + "_lc", width=self.scaling_width, extra=["--error", "0.02"],
                              ref=self.k_probe, cut_heatmap=True, commands=out["commands"])]
            while len(lc) < self.repeats:
                lc.append(self.render(scene, base + "_rep", width=self.scaling_width, extra=["--error", "0.02"],
                                      commands=out["commands"]))
            sd = [self.render(scene, base + "_seed", method="seed", width=self.scaling_width,
                              ref=self.k_probe, commands=out["commands"])]
            while len(sd) < self.repeats:
                sd.append(self.render(scene, base + "_rep", method="seed", width=self.scaling_width,
                                      commands=out["commands"]))
            px = lc[0]["width"] * lc[0]["height"]
            r = lc[0]["reference"]
            rs = sd[0]["reference"]
            out["points"].append(dict(
                n=lc[0]["lights"]["total"], pixels=px,
                lc_render=median(s["time_render_s"] for s in lc), lc_tree=median(s["time_tree_s"] for s in lc),
                lc_lights=lc[0]["avg_lights_per_shading_point"],
                lc_shadow_rays=lc[0]["avg_shadow_rays_per_shading_point"],
                lc_tree_bytes=lc[0].get("tree_memory_bytes"),
                seed_render=median(s["time_render_s"] for s in sd), seed_tree=median(s["time_tree_s"] for s in sd),
                seed_lights=sd[0]["avg_lights_per_shading_point"],
                brute_estimate=r["brute_seconds_estimate"], brute_lights=r["brute_lights_per_shading_point"],
                lc_err=dict(mean=r["mean_relative_error"], p99=r["p99_relative_error"], over=r["fraction_over_2pct"]),
                seed_err=dict(mean=rs["mean_relative_error"], p99=rs["p99_relative_error"],
                              over=rs["fraction_over_2pct"]),
                ref_pixels=r["pixels"], exr=lc[0]["exr"], cut=lc[0]["cut_png"], seed_exr=sd[0]["exr"]))
        out["seconds"] = now() - t0
        out["commit"] = self.results["env"]["commit"]
        self.results["parts"][key] = out
        self.save()

    def accuracy(self):
        key = "accuracy"
        if self.done(key):
            return
        t0 = now()
        n = 100000
        cmds = []
        scene = os.path.join(self.work, f"scaling_{n}.ray")
        if not os.path.exists(scene):
            self.run([PY, os.path.join(HERE, "gen_scaling_scene.py"), str(n), scene], cmds)
        base = os.path.join(self.work, "accuracy")
        w = self.scaling_width
        lc = [self.render(scene, base + "_lc", width=w, extra=["--error", "0.02"], cut_heatmap=True, commands=cmds)]
        while len(lc) < self.repeats:
            lc.append(self.render(scene, base + "_rep", width=w, extra=["--error", "0.02"], commands=cmds))
        br = self.render(scene, base + "_brute", method="brute", width=w, commands=cmds)
        err = self.compare(br["exr"], lc[0]["exr"], base + "_err.png", cmds)
        self.results["parts"][key] = dict(
            n=lc[0]["lights"]["total"], width=w, err=err, lc_time=median(self.cost(s) for s in lc),
            lc_render=median(s["time_render_s"] for s in lc), lc_tree=median(s["time_tree_s"] for s in lc),
            lc_lights=lc[0]["avg_lights_per_shading_point"], brute_time=br["time_render_s"],
            files=dict(lc=lc[0]["exr"], brute=br["exr"], err=base + "_err.png", cut=lc[0]["cut_png"]),
            commands=cmds, seconds=now() - t0, commit=self.results["env"]["commit"])
        self.save()

    # --- micro benchmarks ----------------------------------------------------------------

    def micro(self):
        key = "micro"
        if self.done(key):
            return
        t0 = now()
        cmds = []
        bench = os.path.join(self.build, "bench")
        mt = "0.05" if self.quick else "0.5"
        reps = "1" if self.quick else "3"
        out = dict(commands=cmds)
        for name, filt in (("rays", None), ("tree", "TreeBuild"), ("eval", "Evaluate")):
            exe = os.path.join(bench, "rays_bench" if name == "rays" else "lightcuts_bench")
            if not os.path.exists(exe):
                out[name] = None
                continue
            cmd = [exe, "--benchmark_format=json", f"--benchmark_min_time={mt}",
                   f"--benchmark_repetitions={reps}"]
            if reps != "1":
                cmd.append("--benchmark_report_aggregates_only=true")
            if filt:
                cmd.append(f"--benchmark_filter={filt}")
            data = json.loads(self.run(cmd, cmds, capture=True))
            rows = []
            for b in data["benchmarks"]:
                if b.get("run_type") == "aggregate" and b.get("aggregate_name") != "median":
                    continue
                rows.append(dict(name=b.get("run_name", b["name"]), label=b.get("label", ""),
                                 real_time=b["real_time"], unit=b["time_unit"],
                                 counters={k: v for k, v in b.items() if k in ("rays/s", "hit fraction", "lights/s",
                                                                               "points/s", "cut")}))
            out[name] = rows
        out["seconds"] = now() - t0
        out["commit"] = self.results["env"]["commit"]
        self.results["parts"][key] = out
        self.save()

    # --- images ----------------------------------------------------------------------------

    def load_exr(self, path):
        import numpy as np
        pfm = os.path.join(self.work, "tmp_convert.pfm")
        self.run(["convert", path, pfm])
        with open(pfm, "rb") as f:
            kind = f.readline().strip()
            w, h = map(int, f.readline().split())
            scale = float(f.readline())
            data = np.frombuffer(f.read(), dtype="<f4" if scale < 0 else ">f4")
        ch = 3 if kind == b"PF" else 1
        img = data.reshape(h, w, ch)[::-1]
        if ch == 1:
            img = np.repeat(img, 3, axis=2)
        return img

    def tonemap(self, exr):
        """The renderer's default 8-bit output (--tonemap srgb: the sRGB encoding of the clamped
        linear values, as src/io/image.cpp's quantize8), as a PIL image."""
        import numpy as np
        from PIL import Image
        v = np.clip(np.nan_to_num(self.load_exr(exr)), 0, 1)
        v = np.where(v <= 0.0031308, 12.92 * v, 1.055 * np.power(v, 1 / 2.4) - 0.055)
        return Image.fromarray((v * 255 + 0.5).astype("uint8"), "RGB")

    def tile(self, img, label, width):
        from PIL import Image, ImageDraw
        if img.width != width:
            img = img.resize((width, max(1, round(img.height * width / img.width))), Image.LANCZOS)
        t = Image.new("RGB", (width, img.height + 16), (255, 255, 255))
        t.paste(img, (0, 16))
        ImageDraw.Draw(t).text((3, 2), label, fill=(0, 0, 0))
        return t

    def montage(self, tiles, out, width=512, cols=2):
        """Tiles [(PIL image, label)] in a grid `width` wide; saved as a small PNG."""
        from PIL import Image
        tw = (width - 4 * (cols - 1)) // cols
        made = [self.tile(im, lab, tw) for im, lab in tiles]
        rows = [made[i:i + cols] for i in range(0, len(made), cols)]
        hts = [max(t.height for t in r) for r in rows]
        sheet = Image.new("RGB", (width, sum(hts) + 4 * (len(rows) - 1)), (255, 255, 255))
        y = 0
        for r, h in zip(rows, hts):
            for i, t in enumerate(r):
                sheet.paste(t, (i * (tw + 4), y))
            y += h + 4
        self.save_png(sheet, out)

    def save_png(self, img, out, limit=150_000):
        img.save(out, optimize=True)
        if os.path.getsize(out) > limit:
            img.quantize(256, dither=0).save(out, optimize=True)
        if os.path.getsize(out) > limit:
            img.quantize(128).save(out, optimize=True)

    def images_for_rows(self):
        from PIL import Image
        made = {}
        for row in ROWS:
            r = self.results["parts"].get("row:" + row["key"])
            if not r:
                continue
            f = r["files"]
            tiles = []
            if f.get("brute"):
                tiles.append((self.tonemap(f["brute"]), "brute force"))
            tiles.append((self.tonemap(f["lc"]), "lightcuts"))
            if f.get("err"):
                tiles.append((Image.open(f["err"]).convert("RGB"), "relative error vs brute force"))
            else:
                tiles.append((self.tonemap(f["seed"]), "seed's method"))
            tiles.append((Image.open(f["cut"]).convert("RGB"), "cut size (lights per pixel)"))
            name = f"bench_{row['key']}.png"
            self.montage(tiles, os.path.join(self.images, name))
            made[row["key"]] = dict(main=name)
            if f.get("nogi") and row.get("pair", True):
                gname = f"bench_{row['key']}_gi.png"
                self.montage([(self.tonemap(f["nogi"]), "without GI (--gi off)"),
                              (self.tonemap(f["lc"]), f"with GI ({r['vpls']:,} VPLs)")],
                             os.path.join(self.images, gname))
                made[row["key"]]["gi"] = gname
        return made

    def scaling_plot(self):
        sc = self.results["parts"].get("scaling")
        if not sc:
            return None
        import matplotlib
        matplotlib.use("Agg")
        import matplotlib.pyplot as plt
        pts = sc["points"]
        n = [p["n"] for p in pts]
        us = lambda t, p: 1e6 * t / p["pixels"]  # noqa: E731
        fig, ax = plt.subplots(1, 3, figsize=(5.12, 2.3), dpi=100)
        ax[0].loglog(n, [us(p["lc_render"] + p["lc_tree"], p) for p in pts], "o-", label="lightcuts")
        ax[0].loglog(n, [us(p["seed_render"] + p["seed_tree"], p) for p in pts], "s-", label="seed")
        ax[0].loglog(n, [us(p["brute_estimate"], p) for p in pts], "^--", label="brute (est.)")
        ax[0].set_title("µs per pixel", fontsize=8)
        ax[1].loglog(n, [p["lc_lights"] for p in pts], "o-", label="lightcuts")
        ax[1].loglog(n, [p["seed_lights"] for p in pts], "s-", label="seed")
        ax[1].loglog(n, n, "^--", label="brute")
        ax[1].set_title("lights per point", fontsize=8)
        ax[2].loglog(n, [max(p["lc_tree"], 1e-4) for p in pts], "o-", label="walter")
        ax[2].loglog(n, [max(p["seed_tree"], 1e-4) for p in pts], "s-", label="seed")
        ax[2].set_title("tree build (s)", fontsize=8)
        for a in ax:
            a.set_xlabel("lights", fontsize=7)
            a.tick_params(labelsize=6)
            a.grid(True, which="major", alpha=0.3)
        ax[0].legend(fontsize=6)
        ax[2].legend(fontsize=6)
        fig.tight_layout(pad=0.4)
        out = os.path.join(self.images, "bench_scaling.png")
        fig.savefig(out)
        plt.close(fig)
        return "bench_scaling.png"

    def accuracy_image(self):
        acc = self.results["parts"].get("accuracy")
        if not acc:
            return None
        from PIL import Image
        f = acc["files"]
        self.montage([(self.tonemap(f["brute"]), "brute force"), (self.tonemap(f["lc"]), "lightcuts, --error 0.02"),
                      (Image.open(f["err"]).convert("RGB"), "relative error"),
                      (Image.open(f["cut"]).convert("RGB"), "cut size")],
                     os.path.join(self.images, "bench_accuracy.png"))
        return "bench_accuracy.png"

    # --- the Markdown ----------------------------------------------------------------------

    def markdown(self, imgs, scaling_png, acc_png):
        env = self.results["env"]
        P = self.results["parts"]
        img_dir = os.path.relpath(self.images, os.path.dirname(self.md))
        L = []
        L.append(BEGIN)
        L.append("")
        L.append("## Measured results (generated by `make bench`: do not edit between the markers)")
        L.append("")
        other = sorted({p.get("commit") for p in P.values()} - {env["commit"], None})
        dirty = " (with uncommitted changes in: " + ", ".join(f"`{d}`" for d in env["dirty_files"]) + ")" \
            if env["dirty"] else " (clean tree)"
        L.append(f"- **Commit** `{env['commit']}`{dirty}; **mode** {env['mode']}"
                 f"{' (BENCH_QUICK=1: small images, one run each; not the real figures)' if env['mode'] == 'quick' else ''}.")
        if other:
            L.append("- Some parts were measured at other commits (" + ", ".join(f"`{c}`" for c in other) +
                     "): " + ", ".join(k.split(":")[-1] + f" at `{p.get('commit')}`" for k, p in P.items()
                                       if p.get("commit") in other) + ".")
        L.append(f"- **Machine** {env['cpu']}, {env['nproc']} cores (`nproc`), load average {env['loadavg_start']:.2f} "
                 f"at the start; **date** {env['date']}; build `{env['build']}` (Release).")
        tot = sum(p.get("seconds", 0) for p in P.values())
        L.append(f"- **Driver** `scripts/bench.py` (`make bench`), {tot / 60:.0f} min of measurements. Other work "
                 "shared the machine at times: each time is the median of repeated runs (3, or 2 when one run takes "
                 "over a minute; 1 in quick mode), and each ratio is taken within one run of the driver.")
        L.append(f"- **Times** are the render phase plus the light-tree build (`time_render_s + time_tree_s` from "
                 f"`--stats`), wall clock on {env['nproc']} threads; loading, BVH and VPL generation are the same for "
                 f"every method and left out. Brute force is rendered in full when the estimate from "
                 f"`--reference-pixels {env['k_probe']}` is under {env['brute_limit']} s; otherwise its time is that "
                 f"estimate, marked **~**, and errors are measured at `--reference-pixels {env['k_ref']}` pixels "
                 "instead of the whole image.")
        L.append("")

        # table 1: the seed's table
        L.append(f"### The seed's table, reproduced ({env['width']}×{env['width']})")
        L.append("")
        L.append("| Test case | Lights | No extra lights | Brute force | Lightcuts | Speed-up | Lights per shading point, "
                 "brute → lightcuts (cut nodes / shadow rays) | Seed's method (time, lights/point, speed-up; its error: "
                 "mean, pixels over 2%) | "
                 "The seed's figures |")
        L.append("|---|---|---|---|---|---|---|---|---|")
        for row in ROWS:
            r = P.get("row:" + row["key"])
            if not r:
                continue
            lights = f"{r['lights']['total']:,}"
            if r["vpls"]:
                lights += f" ({r['object_lights']:,} object + {r['vpls']:,} VPLs)"
            noextra = "N/A" if not r["gi"] else f"{fmt_time(r['noextra_time'])} ({r['noextra_lights']:,} lights)"
            L.append(f"| {r['name']} | {lights} | {noextra} | {fmt_time(r['brute_time'], r['brute_approx'])} | "
                     f"{fmt_time(r['lc_time'])} | {'~' if r['brute_approx'] else ''}{r['speedup']:.1f}× | "
                     f"{r['brute_lights']:,.0f} → {r['lc_lights']:.1f} / {r.get('lc_shadow_rays', 0):.1f} | "
                     f"{fmt_time(r['seed_time'])}, "
                     f"{r['seed_lights']:.1f}, {'~' if r['brute_approx'] else ''}{r['seed_speedup']:.1f}×; "
                     f"error {fmt_pct(r['err_seed'].get('mean_relative_error'))}, "
                     f"{fmt_pct(r['err_seed'].get('fraction_over_2pct'))} | "
                     f"{row.get('seed', '')} |")
        L.append("")
        L.append("The seed's rows: Green light emitter 43 s → 7 s and 11.8 → 1.5 lights per pixel (its Luminous object "
                 "line); Cornell box 2 s (no extra lights) / 2031 s (no lightcuts) / 95 s (lightcuts) with 8,638 VPLs, "
                 "8,638 → 273.6 VPLs per pixel. The seed's \"lights per pixel\" counted its coalesced lights, each "
                 "with a shadow ray. Ours gives two figures per shading point: the cut size (light-tree nodes whose "
                 "light is evaluated) and the shadow rays sent. Lightcuts runs with its defaults: first-order "
                 "estimates, visibility probes and reconstruction cuts (`--reconstruct auto`, every 4 pixels at "
                 "512×512, every 8 where the corners of a cell of 8 agree): points between samples evaluate their "
                 "samples' merged cut (the finer cut where the samples' visibility differs, the coarser where all "
                 "saw it visible and smooth), borrowing "
                 "visibility where the samples agree, so most of their nodes need no shadow ray.")
        L.append("")

        # table 2: errors
        L.append("### Error against brute force")
        L.append("")
        L.append("Relative error of each pixel's luminance against brute force (`lightcuts compare`; over the whole "
                 "image, or at the reference pixels where brute force was extrapolated).")
        L.append("")
        L.append("| Test case | Measured over | Lightcuts: mean | p99 | pixels over 2% | Seed's method: mean | p99 | "
                 "pixels over 2% |")
        L.append("|---|---|---|---|---|---|---|---|")
        for row in ROWS:
            r = P.get("row:" + row["key"])
            if not r:
                continue
            e, s = r["err_lc"], r["err_seed"]
            over = f"{r['err_lc']['pixels']:,} reference pixels" if r["brute_approx"] else f"{r['width']}×{r['width']} image"
            L.append(f"| {r['name']} | {over} | {fmt_pct(e.get('mean_relative_error'))} | "
                     f"{fmt_pct(e.get('p99_relative_error'))} | {fmt_pct(e.get('fraction_over_2pct'))} | "
                     f"{fmt_pct(s.get('mean_relative_error'))} | {fmt_pct(s.get('p99_relative_error'))} | "
                     f"{fmt_pct(s.get('fraction_over_2pct'))} |")
        L.append("")
        n_rows = sum(1 for x in ROWS if P.get("row:" + x["key"]))
        bad_seed = [P["row:" + x["key"]]["name"] for x in ROWS if P.get("row:" + x["key"]) and
                    (P["row:" + x["key"]]["err_seed"].get("fraction_over_2pct") or 0) > 0.5]
        if bad_seed:
            where = "every row" if len(bad_seed) == n_rows else ", ".join(bad_seed)
            L.append(f"The seed's method is fast but not accurate: over half of the pixels are more than 2% off in "
                     f"{where}. On the emitter scenes its images are mostly black: a cluster's "
                     "representative is the intensity-weighted mean of its lights' positions, which for a closed "
                     "emitter (the sphere, the torus) lies inside it, so the representative's shadow ray is blocked "
                     "by the emitter itself, and the one-level fallback to the two children does not escape it "
                     "(see the seed's-method tiles below, shown where brute force was extrapolated). Its "
                     "speed-ups are therefore not "
                     "comparable with Lightcuts', whose error is bounded.")
            L.append("")

        # images
        L.append("### Images")
        L.append("")
        L.append("Each scene: brute force, lightcuts, the relative-error heatmap of lightcuts against brute force "
                 "(scale 0–5%) and the cut size per pixel; where brute force was extrapolated there is no full "
                 "brute-force image, and the seed's method takes its place beside lightcuts. Then, for scenes with "
                 "global illumination, the image without (`--gi off`) and with it.")
        L.append("")
        for row in ROWS:
            if row["key"] not in imgs:
                continue
            r = P["row:" + row["key"]]
            L.append(f"**{r['name']}** (`{r['scene']}`)")
            L.append("")
            L.append(f"![{r['name']}: brute force, lightcuts, error, cut size]({img_dir}/{imgs[row['key']]['main']})")
            L.append("")
            if "gi" in imgs[row["key"]]:
                desc = GI_DESCRIPTIONS.get(row["key"], "")
                L.append(f"![{r['name']}: without and with global illumination]({img_dir}/{imgs[row['key']]['gi']})")
                L.append("")
                if desc:
                    L.append(f"*Without / with GI:* {desc}")
                    L.append("")

        # scaling
        sc = P.get("scaling")
        if sc:
            L.append(f"### Scaling: 1k to 1M lights ({sc['width']}×{sc['width']})")
            L.append("")
            L.append("`scripts/gen_scaling_scene.py N`: a 16×16 grid of luminous panels over a floor with occluders, "
                     "N oriented lights in all, the same total power at every N. Lightcuts at `--error 0.02`, the "
                     "seed's method at its default; brute force estimated from reference pixels (marked ~). Time per "
                     "pixel is wall clock on all cores, render plus tree build.")
            L.append("")
            L.append("| Lights | Lightcuts µs/pixel | cut size | tree build | Seed µs/pixel | seed lights/point | seed tree "
                     "build | Brute µs/pixel | Lightcuts speed-up | Lightcuts error (mean / p99 / >2%) | Seed error "
                     "(mean / p99 / >2%) |")
            L.append("|---|---|---|---|---|---|---|---|---|---|---|")
            for p in sc["points"]:
                us = lambda t: 1e6 * t / p["pixels"]  # noqa: E731
                lt = p["lc_render"] + p["lc_tree"]
                st = p["seed_render"] + p["seed_tree"]
                L.append(f"| {p['n']:,} | {us(lt):.1f} | {p['lc_lights']:.1f} ({100 * p['lc_lights'] / p['n']:.2g}%) | "
                         f"{p['lc_tree'] * 1000:.0f} ms | {us(st):.1f} | {p['seed_lights']:.1f} | "
                         f"{p['seed_tree'] * 1000:.0f} ms | ~{us(p['brute_estimate']):.0f} | "
                         f"~{p['brute_estimate'] / lt:.1f}× | {fmt_pct(p['lc_err']['mean'])} / "
                         f"{fmt_pct(p['lc_err']['p99'])} / {fmt_pct(p['lc_err']['over'])} | "
                         f"{fmt_pct(p['seed_err']['mean'])} / {fmt_pct(p['seed_err']['p99'])} / "
                         f"{fmt_pct(p['seed_err']['over'])} |")
            L.append("")
            L.append(f"Errors at {sc['points'][0]['ref_pixels']} reference pixels per size.")
            L.append("")
            if scaling_png:
                L.append(f"![Scaling: time per pixel, lights per point, tree build]({img_dir}/{scaling_png})")
                L.append("")

        acc = P.get("accuracy")
        if acc:
            e = acc["err"]
            L.append(f"### Accuracy at {acc['n']:,} lights ({acc['width']}×{acc['width']})")
            L.append("")
            L.append(f"The scaling scene at {acc['n']:,} lights, brute force over the whole image against "
                     f"`--method lightcuts --error 0.02`:")
            L.append("")
            L.append("| Brute force | Lightcuts | Speed-up | Cut size | Mean rel. error | p99 | Pixels over 2% | "
                     "RMSE | PSNR |")
            L.append("|---|---|---|---|---|---|---|---|---|")
            L.append(f"| {fmt_time(acc['brute_time'])} | {fmt_time(acc['lc_time'])} | "
                     f"{acc['brute_time'] / acc['lc_time']:.1f}× | {acc['lc_lights']:.1f} "
                     f"({100 * acc['lc_lights'] / acc['n']:.2f}% of the lights) | {fmt_pct(e['mean_relative_error'])} | "
                     f"{fmt_pct(e['p99_relative_error'])} | {fmt_pct(e['fraction_over_2pct'])} | {e['rmse']:.4g} | "
                     f"{e['psnr']:.1f} dB |")
            L.append("")
            if acc_png:
                L.append(f"![Accuracy: brute force, lightcuts, error, cut size]({img_dir}/{acc_png})")
                L.append("")

        mi = P.get("micro")
        if mi:
            L.append("### Ray throughput and tree builds")
            L.append("")
            L.append("Google Benchmark (`build/bench/rays_bench`, `build/bench/lightcuts_bench`), single-threaded, "
                     + ("median of 3 repetitions." if not self.quick else "one repetition."))
            L.append("")
            if mi.get("rays"):
                L.append("| Rays | Scene | Rays per second (one core) |")
                L.append("|---|---|---|")
                for b in mi["rays"]:
                    kind = "primary (closest hit)" if b["name"].startswith("Primary") else "shadow (occlusion, incoherent)"
                    L.append(f"| {kind} | {b['label']} | {b['counters'].get('rays/s', 0) / 1e6:.2f} M |")
                L.append("")
            if mi.get("tree"):
                L.append("| Tree build | Lights | Time |")
                L.append("|---|---|---|")
                for b in mi["tree"]:
                    n = int(b["name"].split("/")[1])
                    L.append(f"| {b['label']} | {n:,} | {b['real_time']:.1f} {b['unit']} |")
                L.append("")
            if mi.get("eval"):
                L.append("| Evaluator (no shadow rays) | Lights | Shading points per second | Cut size |")
                L.append("|---|---|---|---|")
                for b in mi["eval"]:
                    n = int(b["name"].split("/")[1])
                    L.append(f"| {b['label']} | {n:,} | {b['counters'].get('points/s', 0):,.0f} | "
                             f"{b['counters'].get('cut', 0):.1f} |")
                L.append("")

        L += self.goals()

        L.append("### Commands")
        L.append("")
        L.append("<details><summary>Every command the driver ran, in order</summary>")
        L.append("")
        L.append("```")
        for key in sorted(P, key=lambda k: list(P).index(k)):
            for c in P[key].get("commands", []):
                L.append(c)
        L.append("```")
        L.append("")
        L.append("</details>")
        L.append("")
        L.append(END)
        return "\n".join(L)

    def goals(self):
        P = self.results["parts"]
        L = ["### Goals", ""]

        def mark(ok):
            return "met" if ok else "**not met**"

        def row(k):
            return P.get("row:" + k)

        g = []
        for k, target, what in (("green", 6.1, "the seed's 6× on the emitter scene"),
                                ("green_dense", 6.1, "the seed's 6× on the emitter scene (dense variant)"),
                                ("luminous_dense", 6.1, "the seed's 6× (luminous object, dense variant)"),
                                ("cornell", 25.0, "≥ 25× on the Cornell box with ~8,638 VPLs (seed: 21×)"),
                                ("cornell_100k", 100.0, "≥ 100× on the Cornell box with 100,000 VPLs")):
            r = row(k)
            if r:
                g.append(f"- {what}: {r['speedup']:.1f}× — {mark(r['speedup'] >= target)}")
        r = row("cornell")
        if r:
            rays = r.get("lc_shadow_rays", r["lc_lights"])
            g.append(f"- fewer lights per shading point than the seed on the Cornell box (273.6): cut "
                     f"{r['lc_lights']:.1f} nodes — {mark(r['lc_lights'] < 273.64)}; shadow rays (lights tested "
                     f"for visibility) {rays:.1f} — {mark(rays < 273.64)}")
        r = row("green12")
        if r:
            # The seed's "lights per pixel" were coalesced lights, each with a shadow ray: the figure
            # to compare is the shadow rays; the cut nodes (many shaded with borrowed visibility) are
            # given beside it.
            rays = r.get("lc_shadow_rays", r["lc_lights"])
            g.append(f"- fewer lights per shading point than the seed on the emitter (11.8 → 1.5), at its light "
                     f"count ({r['lights']['total']:,} lights, brute force {r['brute_lights']:,.1f} per point): shadow "
                     f"rays {rays:.2f} — {mark(rays < 1.50233)}, with {100 * (1 - r['err_lc']['fraction_over_2pct']):.2f}% "
                     f"of pixels within 2%; cut nodes {r['lc_lights']:.1f} — {mark(r['lc_lights'] < 1.50233)} (the seed's "
                     f"method here: {r['seed_lights']:.1f} lights, "
                     f"{100 * (r['err_seed'].get('fraction_over_2pct') or 0):.0f}% of pixels over 2%)")
        r = row("green")
        if r:
            n, rays = r["lights"]["total"], r.get("lc_shadow_rays", r["lc_lights"])
            g.append(f"- the same on the {n:,}-light emitter: {r['lc_lights']:.1f} cut nodes / {rays:.1f} shadow "
                     f"rays against the seed's 1.5 — {mark(rays < 1.50233)} (a bound of 2% with {n:,} lights "
                     f"this close to their receivers needs ~{r['lc_lights']:.0f} clusters; the seed's method here: "
                     f"{r['seed_lights']:.1f} lights, {100 * (r['err_seed'].get('fraction_over_2pct') or 0):.0f}% of "
                     "pixels over 2%)")
        bad = [P["row:" + x["key"]]["name"] for x in ROWS
               if P.get("row:" + x["key"]) and (P["row:" + x["key"]]["err_lc"].get("fraction_over_2pct") or 0) > 0.01]
        n_rows = sum(1 for x in ROWS if P.get("row:" + x["key"]))
        if n_rows:
            g.append(f"- ≥ 99% of pixels within 2% of brute force: {n_rows - len(bad)} of {n_rows} rows — "
                     f"{mark(not bad)}" + (f" (not: {', '.join(bad)})" if bad else ""))
        acc = P.get("accuracy")
        if acc:
            e = acc["err"]
            sp = acc["brute_time"] / acc["lc_time"]
            g.append(f"- {acc['n']:,} lights, {acc['width']}×{acc['width']}: ≥ 99% of pixels within 2%: "
                     f"{100 * (1 - e['fraction_over_2pct']):.2f}% — {mark(e['fraction_over_2pct'] <= 0.01)}; "
                     f"cut ≤ 1% of the lights: {acc['lc_lights']:.0f} — {mark(acc['lc_lights'] <= 0.01 * acc['n'])}; "
                     f"≥ 50× faster than brute force: {sp:.1f}× — {mark(sp >= 50)}")
        sc = P.get("scaling")
        if sc and len(sc["points"]) >= 2:
            a, b = sc["points"][0], sc["points"][-1]
            grow = ((b["lc_render"] + b["lc_tree"]) / (a["lc_render"] + a["lc_tree"]))
            g.append(f"- sub-linear growth 1k → 1M lights: time per pixel ×{grow:.1f} for ×{b['n'] / a['n']:.0f} lights "
                     f"— {mark(grow < b['n'] / a['n'])}")
        mi = P.get("micro")
        if mi and mi.get("tree"):
            t = [x for x in mi["tree"] if x["name"].split("/")[1] == "1000000"]
            if t:
                worst = max(x["real_time"] * (1e-3 if x["unit"] == "ms" else 1) for x in t)
                g.append(f"- 1,000,000 lights tree build under 3 s: {worst:.2f} s — {mark(worst < 3)}")
        return L + g + [""]

    def write(self):
        imgs = self.images_for_rows()
        scaling_png = self.scaling_plot()
        acc_png = self.accuracy_image()
        section = self.markdown(imgs, scaling_png, acc_png)
        if os.path.exists(self.md):
            text = open(self.md).read()
        else:
            text = ("# Benchmarks\n\nThis product's figures beside the seed's (docs/SEED.md): the scene suite under "
                    "`scenes/`, rendered by brute force, Lightcuts and the seed's method. Regenerate the section "
                    "between the markers with `make bench` (`BENCH_QUICK=1` for a quick check, written to "
                    "`out/bench-quick/`); `make report` turns this page into `docs/report.html`.\n\n"
                    f"{BEGIN}\n{END}\n")
        if BEGIN in text and END in text:
            pre = text[:text.index(BEGIN)]
            post = text[text.index(END) + len(END):]
            text = pre + section + post
        else:
            text = text.rstrip() + "\n\n" + section + "\n"
        tmp = self.md + ".tmp"
        open(tmp, "w").write(text)
        os.replace(tmp, self.md)
        print(f"bench: wrote {self.rel(self.md)} and images in {self.rel(self.images)}")

    # --- main --------------------------------------------------------------------------------

    def check_exr_reader(self):
        """Fails before measuring, not an hour later, when ImageMagick cannot read the renders."""
        try:
            formats = subprocess.run(["convert", "-list", "format"], capture_output=True, text=True).stdout
        except OSError:
            formats = ""
        if not re.search(r"^\s*EXR\*?\s+EXR\s+r", formats, re.M):
            raise SystemExit("bench: ImageMagick's convert cannot read OpenEXR; install imagemagick and "
                             "libmagickcore-6.q16-6-extra (scripts/bench.sh does)")

    def main(self):
        self.check_exr_reader()
        if not self.a.write_only:
            if not os.path.exists(self.lc):
                raise SystemExit(f"bench: {self.rel(self.lc)} not found: build first (make build BUILD=...)")
            env = self.environment()
            old = self.results.get("env")
            if old and old.get("commit") == env["commit"] and self.a.resume:
                env["loadavg_start"] = old.get("loadavg_start", env["loadavg_start"])
            self.results["env"] = env
            only = set(self.a.only or [])
            parts = [("row:" + r["key"], lambda r=r: self.table_row(r)) for r in ROWS]
            parts += [("scaling", self.scaling), ("accuracy", self.accuracy), ("micro", self.micro)]
            t0 = now()
            for key, fn in parts:
                short = key.split(":")[-1]
                if only and short not in only and key not in only and not (key.startswith("row:") and "table" in only):
                    continue
                t = now()
                print(f"bench: {short} ...", flush=True)
                fn()
                print(f"bench: {short} done in {now() - t:.0f} s (total {(now() - t0) / 60:.1f} min)", flush=True)
        self.write()


def main():
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--build", default=os.environ.get("BUILD", "build"), help="build folder (default $BUILD or build)")
    ap.add_argument("--quick", action="store_true", default=os.environ.get("BENCH_QUICK", "") not in ("", "0"),
                    help="small sizes, one run each (also BENCH_QUICK=1)")
    ap.add_argument("--work", help="folder for renders and results.json (default out/bench or out/bench-quick)")
    ap.add_argument("--docs", action="store_true", help="in quick mode, write docs/ too")
    ap.add_argument("--resume", action="store_true", help="reuse parts already measured at this commit")
    ap.add_argument("--write-only", action="store_true", help="only rewrite the Markdown and images from results.json")
    ap.add_argument("--only", nargs="*", help="parts to run: row keys (" + ", ".join(r["key"] for r in ROWS) +
                    "), table, scaling, accuracy, micro")
    a = ap.parse_args()
    Driver(a).main()


if __name__ == "__main__":
    main()
