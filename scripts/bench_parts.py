"""The measured parts of the benchmark (scripts/bench.py), each stored in results.json under its
key: a row of the seed's table (`row:KEY`: lightcuts with brute force probed at reference
pixels, the seed's method, no extra lights, brute force in full or extrapolated), the scaling
sweep, the 100k-light accuracy check and the Google Benchmark micro benchmarks. Each function
takes the Driver (bench_runs.py) and skips a part that is already done (--resume)."""
import json
import os
import re

from bench_runs import HERE, PY, ROOT, median, now


def vpl_paths(drv, scene, target):
    """The path count (--vpls) that deposits about `target` VPLs in this scene."""
    base = drv.info(scene)["vpls"]
    block = re.search(r"vpls\s*=\s*(\d+)", open(os.path.join(ROOT, scene)).read())
    paths = int(block.group(1)) if block else target
    if abs(base - target) <= 0.005 * target:
        return None, base  # the scene's own block is close enough
    ratio = base / paths if base else 0.8
    guess = int(round(target / ratio))
    for _ in range(3):
        got = drv.info(scene, ["--vpls", str(guess)])["vpls"]
        if got == target or abs(got - target) <= max(1, target // 2000):
            return guess, got
        guess = max(1, int(round(guess * target / max(got, 1))))
    return guess, drv.info(scene, ["--vpls", str(guess)])["vpls"]


def table_row(drv, row):
    key = "row:" + row["key"]
    if drv.done(key):
        return
    t_row = now()
    scene = row["scene"]
    base = os.path.join(drv.work, row["key"])
    cmds = []
    extra = list(row.get("extra", []))
    res = dict(key=row["key"], name=row["name"], scene=scene, width=drv.width, gi=bool(row.get("gi")),
               loadavg=os.getloadavg()[0])
    if row.get("vpls"):
        paths, got = vpl_paths(drv, scene, row["vpls"])
        extra += ["--vpls", str(paths)] if paths else []
        res["vpl_paths"] = paths
    # lightcuts, first with a probe of brute force at a few pixels
    lc = [drv.render(scene, base + "_lc", extra=extra, ref=drv.k_probe, cut_heatmap=True, commands=cmds)]
    est = lc[0]["reference"]["brute_seconds_estimate"]
    full = row.get("brute", "auto") == "auto" and est <= drv.brute_limit
    ref_stats = lc[0]["reference"]
    if not full and drv.k_ref > drv.k_probe:
        lc.append(drv.render(scene, base + "_lcref", extra=extra, ref=drv.k_ref, commands=cmds))
        ref_stats = lc[-1]["reference"]
    reps = drv.repeats if drv.cost(lc[0]) < 60 else max(1, drv.repeats - 1)
    while len(lc) < reps:
        lc.append(drv.render(scene, base + "_rep", extra=extra, commands=cmds))
    # the seed's method
    sd = [drv.render(scene, base + "_seed", method="seed", extra=extra,
                      ref=0 if full else drv.k_ref, commands=cmds)]
    reps_s = drv.repeats if drv.cost(sd[0]) < 60 else max(1, drv.repeats - 1)
    while len(sd) < reps_s:
        sd.append(drv.render(scene, base + "_rep", method="seed", extra=extra, commands=cmds))
    # no extra lights: direct light only
    ne = []
    if row.get("gi"):
        ne = [drv.render(scene, base + "_nogi", extra=extra + ["--gi", "off"], commands=cmds)]
        reps_n = drv.repeats if drv.cost(ne[0]) < 60 else max(1, drv.repeats - 1)
        while len(ne) < reps_n:
            ne.append(drv.render(scene, base + "_rep", extra=extra + ["--gi", "off"], commands=cmds))
    # brute force
    br = None
    if full:
        br = drv.render(scene, base + "_brute", method="brute", extra=extra, commands=cmds)
        res["err_lc"] = drv.compare(br["exr"], lc[0]["exr"], base + "_err.png", cmds)
        res["err_seed"] = drv.compare(br["exr"], sd[0]["exr"], base + "_seed_err.png", cmds)
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
    res["lc_time"] = median(drv.cost(s) for s in lc)
    res["lc_times"] = [drv.cost(s) for s in lc]
    res["lc_tree"] = median(s.get("time_tree_s", 0) for s in lc)
    res["lc_lights"] = lc[0]["avg_lights_per_shading_point"]
    res["lc_shadow_rays"] = lc[0]["avg_shadow_rays_per_shading_point"]
    res["seed_time"] = median(drv.cost(s) for s in sd)
    res["seed_times"] = [drv.cost(s) for s in sd]
    res["seed_lights"] = sd[0]["avg_lights_per_shading_point"]
    res["brute_lights"] = ref_stats.get("brute_lights_per_shading_point") or res["lights"]["total"]
    res["noextra_time"] = median(drv.cost(s) for s in ne) if ne else None
    res["noextra_times"] = [drv.cost(s) for s in ne]
    res["noextra_lights"] = ne[0]["lights"]["total"] if ne else None
    res["speedup"] = res["brute_time"] / res["lc_time"] if res["lc_time"] else None
    res["seed_speedup"] = res["brute_time"] / res["seed_time"] if res["seed_time"] else None
    res["vpl_clamped_fraction"] = lc[0].get("vpl_clamped_fraction")
    res["files"] = dict(lc=lc[0]["exr"], cut=lc[0]["cut_png"], seed=sd[0]["exr"],
                        brute=br["exr"] if br else None, err=base + "_err.png" if full else None,
                        nogi=ne[0]["exr"] if ne else None)
    res["commands"] = cmds
    res["seconds"] = now() - t_row
    res["commit"] = drv.results["env"]["commit"]
    drv.results["parts"][key] = res
    drv.save()


def scaling(drv):
    key = "scaling"
    if drv.done(key):
        return
    t0 = now()
    out = dict(width=drv.scaling_width, points=[], commands=[])
    for n in drv.scaling_n:
        scene = os.path.join(drv.work, f"scaling_{n}.ray")
        drv.run([PY, os.path.join(HERE, "gen_scaling_scene.py"), str(n), scene], out["commands"])
        base = os.path.join(drv.work, f"scaling_{n}")
        lc = [drv.render(scene, base + "_lc", width=drv.scaling_width, extra=["--error", "0.02"],
                          ref=drv.k_probe, cut_heatmap=True, commands=out["commands"])]
        while len(lc) < drv.repeats:
            lc.append(drv.render(scene, base + "_rep", width=drv.scaling_width, extra=["--error", "0.02"],
                                  commands=out["commands"]))
        sd = [drv.render(scene, base + "_seed", method="seed", width=drv.scaling_width,
                          ref=drv.k_probe, commands=out["commands"])]
        while len(sd) < drv.repeats:
            sd.append(drv.render(scene, base + "_rep", method="seed", width=drv.scaling_width,
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
    out["commit"] = drv.results["env"]["commit"]
    drv.results["parts"][key] = out
    drv.save()


def accuracy(drv):
    key = "accuracy"
    if drv.done(key):
        return
    t0 = now()
    n = 100000
    cmds = []
    scene = os.path.join(drv.work, f"scaling_{n}.ray")
    if not os.path.exists(scene):
        drv.run([PY, os.path.join(HERE, "gen_scaling_scene.py"), str(n), scene], cmds)
    base = os.path.join(drv.work, "accuracy")
    w = drv.scaling_width
    lc = [drv.render(scene, base + "_lc", width=w, extra=["--error", "0.02"], cut_heatmap=True, commands=cmds)]
    while len(lc) < drv.repeats:
        lc.append(drv.render(scene, base + "_rep", width=w, extra=["--error", "0.02"], commands=cmds))
    br = drv.render(scene, base + "_brute", method="brute", width=w, commands=cmds)
    err = drv.compare(br["exr"], lc[0]["exr"], base + "_err.png", cmds)
    drv.results["parts"][key] = dict(
        n=lc[0]["lights"]["total"], width=w, err=err, lc_time=median(drv.cost(s) for s in lc),
        lc_render=median(s["time_render_s"] for s in lc), lc_tree=median(s["time_tree_s"] for s in lc),
        lc_lights=lc[0]["avg_lights_per_shading_point"], brute_time=br["time_render_s"],
        files=dict(lc=lc[0]["exr"], brute=br["exr"], err=base + "_err.png", cut=lc[0]["cut_png"]),
        commands=cmds, seconds=now() - t0, commit=drv.results["env"]["commit"])
    drv.save()


def micro(drv):
    key = "micro"
    if drv.done(key):
        return
    t0 = now()
    cmds = []
    bench = os.path.join(drv.build, "bench")
    mt = "0.05" if drv.quick else "0.5"
    reps = "1" if drv.quick else "3"
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
        data = json.loads(drv.run(cmd, cmds, capture=True))
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
    out["commit"] = drv.results["env"]["commit"]
    drv.results["parts"][key] = out
    drv.save()
