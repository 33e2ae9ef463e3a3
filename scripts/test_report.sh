#!/usr/bin/env bash
# ctest ReportOpensInChromium: builds the self-contained HTML report (scripts/report.py) into a
# temporary folder, from a small fixture (a table, a list, code, an image) and from
# docs/BENCHMARKS.md when it exists (or from the pages given), opens each in headless
# Chromium, and checks that
#   - the page references nothing outside itself (no http(s) or protocol-relative src/href,
#     no external script or style sheet, every image an inlined data URI),
#   - Chromium writes a screenshot that is not blank,
#   - the console shows no error (no CONSOLE message, no "Uncaught", no failed load).
# and that the page is the user's: a table of contents linked to its headings, no heading that
# names a project issue ("issue 3"), no hand-written notes from after the GENERATED markers.
# Exits 77 (ctest: skipped) when chromium is not installed.
#   scripts/test_report.sh [MARKDOWN ...]
#   LC_REPORT_SCREENSHOT=shot.png scripts/test_report.sh   # keep the last screenshot
set -euo pipefail
ROOT="$(cd "$(dirname "$0")/.." && pwd)"

CHROME=""
for c in chromium chromium-browser google-chrome; do
  if command -v "$c" >/dev/null 2>&1; then CHROME="$(command -v "$c")"; break; fi
done
if [ -z "$CHROME" ]; then
  echo "test_report: chromium is not installed (apt-get install chromium): skipped"
  exit 77
fi
PY=/usr/bin/python3
[ -x "$PY" ] || PY="$(command -v python3)"

tmp="$(mktemp -d)"
trap 'rm -rf "$tmp"' EXIT

# A fixture: a heading, a list, a table, an image, code in a <details> block.
fixture="$tmp/fixture/BENCHMARKS.md"
mkdir -p "$tmp/fixture/images"
"$PY" - "$tmp/fixture/images/grad.png" <<'PYEOF'
import struct, sys, zlib
w, h = 64, 48
raw = b"".join(b"\0" + b"".join(bytes((x * 4 % 256, y * 5 % 256, 128)) for x in range(w)) for y in range(h))
def chunk(t, d):
    return struct.pack(">I", len(d)) + t + d + struct.pack(">I", zlib.crc32(t + d) & 0xffffffff)
png = (b"\x89PNG\r\n\x1a\n" + chunk(b"IHDR", struct.pack(">IIBBBBB", w, h, 8, 2, 0, 0, 0)) +
       chunk(b"IDAT", zlib.compress(raw)) + chunk(b"IEND", b""))
open(sys.argv[1], "wb").write(png)
PYEOF
cat > "$fixture" <<'MDEOF'
# Benchmarks (fixture)

<!-- BEGIN GENERATED -->
## Measured results

- **Commit** `0000000`; a *fixture* page.

| Test case | Brute force | Lightcuts | Speed-up |
|---|---|---|---|
| Cornell box | 100 s | 4 s | 25.0× |

### Scaling (256×256, issue 3)

![a gradient](images/grad.png)

<details><summary>Commands</summary>

```
lightcuts render scenes/cornell_box.ray -o out.exr
```

</details>
<!-- END GENERATED -->
MDEOF

if [ $# -gt 0 ]; then
  inputs=("$@")
else
  inputs=("$fixture")
  if [ -f "$ROOT/docs/BENCHMARKS.md" ]; then inputs+=("$ROOT/docs/BENCHMARKS.md"); fi
fi

n=0
shot=""
for md in "${inputs[@]}"; do
  n=$((n + 1))
  html="$tmp/report$n.html"
  echo "test_report: $md"
  "$PY" "$ROOT/scripts/report.py" -i "$md" -o "$html"

  # Self-contained: nothing to fetch, every image inlined.
  if grep -Eiq '(src|href)="(https?:)?//' "$html" ||
     grep -Eiq '<(script|link|iframe)[^>]+(src|href)=' "$html" ||
     grep -Eio '<img[^>]+src="[^"]{0,5}' "$html" | grep -qv 'src="data:'; then
    echo "test_report: the page refers to external resources:" >&2
    grep -Eio '(src|href)="[^"]{0,80}' "$html" | grep -v 'data:' | head >&2
    exit 1
  fi
  if grep -Eo '<h[1-6][^>]*>[^<]*issues? [0-9]' "$html" >&2; then
    echo "test_report: a heading names a project issue (above)" >&2
    exit 1
  fi
  if ! grep -q '<nav class="toc"><strong><a href="#measured-results">' "$html"; then
    echo "test_report: no table of contents linked to the headings" >&2
    exit 1
  fi
  if grep -q 'Notes on the generated figures' "$html"; then
    echo "test_report: the developer notes after the GENERATED markers are in the page" >&2
    exit 1
  fi
  if grep -q '!\[' "$md" && ! grep -q 'src="data:image/png;base64,' "$html"; then
    echo "test_report: the page has images but none was inlined" >&2
    exit 1
  fi

  shot="$tmp/shot$n.png"
  set +e
  timeout 120 "$CHROME" --headless --no-sandbox --disable-gpu --disable-quic --no-first-run \
    --disable-background-networking --disable-component-update --disable-sync --disable-extensions \
    --user-data-dir="$tmp/profile$n" --enable-logging=stderr --v=0 \
    --screenshot="$shot" --window-size=1200,900 "file://$html" >"$tmp/chrome$n.log" 2>&1
  rc=$?
  set -e
  if [ $rc -ne 0 ] || [ ! -s "$shot" ]; then
    echo "test_report: chromium failed (exit $rc) or wrote no screenshot" >&2
    tail -30 "$tmp/chrome$n.log" >&2
    exit 1
  fi
  if grep -Ei 'CONSOLE|Uncaught|net::ERR_|Not allowed to load' "$tmp/chrome$n.log" >&2; then
    echo "test_report: errors in the console (above)" >&2
    exit 1
  fi

  # Not blank: enough distinct colours (PIL when available, else the PNG's size).
  if "$PY" -c "import PIL" 2>/dev/null; then
    "$PY" - "$shot" <<'PYEOF'
import sys
from PIL import Image
im = Image.open(sys.argv[1]).convert("RGB")
colours = im.getcolors(1 << 24) or []
print(f"test_report: screenshot {im.width}x{im.height}, {len(colours)} colours")
if im.width < 600 or len(colours) < 20:
    sys.exit("test_report: the screenshot looks blank")
PYEOF
  else
    size=$(stat -c %s "$shot")
    echo "test_report: screenshot of $size bytes"
    if [ "$size" -lt 10000 ]; then echo "test_report: the screenshot looks blank" >&2; exit 1; fi
  fi
done
if [ -n "${LC_REPORT_SCREENSHOT:-}" ] && [ -n "$shot" ]; then cp "$shot" "$LC_REPORT_SCREENSHOT"; fi
echo "test_report: ok"
