#!/usr/bin/env python3
"""The size limits of issues 39 and 55, so that the house stays walkable: every file of the
core (crates/cgdem-core/src) under 1,000 lines and no function over 150; in the harness
(crates/cgdem-harness/src) no file over 800 lines and no function over 120; in the command
(src/) no function over 80.

A function's length counts from its `fn` line to its closing brace. Braces inside string
and character literals and comments do not count. Tests count like any other code.
Usage: python3 scripts/check-sizes.py [ROOT]   (exit status 1 when a limit is passed)
"""
import re
import sys
from pathlib import Path

# (folder, longest file in lines or None, longest function in lines or None)
LIMITS = [
    ("crates/cgdem-core/src", 999, 150),
    ("crates/cgdem-harness/src", 800, 120),
    ("src", None, 80),
]

FN = re.compile(r"^\s*(pub(\([^)]*\))?\s+)?((const|async|unsafe|extern\s+\"C\")\s+)*fn\s+(\w+)")


def code_only(text):
    """`text` with the contents of comments, strings and character literals blanked (line
    breaks kept), so that only the code's own braces remain."""
    out, i, n = [], 0, len(text)
    while i < n:
        c = text[i]
        if text.startswith("//", i):
            j = text.find("\n", i)
            j = n if j < 0 else j
            out.append(" " * (j - i))
            i = j
        elif text.startswith("/*", i):
            depth, j = 1, i + 2
            while j < n and depth:
                if text.startswith("/*", j):
                    depth, j = depth + 1, j + 2
                elif text.startswith("*/", j):
                    depth, j = depth - 1, j + 2
                else:
                    j += 1
            out.append(re.sub(r"[^\n]", " ", text[i:j]))
            i = j
        elif (m := re.match(r'b?r(#*)"', text[i:])) and (i == 0 or not (text[i - 1].isalnum() or text[i - 1] == "_")):
            end = '"' + m.group(1)
            j = text.find(end, i + m.end())
            j = n if j < 0 else j + len(end)
            out.append(re.sub(r"[^\n]", " ", text[i:j]))
            i = j
        elif c == '"':
            j = i + 1
            while j < n and text[j] != '"':
                j += 2 if text[j] == "\\" else 1
            j = min(j + 1, n)
            out.append(re.sub(r"[^\n]", " ", text[i:j]))
            i = j
        elif c == "'" and (m := re.match(r"'(\\.[^']*|[^\\'\n])'", text[i:])):
            out.append(" " * m.end())
            i += m.end()
        else:
            out.append(c)
            i += 1
    return "".join(out)


def functions(path):
    """(name, first line, length in lines) of every function with a body in `path`."""
    lines = code_only(path.read_text()).split("\n")
    found = []
    for start, line in enumerate(lines):
        m = FN.match(line)
        if not m:
            continue
        depth, opened = 0, False
        for end in range(start, len(lines)):
            for ch in lines[end]:
                if ch == "{":
                    depth, opened = depth + 1, True
                elif ch == "}":
                    depth -= 1
                elif ch == ";" and not opened and depth == 0:
                    break
            else:
                if opened and depth == 0:
                    found.append((m.group(5), start + 1, end - start + 1))
                    break
                continue
            break
    return found


def main():
    root = Path(sys.argv[1] if len(sys.argv) > 1 else Path(__file__).resolve().parent.parent)
    problems = []
    for folder, file_limit, fn_limit in LIMITS:
        for path in sorted((root / folder).rglob("*.rs")):
            rel = path.relative_to(root)
            count = len(path.read_text().split("\n")) - 1
            if file_limit is not None and count > file_limit:
                problems.append(f"{rel}: {count} lines (at most {file_limit} in {folder})")
            if fn_limit is not None:
                for name, first, length in functions(path):
                    if length > fn_limit:
                        problems.append(f"{rel}:{first}: fn {name} is {length} lines (at most {fn_limit} in {folder})")
    for p in problems:
        print(p)
    if problems:
        print(f"check-sizes: {len(problems)} limit(s) passed (issues 39 and 55: a file or function this long is split)")
        return 1
    print("check-sizes: every file and function within the limits")
    return 0


if __name__ == "__main__":
    sys.exit(main())
