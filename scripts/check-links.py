#!/usr/bin/env python3
"""Every relative link of the README and the guide resolves to a file or folder of the
repository, and every anchor into a Markdown file (`chapter.md#a-heading`, `#a-heading` on the
same page) to one of its headings, as GitHub makes their anchors. Usage: python3
scripts/check-links.py [FILE.md ...] (default: README.md and docs/**/*.md). Exit status 1,
naming each broken link with its file and line, when one does not resolve; links to the web
(http, https, mailto) are not checked."""
import re
import sys
from pathlib import Path

LINK = re.compile(r"!?\[[^\]]*\]\(([^)\s]+)(?:\s+\"[^\"]*\")?\)")
FENCE = re.compile(r"^\s*```")


def anchors(md):
    """The anchors GitHub gives the headings of a Markdown file: lower case, punctuation
    dropped but hyphens and underscores, spaces as hyphens, a repeated one numbered."""
    seen = {}
    out = set()
    in_code = False
    for line in md.read_text(encoding="utf-8").splitlines():
        if FENCE.match(line):
            in_code = not in_code
            continue
        m = None if in_code else re.match(r"^#{1,6}\s+(.*?)\s*#*\s*$", line)
        if not m:
            continue
        slug = re.sub(r"[^\w\- ]", "", m.group(1).lower()).replace(" ", "-")
        n = seen.get(slug, 0)
        seen[slug] = n + 1
        out.add(slug if n == 0 else f"{slug}-{n}")
    return out


root = Path(__file__).resolve().parent.parent
files = [Path(a) for a in sys.argv[1:]] or [root / "README.md", *sorted((root / "docs").rglob("*.md"))]
broken = []
checked = 0
for md in files:
    in_code = False
    for number, line in enumerate(md.read_text(encoding="utf-8").splitlines(), 1):
        if FENCE.match(line):
            in_code = not in_code
            continue
        if in_code:
            continue
        # Code spans are text, not links.
        line = re.sub(r"`[^`]*`", "", line)
        for target in LINK.findall(line):
            if re.match(r"^(https?|mailto):", target):
                continue
            path, _, anchor = target.partition("#")
            checked += 1
            dest = md.parent / path if path else md
            if not dest.exists() or (
                anchor and dest.suffix == ".md" and anchor not in anchors(dest)
            ):
                broken.append(f"{md.relative_to(root) if md.is_absolute() else md}:{number}: {target}")
for b in broken:
    print(f"broken link: {b}")
print(f"{checked} relative links in {len(files)} files, {len(broken)} broken")
sys.exit(1 if broken else 0)
