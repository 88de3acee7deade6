#!/usr/bin/env python3
"""The import graph of a crate's modules, from its `crate::`/`super::`/`self::` paths, and
its circles (strongly connected components of more than one module).

Usage: python3 scripts/module-graph.py CRATE_SRC [--depth N] [--edges]
  CRATE_SRC  e.g. crates/cgdem-harness/src
  --depth N  how many levels of the module path make a node (1: `decks`; 2: `decks::lammps`)
  --edges    print every edge, not only the circles
Exit status 1 when there is a circle (usable as a check). Test modules (`#[cfg(test)]`
blocks to the end of a file, files named `*tests.rs`) are left out: a test may import what
it checks.
"""
import re
import sys
from pathlib import Path

PATH = re.compile(r"\b(crate|super|self)((?:::[A-Za-z_][A-Za-z0-9_]*)+)")
USE_GROUP = re.compile(r"\buse\s+(crate|super|self)::\{([^;]*)\};", re.S)


def module_of(src: Path, file: Path) -> list[str]:
    parts = list(file.relative_to(src).with_suffix("").parts)
    if parts[-1] in ("mod", "lib", "main"):
        parts = parts[:-1]
    return parts


def code_of(text: str) -> str:
    text = re.sub(r"//[^\n]*", "", text)
    cut = re.search(r"#\[cfg\(test\)\]\s*(pub(\([a-z]+\))?\s+)?mod\s+tests", text)
    return text[: cut.start()] if cut else text


def resolve(module: list[str], is_mod_file: bool, root: str, rest: list[str]) -> list[str]:
    if root == "crate":
        return rest
    base = list(module)
    if root == "super":
        base = base[:-1]
        while rest and rest[0] == "super":
            base, rest = base[:-1], rest[1:]
    return base + rest


def targets(text: str):
    """(root, [segments]) of every path, with `use x::{a, b::c}` groups expanded one level."""
    for m in USE_GROUP.finditer(text):
        for item in re.split(r",(?![^{]*\})", m.group(2)):
            item = item.strip()
            name = re.match(r"[A-Za-z_][A-Za-z0-9_]*", item)
            if name and item != "self":
                yield m.group(1), [name.group(0)]
    for m in PATH.finditer(text):
        yield m.group(1), m.group(2).strip(":").split("::")


def graph(src: Path, depth: int):
    modules = {}
    for file in sorted(src.rglob("*.rs")):
        if file.stem.endswith("tests") or file.stem.endswith("_test"):
            continue  # a test-only module file (declared under #[cfg(test)])
        modules[tuple(module_of(src, file))] = file
    known = {m[:depth] for m in modules if m}
    edges = {}
    for module, file in modules.items():
        if not module:
            continue
        node = module[:depth]
        for root, rest in targets(code_of(file.read_text())):
            path = resolve(list(module), file.name == "mod.rs", root, rest)
            # The longest prefix of the path that is a module, cut to the depth.
            target = None
            for k in range(min(depth, len(path)), 0, -1):
                if tuple(path[:k]) in known:
                    target = tuple(path[:k])
                    break
            if target and target != node and target[:len(node)] != node and node[:len(target)] != target:
                edges.setdefault(node, set()).add(target)
    return known, edges


def circles(nodes, edges):
    index, low, stack, on, out, counter = {}, {}, [], set(), [], [0]

    def visit(v):
        index[v] = low[v] = counter[0]
        counter[0] += 1
        stack.append(v)
        on.add(v)
        for w in sorted(edges.get(v, ())):
            if w not in index:
                visit(w)
                low[v] = min(low[v], low[w])
            elif w in on:
                low[v] = min(low[v], index[w])
        if low[v] == index[v]:
            comp = []
            while True:
                w = stack.pop()
                on.discard(w)
                comp.append(w)
                if w == v:
                    break
            if len(comp) > 1:
                out.append(sorted(comp))

    sys.setrecursionlimit(10000)
    for v in sorted(nodes):
        if v not in index:
            visit(v)
    return out


def main():
    args = sys.argv[1:]
    if not args:
        print(__doc__)
        return 2
    src = Path(args[0])
    depth = int(args[args.index("--depth") + 1]) if "--depth" in args else 1
    nodes, edges = graph(src, depth)
    name = lambda m: "::".join(m)
    if "--edges" in args:
        for v in sorted(edges):
            print(f"{name(v)} -> {', '.join(name(w) for w in sorted(edges[v]))}")
    found = circles(nodes, edges)
    for comp in found:
        inner = [f"{name(v)}->{name(w)}" for v in comp for w in sorted(edges.get(v, ())) if w in comp]
        print(f"circle: {{{', '.join(name(v) for v in comp)}}}  edges: {' '.join(inner)}")
    print(f"{len(nodes)} modules at depth {depth}, {sum(map(len, edges.values()))} edges, {len(found)} circles")
    return 1 if found else 0


if __name__ == "__main__":
    sys.exit(main())
