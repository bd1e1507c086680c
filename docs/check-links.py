#!/usr/bin/env python3
"""Check the relative links of docs/*.md (and below) and README.md.

Every Markdown link `[text](target)` whose target is not a URL (`http:`, `https:`,
`mailto:`) must name a file or folder that exists, relative to the page; a `#anchor`
after a Markdown file must be one of that file's headings, spelt as GitHub spells them
(lower case, punctuation other than `-` and `_` dropped, spaces to `-`, repeats `-1`, `-2`).
Links inside fenced code blocks and inline code are not links.

Run from anywhere: `python3 docs/check-links.py`. Exit 0 when every link resolves, 1 with
one line per broken link (`page:line: target: why`).
"""

import os
import re
import sys

ROOT = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
LINK = re.compile(r"(?<!\!)\[(?:[^\[\]]|\[[^\]]*\])*\]\(([^()\s]+(?:\([^()]*\))?[^()\s]*)\)")
IMAGE = re.compile(r"!\[[^\]]*\]\(([^)\s]+)\)")


def pages():
    yield os.path.join(ROOT, "README.md")
    for folder, _, files in os.walk(os.path.join(ROOT, "docs")):
        for name in sorted(files):
            if name.endswith(".md"):
                yield os.path.join(folder, name)


def prose_lines(path):
    """(line number, text) of the lines outside fenced code, with inline code removed."""
    fence = None
    with open(path, encoding="utf-8") as f:
        for number, line in enumerate(f, 1):
            stripped = line.lstrip()
            marker = stripped[:3]
            if marker in ("```", "~~~"):
                if fence is None:
                    fence = marker
                elif marker == fence:
                    fence = None
                continue
            if fence is None:
                yield number, re.sub(r"`[^`]*`", "", line)


def slug(heading):
    text = heading.strip().lower()
    text = re.sub(r"[^\w\- ]", "", text)
    return text.replace(" ", "-")


def anchors(path, cache={}):
    if path not in cache:
        seen = {}
        found = set()
        for _, line in prose_lines_with_code(path):
            m = re.match(r"^(#{1,6})\s+(.*?)\s*#*\s*$", line)
            if not m:
                continue
            base = slug(m.group(2))
            n = seen.get(base, 0)
            found.add(base if n == 0 else f"{base}-{n}")
            seen[base] = n + 1
        cache[path] = found
    return cache[path]


def prose_lines_with_code(path):
    """Lines outside fenced code, inline code kept (headings keep their code text)."""
    fence = None
    with open(path, encoding="utf-8") as f:
        for number, line in enumerate(f, 1):
            marker = line.lstrip()[:3]
            if marker in ("```", "~~~"):
                if fence is None:
                    fence = marker
                elif marker == fence:
                    fence = None
                continue
            if fence is None:
                yield number, line


def check():
    broken = []
    count = 0
    for page in pages():
        rel_page = os.path.relpath(page, ROOT)
        for number, line in prose_lines(page):
            for m in list(LINK.finditer(line)) + list(IMAGE.finditer(line)):
                target = m.group(1)
                if re.match(r"^[a-z]+:", target):
                    continue
                count += 1
                path, _, anchor = target.partition("#")
                if path:
                    file = os.path.normpath(os.path.join(os.path.dirname(page), path))
                else:
                    file = page
                if not os.path.exists(file):
                    broken.append(f"{rel_page}:{number}: {target}: no such file")
                    continue
                if anchor and file.endswith(".md") and anchor not in anchors(file):
                    broken.append(f"{rel_page}:{number}: {target}: no such heading")
    return count, broken


if __name__ == "__main__":
    count, broken = check()
    for b in broken:
        print(b)
    print(f"{count} relative links checked, {len(broken)} broken")
    sys.exit(1 if broken else 0)
