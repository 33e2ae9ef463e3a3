#!/usr/bin/python3
"""ctest ReadmeQuickStart: runs the commands of README.md's "Quick start" section as written.

Every ```sh block between the "## Quick start" heading and the next "## " heading runs as one
bash script (set -euo pipefail) in a fresh temporary folder that looks like the repository
root: build/lightcuts is the binary under test, scenes/ and data/ link to the source tree.
Each block must exit 0 and print no "lightcuts: warning", and every file it names with -o or
--heatmap must exist afterwards, non-empty.

  scripts/test_readme.py BINARY [README.md]
"""
import os
import re
import subprocess
import sys
import tempfile

ROOT = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))


def quick_start_blocks(text):
    m = re.search(r"^## Quick start\n(.*?)(?=^## |\Z)", text, re.M | re.S)
    if not m:
        sys.exit("test_readme: README.md has no '## Quick start' section")
    return re.findall(r"^```sh\n(.*?)^```", m.group(1), re.M | re.S)


def main():
    binary = os.path.abspath(sys.argv[1])
    readme = sys.argv[2] if len(sys.argv) > 2 else os.path.join(ROOT, "README.md")
    blocks = quick_start_blocks(open(readme, encoding="utf-8").read())
    if len(blocks) < 4:
        sys.exit(f"test_readme: expected at least 4 sh blocks in the quick start, found {len(blocks)}")
    with tempfile.TemporaryDirectory() as tmp:
        os.makedirs(os.path.join(tmp, "build"))
        os.symlink(binary, os.path.join(tmp, "build", "lightcuts"))
        for d in ("scenes", "data"):
            os.symlink(os.path.join(ROOT, d), os.path.join(tmp, d))
        for i, block in enumerate(blocks, 1):
            print(f"test_readme: block {i}:\n{block}", flush=True)
            r = subprocess.run(["bash", "-c", "set -euo pipefail\n" + block], cwd=tmp, capture_output=True,
                               text=True, timeout=600)
            sys.stdout.write(r.stdout[-3000:])
            sys.stdout.write(r.stderr[-3000:])
            if r.returncode != 0:
                sys.exit(f"test_readme: block {i} exited {r.returncode}")
            if "lightcuts: warning" in r.stderr:
                sys.exit(f"test_readme: block {i} printed a warning")
            for out in re.findall(r"(?:-o|--heatmap)\s+(\S+)", block):
                path = os.path.join(tmp, out)
                if not os.path.isfile(path) or os.path.getsize(path) == 0:
                    sys.exit(f"test_readme: block {i} did not write {out}")
    print(f"test_readme: ok ({len(blocks)} blocks)")


if __name__ == "__main__":
    main()
