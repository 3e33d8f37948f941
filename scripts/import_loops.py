#!/usr/bin/env python3
"""Import loops between the library's source files.

Every `crate::…` and `super::…` path in a file's code (comments and doc comments left
out) is resolved to the longest module it names; an edge goes from the file to that
module's file. A loop is a strongly connected set of two or more files. A module's
`mod.rs` and the files of its own folder are left out of each other's edges when
`--siblings` is given (a parent re-exporting its children is not a loop between
concepts), so that only loops between sibling files and across folders are counted.

    scripts/import_loops.py [--siblings] [SRC_DIR]

Prints each loop and the count; exits 0 whatever it finds (a measurement, not a gate).
"""
import os
import re
import sys


def modules(src):
    """Module path (tuple) -> file, for every .rs file under src."""
    out = {}
    for root, _, files in os.walk(src):
        for f in files:
            if not f.endswith(".rs"):
                continue
            path = os.path.join(root, f)
            rel = os.path.relpath(path, src)[:-3].split(os.sep)
            if rel[-1] in ("mod", "lib"):
                rel = rel[:-1]
            out[tuple(rel)] = path
    return out


def code_of(path):
    text = open(path, encoding="utf-8").read()
    # Unit tests (a `#[cfg(test)] mod …` to the end of the file) are not the design.
    text = re.split(r"#\[cfg\(test\)\]\s*(?:pub(?:\(crate\))?\s+)?mod\s+\w+\s*\{", text)[0]
    text = re.sub(r"/\*.*?\*/", "", text, flags=re.S)
    return "\n".join(re.sub(r"//.*", "", line) for line in text.splitlines())


def own_module(path, src):
    rel = os.path.relpath(path, src)[:-3].split(os.sep)
    if rel[-1] in ("mod", "lib"):
        return tuple(rel[:-1])
    return tuple(rel)


def resolve(parts, mods):
    for n in range(len(parts), -1, -1):
        if tuple(parts[:n]) in mods:
            return tuple(parts[:n])
    return None


def edges(src, mods):
    out = {}
    for mod, path in mods.items():
        code = code_of(path)
        targets = set()
        # `use a::{b, c::d}` groups: expand one level of braces.
        for m in re.finditer(r"\b(crate|super(?:::super)*)((?:::\w+)+)(::\{([^}]*)\})?", code):
            head, tail, _, group = m.groups()
            # `super` is the parent of this file's module (for a mod.rs, of its folder's).
            base = [] if head == "crate" else list(mod)[: len(mod) - head.count("super")]
            parts = base + [p for p in tail.split("::") if p]
            paths = [parts]
            if group:
                for item in group.split(","):
                    item = item.strip().split(" as ")[0]
                    if item and item != "self":
                        paths.append(parts + [p for p in item.split("::") if p])
            for p in paths:
                t = resolve(p, mods)
                if t is not None and t != mod:
                    targets.add(t)
        out[mod] = targets
    return out


def sccs(graph):
    index, low, stack, on, out, counter = {}, {}, [], set(), [], [0]

    def visit(v):
        index[v] = low[v] = counter[0]
        counter[0] += 1
        stack.append(v)
        on.add(v)
        for w in graph.get(v, ()):
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
    for v in graph:
        if v not in index:
            visit(v)
    return out


def main():
    args = [a for a in sys.argv[1:] if not a.startswith("--")]
    siblings = "--siblings" in sys.argv
    src = args[0] if args else os.path.join(os.path.dirname(__file__), "..", "crates", "inertia", "src")
    mods = modules(src)
    graph = edges(src, mods)
    if siblings:
        for m, ts in graph.items():
            # Drop parent <-> child edges.
            graph[m] = {t for t in ts if not (t == m[:-1] or t[:-1] == m)}
    loops = sccs(graph)
    for comp in loops:
        print("loop:", ", ".join("::".join(c) or "crate" for c in comp))
    print(f"{len(loops)} import loops among {len(mods)} files")


if __name__ == "__main__":
    main()
