#!/usr/bin/env bash
# ctest InstallLayout: `make install PREFIX=... DESTDIR=...` puts the binary, the man page (when
# help2man is there), the scenes and the docs under DESTDIR/PREFIX and nothing elsewhere, and the
# installed binary renders an installed scene that borrows a texture from data/.
#   scripts/test_install.sh BUILD_DIR [HELP2MAN]
set -euo pipefail
ROOT="$(cd "$(dirname "$0")/.." && pwd)"
BUILD="$1"
HELP2MAN="${2:-}"
tmp="$(mktemp -d)"
trap 'rm -rf "$tmp"' EXIT

# The Makefile passes PREFIX and DESTDIR on to cmake --install.
cmd="$(make -s -n -C "$ROOT" install BUILD="$BUILD" PREFIX=/opt/lcx DESTDIR=/stage/x | grep 'cmake --install')"
case "$cmd" in
  *"DESTDIR=/stage/x cmake --install $BUILD --prefix /opt/lcx"*) ;;
  *) echo "test_install: make install does not pass PREFIX and DESTDIR: $cmd" >&2; exit 1 ;;
esac

DESTDIR="$tmp/stage" cmake --install "$BUILD" --prefix /opt/lc >/dev/null
root="$tmp/stage/opt/lc"
for f in bin/lightcuts share/lightcuts/scenes/cornell_box.ray share/lightcuts/scenes/features/area_lights.ray \
         share/lightcuts/data/public-scenes/checkerboard.bmp share/doc/lightcuts/README.md \
         share/doc/lightcuts/LIGHTCUTS.md share/doc/lightcuts/images/cornell_box.png; do
  [ -s "$root/$f" ] || { echo "test_install: $f is missing" >&2; exit 1; }
done
[ -x "$root/bin/lightcuts" ] || { echo "test_install: bin/lightcuts is not executable" >&2; exit 1; }
if [ -n "$HELP2MAN" ]; then
  man="$root/share/man/man1/lightcuts.1"
  [ -s "$man" ] || { echo "test_install: no man page (help2man is $HELP2MAN)" >&2; exit 1; }
  for want in '^\.TH LIGHTCUTS' 'tonemap' 'exposure' 'Error metrics of TEST'; do
    grep -q -- "$want" "$man" || { echo "test_install: the man page lacks $want" >&2; exit 1; }
  done
else
  echo "test_install: help2man not found at configure time: man page not checked"
fi
stray="$(find "$tmp/stage" -type f | grep -v "^$root/" || true)"
[ -z "$stray" ] || { echo "test_install: files outside the prefix: $stray" >&2; exit 1; }

# The installed binary renders an installed scene whose texture path goes through ../../data.
(cd "$tmp" && "$root/bin/lightcuts" render "$root/share/lightcuts/scenes/features/area_lights.ray" -o a.png \
   --width 24 -q --vpls 0)
[ -s "$tmp/a.png" ] || { echo "test_install: the installed binary wrote no image" >&2; exit 1; }
"$root/bin/lightcuts" --version | grep -q '^lightcuts [0-9]'
echo "test_install: ok"
