#!/usr/bin/env bash
# Seeds the fuzz corpora: fuzz/seed_corpus.sh OUT_DIR creates OUT_DIR/<target>/ for each
# target from the repository's scenes and models (and ../shared/ when it exists), the
# committed image seeds, the error fixtures and the regression inputs. Idempotent: files
# are named by content hash, so re-seeding an existing corpus only adds what is new.
set -euo pipefail
root="$(cd "$(dirname "$0")/.." && pwd)"
out="${1:?usage: seed_corpus.sh OUT_DIR}"
max_bytes=262144  # larger files slow every iteration down; libFuzzer mutates small ones better
mkdir -p "$out"/{ray_parser,obj_loader,image,scene,compare,cli}

# add TARGET FILE: copies FILE into the corpus under its content hash.
add() {
  local target="$1" f="$2"
  [ -f "$f" ] || return 0
  [ "$(stat -c %s "$f")" -le "$max_bytes" ] || return 0
  cp "$f" "$out/$target/seed-$(sha1sum "$f" | cut -c1-16)"
}

shopt -s nullglob globstar
scene_dirs=("$root/scenes" "$root/data/public-scenes" "$root/data/errors" "$root/../shared/scenes")
model_dirs=("$root/data/models" "$root/data/obj" "$root/../shared/models")

# .ray seeds feed both the parser and the scene target.
for d in "${scene_dirs[@]}"; do
  for f in "$d"/**/*.ray; do add ray_parser "$f"; add scene "$f"; done
done

# OBJ seeds: the OBJ with its first mtllib renamed to f.mtl, then "%%MTL%%" and that MTL
# (the format fuzz/fuzz_entry.h's loadObj expects).
tmp="$(mktemp)"
trap 'rm -f "$tmp"' EXIT
for d in "${model_dirs[@]}"; do
  for f in "$d"/**/*.obj; do
    mtl=""
    lib="$(grep -m1 -E '^[[:space:]]*mtllib[[:space:]]' "$f" | sed -E 's/^[[:space:]]*mtllib[[:space:]]+//; s/[[:space:]]*\r?$//' || true)"
    if [ -n "$lib" ]; then
      for cand in "$(dirname "$f")/$lib" "$(dirname "$f")/$(basename "$lib")"; do
        if [ -f "$cand" ]; then mtl="$cand"; break; fi
      done
    fi
    sed -E 's/^([[:space:]]*mtllib[[:space:]]+).*/\1f.mtl/' "$f" > "$tmp"
    if [ -n "$mtl" ]; then printf '\n%%%%MTL%%%%\n' >> "$tmp"; cat "$mtl" >> "$tmp"; fi
    add obj_loader "$tmp"
  done
done

# Images: the committed tiny seeds of every format, and the small images in data/.
for f in "$root"/fuzz/seeds/image/* "$root"/data/**/*.{png,jpg,jpeg,bmp,tga,hdr,exr,ppm}; do
  add image "$f"
done

# compare: pairs of the image seeds, "REF%%TEST%%TEST" (the format of fuzz_entry.h's
# compareImages): each image with itself, and with the next seed of the list.
imgs=("$root"/fuzz/seeds/image/*)
for i in "${!imgs[@]}"; do
  for j in "$i" "$(( (i + 1) % ${#imgs[@]} ))"; do
    { cat "${imgs[$i]}"; printf '%%%%TEST%%%%'; cat "${imgs[$j]}"; } > "$tmp"
    add compare "$tmp"
  done
done

# cli: the committed argument sets (one argument per line).
for f in "$root"/fuzz/seeds/cli/*; do add cli "$f"; done

# Regression inputs are seeds too (their targets must keep handling them).
for t in ray_parser obj_loader image scene compare cli; do
  for f in "$root/data/regressions/$t"/*; do add "$t" "$f"; done
done

for t in ray_parser obj_loader image scene compare cli; do
  echo "seed_corpus: $t: $(ls "$out/$t" | wc -l) files"
done
