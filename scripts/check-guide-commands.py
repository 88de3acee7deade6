#!/usr/bin/env python3
"""Runs the command blocks of a guide page, in order, so the guide cannot drift from the
program (as trycmd and mdBook's `test` do for theirs).

Usage: python3 scripts/check-guide-commands.py [--full] PAGE.md [PAGE.md ...]
  --full  run the pages at their own size (the `replace` directives ignored), each command's
          output printed, and the scratch directories kept: the figures a page quotes

A page is read top to bottom:
- a fenced block whose first line is `# file: NAME` (toml, python, ...) is written to NAME in
  the page's working directory;
- each line of a ```sh block is run with bash in that directory, with target/release first on
  PATH (so `cgdem` is the build under test); it must exit 0;
- HTML comments steer the check and are invisible to readers:
    <!-- guide-check: cwd repository -->   run this page's commands from the repository
                                           (default: a fresh scratch directory)
    <!-- guide-check: replace "A" -> "B" --> in CI, the blocks after it use B for A (a
                                           smaller case than the page's, to fit CI's time)
    <!-- guide-check: exit N[,M] -->       the next block's commands exit with N (or M)
    <!-- guide-check: skip -->             the next block is not run (it installs or
                                           recurses, e.g. the test command itself)
Exit status: 0 when every block ran as expected, 1 otherwise.
"""

import os
import re
import subprocess
import sys
import tempfile
import time
from pathlib import Path

ROOT = Path(__file__).resolve().parent.parent
DIRECTIVE = re.compile(r"<!--\s*guide-check:\s*(.*?)\s*-->")
REPLACE = re.compile(r'replace\s+"(.*)"\s*->\s*"(.*)"')


def blocks(text):
    """(directives before it, language, lines) of each fenced block, in order."""
    pending = []
    lines = text.splitlines()
    k = 0
    while k < len(lines):
        line = lines[k]
        for d in DIRECTIVE.findall(line):
            pending.append(d)
        if line.startswith("```"):
            lang = line[3:].strip()
            body = []
            k += 1
            while k < len(lines) and not lines[k].startswith("```"):
                body.append(lines[k])
                k += 1
            yield pending, lang, body
            pending = []
        k += 1


def check(page, full=False):
    text = page.read_text()
    scratch = Path(tempfile.mkdtemp(prefix=f"guide-{page.stem}-"))
    cwd = scratch
    replacements = []
    env = dict(os.environ)
    env["PATH"] = f"{ROOT / 'target' / 'release'}:{env.get('PATH', '')}"
    failures = 0
    for directives, lang, body in blocks(text):
        expected, skip = {0}, False
        for d in directives:
            if d == "cwd repository":
                cwd = ROOT
            elif d == "skip":
                skip = True
            elif d.startswith("exit "):
                expected = {int(x) for x in d.split()[1].split(",")}
            elif m := REPLACE.fullmatch(d):
                if not full:
                    replacements.append((m.group(1), m.group(2)))
            else:
                sys.exit(f"{page}: unknown guide-check directive {d!r}")
        if skip:
            continue
        body = "\n".join(body)
        for old, new in replacements:
            body = body.replace(old, new)
        first = body.splitlines()[0] if body else ""
        if first.startswith("# file: "):
            name = first[len("# file: "):].strip()
            (cwd / name).write_text(body + "\n")
            print(f"{page.name}: wrote {name}")
            continue
        if lang != "sh":
            continue
        for command in body.splitlines():
            command = command.split(" #")[0].strip() if not command.startswith("#") else ""
            if not command:
                continue
            started = time.time()
            p = subprocess.run(["bash", "-c", command], cwd=cwd, env=env, capture_output=True, text=True)
            took = time.time() - started
            status = "ok" if p.returncode in expected else "FAILED"
            print(f"{page.name}: {status} ({took:.0f} s, exit {p.returncode}, expected {sorted(expected)}): {command}")
            if full:
                print(p.stdout)
                print(p.stderr, file=sys.stderr)
            if p.returncode not in expected:
                failures += 1
                print(p.stdout[-3000:])
                print(p.stderr[-3000:], file=sys.stderr)
    if full:
        print(f"{page.name}: its files and outputs are in {cwd if cwd != ROOT else scratch}")
    return failures


def main():
    full = "--full" in sys.argv[1:]
    pages = [Path(p) for p in sys.argv[1:] if p != "--full"]
    if not pages:
        sys.exit(__doc__)
    failures = sum(check(p, full) for p in pages)
    if failures:
        print(f"{failures} guide commands did not run as the guide says", file=sys.stderr)
    sys.exit(1 if failures else 0)


if __name__ == "__main__":
    main()
