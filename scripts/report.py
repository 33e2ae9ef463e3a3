#!/usr/bin/python3
"""`make report`: turns docs/BENCHMARKS.md (the table and images that `make bench` writes,
and the notes around them) into ONE self-contained HTML page, docs/report.html: images are
inlined as base64 data URIs, the style sheet is inline, nothing is fetched from anywhere.

  /usr/bin/python3 scripts/report.py [-i docs/BENCHMARKS.md] [-o docs/report.html]

Only the standard library is used. The Markdown understood is the subset these pages use:
headings, paragraphs, lists, tables, fenced code, images, links, `code`, **bold**, *italic*,
and raw HTML blocks (<details>, comments).
"""
import argparse
import base64
import html
import mimetypes
import os
import re
import sys

HERE = os.path.dirname(os.path.abspath(__file__))
ROOT = os.path.dirname(HERE)

CSS = """
body { font: 15px/1.5 system-ui, -apple-system, "Segoe UI", sans-serif; color: #222; background: #fafafa;
       max-width: 1100px; margin: 0 auto; padding: 1.5em 2em 4em; }
h1, h2, h3 { line-height: 1.25; } h1 { border-bottom: 2px solid #ddd; padding-bottom: .3em; }
h2 { margin-top: 2em; border-bottom: 1px solid #e4e4e4; padding-bottom: .2em; } h3 { margin-top: 1.6em; }
table { border-collapse: collapse; margin: 1em 0; font-size: 13px; display: block; overflow-x: auto; }
th, td { border: 1px solid #d6d6d6; padding: 4px 8px; vertical-align: top; }
th { background: #eef1f5; text-align: left; } tr:nth-child(even) td { background: #f4f6f8; }
code { font: 12.5px/1.4 ui-monospace, "DejaVu Sans Mono", monospace; background: #eef0f2; padding: 1px 4px;
       border-radius: 3px; }
pre { background: #f0f2f4; padding: .8em 1em; overflow-x: auto; border-radius: 4px; }
pre code { background: none; padding: 0; font-size: 12px; }
img { max-width: 100%; height: auto; border: 1px solid #ddd; background: #fff; }
details { margin: 1em 0; } summary { cursor: pointer; font-weight: 600; }
.meta { color: #666; font-size: 13px; }
"""


def data_uri(path):
    mime = mimetypes.guess_type(path)[0] or "application/octet-stream"
    with open(path, "rb") as f:
        return f"data:{mime};base64," + base64.b64encode(f.read()).decode("ascii")


class Converter:
    def __init__(self, base_dir):
        self.base = base_dir
        self.missing = []

    def image(self, alt, src):
        if re.match(r"^[a-z]+:", src):
            # never reference anything outside the page
            return f"<em>[image: {html.escape(alt)}]</em>"
        path = os.path.normpath(os.path.join(self.base, src))
        if not os.path.exists(path):
            self.missing.append(src)
            return f"<em>[missing image: {html.escape(src)}]</em>"
        return f'<img alt="{html.escape(alt, quote=True)}" src="{data_uri(path)}">'

    def inline(self, text):
        out = []
        # split off code spans first: nothing inside them is interpreted
        for i, part in enumerate(re.split(r"(`[^`]*`)", text)):
            if i % 2 == 1:
                out.append("<code>" + html.escape(part[1:-1]) + "</code>")
                continue
            pieces = []
            pos = 0
            for m in re.finditer(r"!\[([^\]]*)\]\(([^)\s]+)\)|\[([^\]]+)\]\(([^)\s]+)\)", part):
                pieces.append(self.emphasis(html.escape(part[pos:m.start()], quote=False)))
                if m.group(2) is not None:
                    pieces.append(self.image(m.group(1), m.group(2)))
                else:
                    label, href = self.emphasis(html.escape(m.group(3), quote=False)), m.group(4)
                    if re.match(r"^https?://", href):
                        pieces.append(f'<a href="{html.escape(href, quote=True)}">{label}</a>')
                    else:
                        pieces.append(f"{label}")
                pos = m.end()
            pieces.append(self.emphasis(html.escape(part[pos:], quote=False)))
            out.append("".join(pieces))
        return "".join(out)

    @staticmethod
    def emphasis(s):
        s = re.sub(r"\*\*(.+?)\*\*", r"<strong>\1</strong>", s)
        s = re.sub(r"(?<![\w*])\*(?!\s)(.+?)(?<!\s)\*(?![\w*])", r"<em>\1</em>", s)
        return s

    def table(self, lines):
        def cells(line):
            line = line.strip()
            if line.startswith("|"):
                line = line[1:]
            if line.endswith("|"):
                line = line[:-1]
            return [c.strip() for c in line.split("|")]

        head = cells(lines[0])
        out = ["<table>", "<thead><tr>" + "".join(f"<th>{self.inline(c)}</th>" for c in head) + "</tr></thead>",
               "<tbody>"]
        for line in lines[2:]:
            out.append("<tr>" + "".join(f"<td>{self.inline(c)}</td>" for c in cells(line)) + "</tr>")
        out.append("</tbody></table>")
        return "\n".join(out)

    def convert(self, text):
        lines = text.splitlines()
        out = []
        i = 0
        para = []

        def flush():
            if para:
                out.append("<p>" + self.inline(" ".join(para)) + "</p>")
                para.clear()

        while i < len(lines):
            line = lines[i]
            s = line.strip()
            if not s:
                flush()
                i += 1
            elif s.startswith("```"):
                flush()
                j = i + 1
                while j < len(lines) and not lines[j].strip().startswith("```"):
                    j += 1
                out.append("<pre><code>" + html.escape("\n".join(lines[i + 1:j])) + "</code></pre>")
                i = j + 1
            elif s.startswith("<!--"):
                flush()
                while i < len(lines) and "-->" not in lines[i]:
                    i += 1
                i += 1
            elif re.match(r"^</?(details|summary|div|br)\b", s):
                flush()
                out.append(s)
                i += 1
            elif m := re.match(r"^(#{1,6})\s+(.*)$", s):
                flush()
                n = len(m.group(1))
                out.append(f"<h{n}>{self.inline(m.group(2))}</h{n}>")
                i += 1
            elif s.startswith("|") and i + 1 < len(lines) and re.match(r"^\|?\s*:?-{3,}", lines[i + 1].strip()):
                flush()
                j = i
                while j < len(lines) and lines[j].strip().startswith("|"):
                    j += 1
                out.append(self.table(lines[i:j]))
                i = j
            elif re.match(r"^([-*]|\d+\.)\s+", s):
                flush()
                ordered = bool(re.match(r"^\d+\.", s))
                items = []
                while i < len(lines) and lines[i].strip():
                    t = lines[i].strip()
                    m = re.match(r"^([-*]|\d+\.)\s+(.*)$", t)
                    if m and not lines[i].startswith("    "):
                        items.append(m.group(2))
                    elif items:
                        items[-1] += " " + t
                    i += 1
                tag = "ol" if ordered else "ul"
                out.append(f"<{tag}>" + "".join(f"<li>{self.inline(x)}</li>" for x in items) + f"</{tag}>")
            else:
                para.append(s)
                i += 1
        flush()
        return "\n".join(out)


def main(argv=None):
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("-i", "--input", default=os.path.join(ROOT, "docs", "BENCHMARKS.md"))
    ap.add_argument("-o", "--output", default=os.path.join(ROOT, "docs", "report.html"))
    ap.add_argument("--title", default="lightcuts: benchmarks")
    a = ap.parse_args(argv)
    if not os.path.exists(a.input):
        sys.exit(f"report: {a.input} not found (run `make bench` first)")
    text = open(a.input, encoding="utf-8").read()
    conv = Converter(os.path.dirname(os.path.abspath(a.input)))
    body = conv.convert(text)
    page = ("<!DOCTYPE html>\n<html lang=\"en\">\n<head>\n<meta charset=\"utf-8\">\n"
            "<meta name=\"viewport\" content=\"width=device-width, initial-scale=1\">\n"
            f"<title>{html.escape(a.title)}</title>\n<style>{CSS}</style>\n</head>\n<body>\n"
            f"<p class=\"meta\">Generated by <code>scripts/report.py</code> from "
            f"<code>{html.escape(os.path.relpath(os.path.abspath(a.input), ROOT))}</code>; self-contained (images "
            "inlined).</p>\n"
            f"{body}\n</body>\n</html>\n")
    os.makedirs(os.path.dirname(os.path.abspath(a.output)), exist_ok=True)
    tmp = a.output + ".tmp"
    with open(tmp, "w", encoding="utf-8") as f:
        f.write(page)
    os.replace(tmp, a.output)
    for m in conv.missing:
        print(f"report: warning: image not found: {m}", file=sys.stderr)
    print(f"report: wrote {a.output} ({len(page) / 1024:.0f} KiB)")
    return 1 if conv.missing else 0


if __name__ == "__main__":
    sys.exit(main())
