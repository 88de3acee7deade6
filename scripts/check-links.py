#!/usr/bin/env python3
"""Every relative link of the README and the guide resolves to a file or folder of the
repository. Usage: python3 scripts/check-links.py [FILE.md ...] (default: README.md and
docs/**/*.md). Exit status 1, naming each broken link with its file and line, when one does
not resolve; links to the web (http, https, mailto) and to anchors of the same page are not
checked."""
import re
import sys
from pathlib import Path

LINK = re.compile(r"!?\[[^\]]*\]\(([^)\s]+)(?:\s+\"[^\"]*\")?\)")
FENCE = re.compile(r"^\s*```")

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
            if re.match(r"^(https?|mailto):", target) or target.startswith("#"):
                continue
            path = target.split("#", 1)[0]
            checked += 1
            if not (md.parent / path).exists():
                broken.append(f"{md.relative_to(root) if md.is_absolute() else md}:{number}: {target}")
for b in broken:
    print(f"broken link: {b}")
print(f"{checked} relative links in {len(files)} files, {len(broken)} broken")
sys.exit(1 if broken else 0)
