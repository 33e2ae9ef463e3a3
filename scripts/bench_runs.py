"""Running things for the benchmark driver (scripts/bench.py): one run's settings (quick or
full sizes, the work folder, where the Markdown and images go), the lightcuts binary's
`render --stats`, `compare --json` and `info --json`, the log, the cache of measured parts in
results.json (--resume, --write-only) and the machine's description."""
import datetime
import json
import os
import re
import shlex
import statistics
import subprocess
import sys
import time

from bench_scenes import SCALING_N

HERE = os.path.dirname(os.path.abspath(__file__))
ROOT = os.path.dirname(HERE)
PY = sys.executable or "/usr/bin/python3"


def now():
    return time.monotonic()


def median(xs):
    xs = [x for x in xs if x is not None]
    return statistics.median(xs) if xs else None


class Driver:
    """One run of the driver: its settings (from the command line), the binary, results.json."""

    def __init__(self, a):
        self.a = a
        self.quick = a.quick
        self.build = a.build if os.path.isabs(a.build) else os.path.join(ROOT, a.build)
        self.lc = os.path.join(self.build, "lightcuts")
        self.work = os.path.join(ROOT, a.work or ("out/bench-quick" if self.quick else "out/bench"))
        if a.docs or (not self.quick and not getattr(a, "no_docs", False)):
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
        if getattr(self.a, "threads", 0):
            cmd += ["--threads", str(self.a.threads)]
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

    def check_exr_reader(self):
        """Fails before measuring, not an hour later, when ImageMagick cannot read the renders."""
        try:
            formats = subprocess.run(["convert", "-list", "format"], capture_output=True, text=True).stdout
        except OSError:
            formats = ""
        if not re.search(r"^\s*EXR\*?\s+EXR\s+r", formats, re.M):
            raise SystemExit("bench: ImageMagick's convert cannot read OpenEXR; install imagemagick and "
                             "libmagickcore-6.q16-6-extra (scripts/bench.sh does)")
