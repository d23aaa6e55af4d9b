#!/usr/bin/env python3
"""Import circles between the top-level modules of each crate's src/ given on the command line.

A module's dependencies are the `crate::NAME` paths in its code (comments and `#[cfg(test)]`
code left out: tests may use anything). A circle (strongly connected set of two or more
modules) means one part cannot be read without the other. Prints each crate's circles, and its
graph when it has one (or with -v); exits 1 if any crate has one.

    tools/module_circles.py [-v] firmware-atom/src firmware-basic/src ...
"""
import os
import re
import sys


def module_graph(src):
    """{module: set of modules it imports} for the top-level modules of `src`."""
    graph = {}
    for root, _, files in os.walk(src):
        if "/bin" in root:
            continue
        for name in files:
            if not name.endswith(".rs"):
                continue
            path = os.path.join(root, name)
            top = os.path.relpath(path, src).split("/")[0].removesuffix(".rs")
            if top in ("lib", "main"):
                continue
            with open(path) as f:
                code = "\n".join(line.split("//")[0] for line in f.read().split("\n"))
            code = code.split("#[cfg(test)]")[0]
            deps = set(re.findall(r"crate::([a-z_]+)", code))
            for group in re.findall(r"use crate::\{([^}]*)\}", code):
                deps |= set(re.findall(r"\b([a-z_]+)\b", group))
            graph.setdefault(top, set()).update(d for d in deps if d != top)
    return {module: {d for d in deps if d in graph} for module, deps in graph.items()}


def circles(graph):
    """The strongly connected sets of two or more modules (Tarjan's algorithm)."""
    index, low, stack, on_stack, found = {}, {}, [], set(), []

    def visit(v):
        index[v] = low[v] = len(index)
        stack.append(v)
        on_stack.add(v)
        for w in graph[v]:
            if w not in index:
                visit(w)
                low[v] = min(low[v], low[w])
            elif w in on_stack:
                low[v] = min(low[v], index[w])
        if low[v] == index[v]:
            component = []
            while True:
                w = stack.pop()
                on_stack.discard(w)
                component.append(w)
                if w == v:
                    break
            if len(component) > 1:
                found.append(sorted(component))

    for v in sorted(graph):
        if v not in index:
            visit(v)
    return found


def main(sources, verbose):
    failed = False
    for src in sources:
        graph = module_graph(src)
        found = circles(graph)
        print(f"{src}: {len(graph)} modules, circles: {found or 'none'}")
        if found or verbose:
            for module in sorted(graph):
                print(f"  {module:12} -> {', '.join(sorted(graph[module]))}")
        failed |= bool(found)
    return 1 if failed else 0


if __name__ == "__main__":
    args = sys.argv[1:]
    verbose = "-v" in args
    sys.exit(main([a for a in args if a != "-v"] or ["src"], verbose))
