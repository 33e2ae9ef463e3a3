"""The benchmark's figures (scripts/bench.py): the renders tone-mapped as the renderer's 8-bit
output (ImageMagick's convert reads the .exr), tiled with labels into small PNG montages per
scene row (docs/images/bench_KEY.png, bench_KEY_gi.png), the accuracy montage and the scaling
plot (matplotlib). Each function takes the Driver (bench_runs.py) and returns the file names
the Markdown links to."""
import os

from bench_scenes import ROWS


def load_exr(drv, path):
    import numpy as np
    pfm = os.path.join(drv.work, "tmp_convert.pfm")
    drv.run(["convert", path, pfm])
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


def tonemap(drv, exr):
    """The renderer's default 8-bit output (--tonemap srgb: the sRGB encoding of the clamped
    linear values, as src/io/image.cpp's quantize8), as a PIL image."""
    import numpy as np
    from PIL import Image
    v = np.clip(np.nan_to_num(load_exr(drv, exr)), 0, 1)
    v = np.where(v <= 0.0031308, 12.92 * v, 1.055 * np.power(v, 1 / 2.4) - 0.055)
    return Image.fromarray((v * 255 + 0.5).astype("uint8"), "RGB")


def tile(img, label, width):
    from PIL import Image, ImageDraw
    if img.width != width:
        img = img.resize((width, max(1, round(img.height * width / img.width))), Image.LANCZOS)
    t = Image.new("RGB", (width, img.height + 16), (255, 255, 255))
    t.paste(img, (0, 16))
    ImageDraw.Draw(t).text((3, 2), label, fill=(0, 0, 0))
    return t


def montage(tiles, out, width=512, cols=2):
    """Tiles [(PIL image, label)] in a grid `width` wide; saved as a small PNG."""
    from PIL import Image
    tw = (width - 4 * (cols - 1)) // cols
    made = [tile(im, lab, tw) for im, lab in tiles]
    rows = [made[i:i + cols] for i in range(0, len(made), cols)]
    hts = [max(t.height for t in r) for r in rows]
    sheet = Image.new("RGB", (width, sum(hts) + 4 * (len(rows) - 1)), (255, 255, 255))
    y = 0
    for r, h in zip(rows, hts):
        for i, t in enumerate(r):
            sheet.paste(t, (i * (tw + 4), y))
        y += h + 4
    save_png(sheet, out)


def save_png(img, out, limit=150_000):
    img.save(out, optimize=True)
    if os.path.getsize(out) > limit:
        img.quantize(256, dither=0).save(out, optimize=True)
    if os.path.getsize(out) > limit:
        img.quantize(128).save(out, optimize=True)


def images_for_rows(drv):
    from PIL import Image
    made = {}
    for row in ROWS:
        r = drv.results["parts"].get("row:" + row["key"])
        if not r:
            continue
        f = r["files"]
        tiles = []
        if f.get("brute"):
            tiles.append((tonemap(drv, f["brute"]), "brute force"))
        tiles.append((tonemap(drv, f["lc"]), "lightcuts"))
        if f.get("err"):
            tiles.append((Image.open(f["err"]).convert("RGB"), "relative error vs brute force"))
        else:
            tiles.append((tonemap(drv, f["seed"]), "seed's method"))
        tiles.append((Image.open(f["cut"]).convert("RGB"), "cut size (lights per pixel)"))
        name = f"bench_{row['key']}.png"
        montage(tiles, os.path.join(drv.images, name))
        made[row["key"]] = dict(main=name)
        if f.get("nogi") and row.get("pair", True):
            gname = f"bench_{row['key']}_gi.png"
            montage([(tonemap(drv, f["nogi"]), "without GI (--gi off)"),
                     (tonemap(drv, f["lc"]), f"with GI ({r['vpls']:,} VPLs)")],
                    os.path.join(drv.images, gname))
            made[row["key"]]["gi"] = gname
    return made


def scaling_plot(drv):
    sc = drv.results["parts"].get("scaling")
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
    out = os.path.join(drv.images, "bench_scaling.png")
    fig.savefig(out)
    plt.close(fig)
    return "bench_scaling.png"


def accuracy_image(drv):
    acc = drv.results["parts"].get("accuracy")
    if not acc:
        return None
    from PIL import Image
    f = acc["files"]
    montage([(tonemap(drv, f["brute"]), "brute force"), (tonemap(drv, f["lc"]), "lightcuts, --error 0.02"),
             (Image.open(f["err"]).convert("RGB"), "relative error"),
             (Image.open(f["cut"]).convert("RGB"), "cut size")],
            os.path.join(drv.images, "bench_accuracy.png"))
    return "bench_accuracy.png"
