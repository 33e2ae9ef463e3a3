#!/usr/bin/env python3
"""Checks that two lightcuts binaries render the same images, bit for bit: a refactoring
must not change what the renderer computes (issue 28). Python's standard library only.

    OLD=/tmp/lc_before NEW=build/lightcuts scripts/check_identical.py            # the suite
    OLD=... NEW=... scripts/check_identical.py --quick                          # a fast subset
    OLD=... NEW=... scripts/check_identical.py scenes/cornell_box.ray --size 32 # some scenes

Each scene renders with each binary, small (--size, default 64 x 64; 136 x 136 under
reconstruction cuts, whose tiles are 64 pixels) and with --threads (default 2), to an EXR with every AOV layer (cut size and shadow rays per pixel too). The
binaries run from twin folders as `./lightcuts` with the same arguments, so the files' text
metadata (the command line) agrees and the EXR files must be equal byte for byte. Beside the
default render, variants exercise what the default at this size leaves out: reconstruction
cuts and reference pixels, the other methods, --vpl-normalize object, the other values of the
options with named values. The --stats values that depend only on the image and the pixels
(the reference pixels' errors, the counters of a render without reconstruction cuts: those
with them count samples that two tiles may both make, depending on timing) must be equal
too. Exit status 0 when everything matches, 1 otherwise; each difference is named, with
`lightcuts compare`'s numbers for the image."""

import argparse
import filecmp
import glob
import json
import os
import subprocess
import sys
import tempfile
import time

ROOT = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))

# Every scene renders once per variant: name -> (flags, size or None for --size). Under
# reconstruction cuts tiles are 64 pixels or more, so that variant renders 136 x 136: nine
# tiles that share the samples on their edges, the last ones partial.
VARIANTS = {
    "default": ([], None),
    "recon": (["--reconstruct", "4", "--reference-pixels", "64"], 136),
}
# Variants on one scene each (scene, name, flags, size or None): paths the suite's defaults
# do not take.
EXTRA = [
    ("scenes/cornell_box.ray", "recon-coarse0", ["--reconstruct", "2", "--reconstruct-coarse", "0"], 80),
    ("scenes/cornell_box.ray", "recon-spp2-aa24", ["--reconstruct", "4", "--spp", "2", "--aa-samples", "24"], 136),
    ("scenes/cornell_box.ray", "seed", ["--method", "seed", "--reference-pixels", "32"], None),
    ("scenes/cornell_box.ray", "stochastic", ["--method", "stochastic", "--spp", "2"], None),
    ("scenes/cornell_box.ray", "brute", ["--method", "brute", "--vpls", "500"], None),
    ("scenes/cornell_box.ray", "vpl-object", ["--vpl-normalize", "object", "--vpls", "2000"], None),
    ("scenes/cornell_box.ray", "probes-off-walter",
     ["--visibility-probes", "off", "--cut-criterion", "walter", "--gi", "off", "--aa", "off"], None),
    ("scenes/cornell_box.ray", "clear-off", ["--clear-clusters", "off", "--aa", "off"], None),
    ("scenes/green_light_emitter.ray", "error-floor0", ["--error-floor", "0", "--error", "0.05"], None),
    # The named values other than the defaults, aliases among them.
    ("scenes/cornell_box.ray", "course-tree-omni",
     ["--tree", "course", "--estimator", "representative", "--object-lights", "omni",
      "--object-light-placement", "course"], None),
    ("scenes/mirror_ring.ray", "caustic-spot", ["--caustic-lights", "spot", "--caustics", "20000"], None),
]
QUICK = ["scenes/cornell_box.ray", "scenes/green_light_emitter.ray", "scenes/mirror_ring.ray",
         "scenes/ball_lens.ray", "scenes/features/spotlights.ray"]
AOVS = "albedo,normal,depth,cut,shadow_rays"

# --stats keys whose values depend only on the image and the pixels.
STABLE_KEYS = ["width", "height", "method", "error_threshold", "max_cut", "error_floor", "error_floor_pixels",
               "reconstruct_spacing", "reconstruct_coarse_spacing", "lights", "tree_nodes", "vpl_clamped_fraction",
               "aa_pixels", "object_lights", "environment_lights"]
REFERENCE_KEYS = ["pixels", "mean_relative_error", "p99_relative_error", "max_relative_error", "fraction_over_2pct",
                  "fraction_over_threshold", "threshold", "brute_lights_per_shading_point"]
# Counters that tiles sharing reconstruction samples make timing-dependent; stable without them.
COUNTER_KEYS = ["primary_rays", "secondary_rays", "shadow_rays", "shading_points", "avg_lights_per_shading_point",
                "bounds_evaluated", "cut_histogram", "aa_sub_samples", "reconstructed_points", "cuts_at_max_cut"]


def run(binary, folder, scene, flags, size, threads):
    """Renders `scene` with `binary` as ./lightcuts in `folder`; returns the stats (or None) and stderr."""
    os.makedirs(folder, exist_ok=True)
    link = os.path.join(folder, "lightcuts")
    if not os.path.lexists(link):
        os.symlink(os.path.abspath(binary), link)
    for f in ("img.exr", "stats.json"):
        if os.path.exists(os.path.join(folder, f)):
            os.remove(os.path.join(folder, f))
    cmd = ["./lightcuts", "render", os.path.join(ROOT, scene), "-o", "img.exr", "--stats", "stats.json",
           "--width", str(size), "--height", str(size), "--threads", str(threads), "--aov", AOVS, "-q"] + flags
    p = subprocess.run(cmd, cwd=folder, capture_output=True, text=True)
    if p.returncode != 0:
        return None, p.stderr.strip()
    with open(os.path.join(folder, "stats.json")) as f:
        return json.load(f), p.stderr.strip()


def stats_differences(a, b):
    keys = list(STABLE_KEYS)
    if a.get("reconstruct_spacing", 0) <= 1:
        keys += COUNTER_KEYS
    out = [k for k in keys if a.get(k) != b.get(k)]
    ra, rb = a.get("reference", {}), b.get("reference", {})
    out += ["reference." + k for k in REFERENCE_KEYS if ra.get(k) != rb.get(k)]
    return out


def compare_images(binary, old, new):
    p = subprocess.run([binary, "compare", old, new, "--json"], capture_output=True, text=True)
    return p.stdout.strip() or p.stderr.strip()


def main():
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("scenes", nargs="*", help="scenes (default: scenes/*.ray and scenes/features/*.ray)")
    ap.add_argument("--old", default=os.environ.get("OLD"), help="the binary before (default $OLD)")
    ap.add_argument("--new", default=os.environ.get("NEW"), help="the binary after (default $NEW)")
    ap.add_argument("--size", type=int, default=64, help="image width and height (default 64)")
    ap.add_argument("--threads", type=int, default=2, help="render threads (default 2)")
    ap.add_argument("--quick", action="store_true", help="a few fast scenes: " + ", ".join(QUICK))
    ap.add_argument("--variants", default=",".join(VARIANTS), help="per-scene variants (default: %(default)s)")
    ap.add_argument("--no-extra", action="store_true", help="skip the single-scene variants")
    ap.add_argument("--keep", action="store_true", help="keep the renders (their folder is printed)")
    args = ap.parse_args()
    if not args.old or not args.new:
        ap.error("give the two binaries: OLD=path NEW=path (or --old, --new)")
    for b in (args.old, args.new):
        if not os.access(b, os.X_OK):
            ap.error(f"not an executable: {b}")
    scenes = args.scenes or (QUICK if args.quick else
                             sorted(os.path.relpath(p, ROOT) for p in
                                    glob.glob(os.path.join(ROOT, "scenes", "*.ray")) +
                                    glob.glob(os.path.join(ROOT, "scenes", "features", "*.ray"))))
    cases = [(s, v) + VARIANTS[v] for s in scenes for v in args.variants.split(",") if v]
    if not args.no_extra:
        cases += [c for c in EXTRA if args.scenes == [] or c[0] in scenes]

    work = tempfile.mkdtemp(prefix="check_identical_")
    failed = 0
    for scene, variant, flags, size in cases:
        size = size or args.size
        t0 = time.time()
        sa, ea = run(args.old, os.path.join(work, "old"), scene, flags, size, args.threads)
        sb, eb = run(args.new, os.path.join(work, "new"), scene, flags, size, args.threads)
        label = f"{scene} [{variant}] {size}x{size}"
        problems = []
        if sa is None or sb is None:
            if (sa is None) != (sb is None) or ea != eb:
                problems.append(f"exit differs: old: {ea or 'ok'} | new: {eb or 'ok'}")
            else:
                print(f"same    {label}: both fail alike ({ea.splitlines()[-1] if ea else ''})")
                continue
        else:
            a_img, b_img = os.path.join(work, "old", "img.exr"), os.path.join(work, "new", "img.exr")
            if not filecmp.cmp(a_img, b_img, shallow=False):
                problems.append("EXR bytes differ: " + compare_images(args.new, a_img, b_img))
            diff = stats_differences(sa, sb)
            if diff:
                problems.append("stats differ: " + ", ".join(
                    f"{k}: {sa.get(k, sa.get('reference', {}).get(k.split('.')[-1]))!r} vs "
                    f"{sb.get(k, sb.get('reference', {}).get(k.split('.')[-1]))!r}" for k in diff))
            if ea != eb:
                problems.append(f"stderr differs:\n  old: {ea}\n  new: {eb}")
        if problems:
            failed += 1
            print(f"DIFFERS {label}:\n  " + "\n  ".join(problems))
        else:
            print(f"same    {label} ({time.time() - t0:.1f} s)")
        sys.stdout.flush()
    print(f"{len(cases) - failed} of {len(cases)} renders identical" + (f"; {failed} differ" if failed else ""))
    if args.keep:
        print("renders in", work)
    else:
        subprocess.run(["rm", "-rf", work])
    return 1 if failed else 0


if __name__ == "__main__":
    sys.exit(main())
