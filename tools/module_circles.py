#!/usr/bin/env python3
"""Import circles between the file modules of each crate under the src/ dirs given on the command line.

Each crate (`lib.rs`, `main.rs`, `bin/NAME.rs`, `bin/NAME/main.rs` under a given dir) is read
from its root file by following its `mod NAME;` declarations (and `#[path]`), so every file is a
module at its own depth: `bank/readback.rs` is `bank::readback`, `motion/mod.rs` is `motion`,
the root file is `crate`. Inline `mod NAME { }` blocks belong to the file they are written in
(a newcomer reads the file), but `super::`/`self::` inside them count from the inline module.

A module depends on the module of every path its code names: `crate::a::b::Item` counts for
the longest existing module prefix (`a::b`), `super::` and `self::` count from the module the
code is in, a bare `child::f()` counts for a child module, `use` groups may nest braces, and a
name that a module merely imports or re-exports (`pub use child::X`, `use crate::y::Z`) counts
for the module that defines it when other code reaches it through that module. Declaring a
child (`mod child;`) is not a dependency; `pub use child::X` in the parent is (parent -> child),
and `super::Thing` in a child for a `Thing` defined in the parent is (child -> parent).
Comments, strings and `#[cfg(test)]` items (found by matching their braces, so only the gated
module, function or `use` is left out) are not read: tests may use anything.

A circle (strongly connected set of two or more modules) means one part cannot be read without
the other. Prints each crate's circles, and its graph when it has one (or with -v); exits 1 if
any crate has one.

    tools/module_circles.py [-v] firmware-atom/src firmware-basic/src ...
"""
import os
import re
import sys

IDENT = r"[A-Za-z_][A-Za-z0-9_]*"
ITEM = re.compile(
    r"\b(?:fn|struct|enum|trait|type|const|static|union|macro_rules!)\s+(" + IDENT + r")"
)
CFG_TEST = re.compile(r"#\s*\[\s*cfg\s*\(\s*test\s*\)\s*\]")
CFG_TEST_INNER = re.compile(r"#!\s*\[\s*cfg\s*\(\s*test\s*\)\s*\]")
MOD_DECL = re.compile(r"\bmod\s+(" + IDENT + r")\s*([;{])")
PATH_ATTR = re.compile(r'#\s*\[\s*path\s*=\s*"([^"]*)"\s*\]')
EXTERNAL = "external"
USE = re.compile(r"(?<![\w$])use\s+")
PATH = re.compile(
    r"(?<![\w:$])(\$?crate|super|self|[a-z_][a-z0-9_]*)((?:\s*::\s*(?:" + IDENT + r"))+)"
)


def blank(text, start, end):
    """`text` with [start, end) replaced by spaces, newlines kept (offsets stay valid)."""
    return text[:start] + re.sub(r"[^\n]", " ", text[start:end]) + text[end:]


def strip(code):
    """Comments and the contents of string and char literals blanked, same length as `code`."""
    out, i, n = list(code), 0, len(code)

    def wipe(a, b):
        for k in range(a, min(b, n)):
            if out[k] != "\n":
                out[k] = " "

    while i < n:
        c = code[i]
        if code.startswith("//", i):
            j = code.find("\n", i)
            j = n if j < 0 else j
            wipe(i, j)
            i = j
        elif code.startswith("/*", i):
            depth, j = 1, i + 2
            while j < n and depth:
                if code.startswith("/*", j):
                    depth, j = depth + 1, j + 2
                elif code.startswith("*/", j):
                    depth, j = depth - 1, j + 2
                else:
                    j += 1
            wipe(i, j)
            i = j
        elif c in "br" and (m := re.match(r'b?r(#*)"', code[i : i + 260])) and not (
            i and (code[i - 1].isalnum() or code[i - 1] == "_")
        ):
            close = '"' + m.group(1)
            j = code.find(close, i + m.end())
            j = n if j < 0 else j + len(close)
            wipe(i + m.end(), j - len(close))
            i = j
        elif c == '"':
            j = i + 1
            while j < n and code[j] != '"':
                j += 2 if code[j] == "\\" else 1
            wipe(i + 1, j)
            i = j + 1
        elif c == "'":
            if i + 1 < n and code[i + 1] == "\\":
                j = code.find("'", i + 2)
                wipe(i + 1, j)
                i = j + 1
            elif i + 2 < n and code[i + 2] == "'":
                wipe(i + 1, i + 2)
                i += 3
            else:
                i += 1  # a lifetime
        else:
            i += 1
    return "".join(out)


def match_close(code, open_at):
    """The offset just past the bracket closing the one at `open_at`."""
    pairs = {"{": "}", "(": ")", "[": "]"}
    stack = []
    for j in range(open_at, len(code)):
        c = code[j]
        if c in pairs:
            stack.append(pairs[c])
        elif stack and c == stack[-1]:
            stack.pop()
            if not stack:
                return j + 1
    return len(code)


def item_end(code, start):
    """The offset just past the item starting at `start`: its `;` or its block's `}`."""
    j = start
    while True:  # further attributes on the same item
        m = re.compile(r"\s*#\s*\[").match(code, j)
        if not m:
            break
        j = match_close(code, m.end() - 1)
    depth = 0
    while j < len(code):
        c = code[j]
        if c in "([":
            depth += 1
        elif c in ")]":
            depth -= 1
        elif depth == 0 and c == ";":
            return j + 1
        elif depth == 0 and c == "{":
            return match_close(code, j)
        j += 1
    return len(code)


def drop_test_items(code):
    """`code` with every `#[cfg(test)]` item blanked; None if the whole file is test-only."""
    if CFG_TEST_INNER.search(code):
        return None
    while m := CFG_TEST.search(code):
        code = blank(code, m.start(), item_end(code, m.end()))
    return code


def parse_use_tree(text):
    """[(path segments, name bound or None for a glob)] of one `use` tree (after `use`)."""
    tokens = re.findall(r"::|\{|\}|,|\*|\$?" + IDENT, text)
    pos = 0

    def tree(prefix):
        nonlocal pos
        path = list(prefix)
        found = []
        while pos < len(tokens):
            t = tokens[pos]
            if t == "::":
                pos += 1
            elif t == "{":
                pos += 1
                while pos < len(tokens) and tokens[pos] != "}":
                    if tokens[pos] == ",":
                        pos += 1
                        continue
                    found += tree(path)
                pos += 1
                return found
            elif t == "*":
                pos += 1
                return found + [(path, None)]
            elif t in (",", "}"):
                break
            elif t == "as":
                alias = tokens[pos + 1]
                pos += 2
                return found + [(path, alias)]
            else:
                path.append(t)
                pos += 1
        if path and path[-1] == "self":
            path = path[:-1]
        if len(path) > len(prefix):
            found.append((path, path[-1]))
        return found

    return tree([])


class Crate:
    def __init__(self, root_file):
        self.files = {}  # file module path (tuple) -> [(file, blanked code)]
        self.modules = set()  # every module path, file or inline
        self.imports = {}  # module path -> {name: path segments}
        self.globs = {}  # module path -> [path segments]
        self.items = {}  # module path -> {names defined there}
        self.paths = []  # (file module, module the code is in, path segments)
        self.load((), root_file)

    def load(self, module, path):
        with open(path) as f:
            original = f.read()
        code = drop_test_items(strip(original))
        if code is None:
            return
        self.files.setdefault(module, []).append((path, code))
        self.modules.add(module)
        inline = []  # (start, end, name)
        for m in MOD_DECL.finditer(code):
            if m.group(2) == "{":
                inline.append((m.end() - 1, match_close(code, m.end() - 1), m.group(1)))

        def where(offset):
            return module + tuple(n for s, e, n in inline if s <= offset < e)

        for s, _, name in inline:
            self.modules.add(where(s) + (name,))
        base = os.path.dirname(path)
        stem = os.path.basename(path)[:-3]
        children = base if stem in ("mod", "lib", "main") else os.path.join(base, stem)
        for m in MOD_DECL.finditer(code):
            if m.group(2) != ";":
                continue
            name, inner = m.group(1), where(m.start())[len(module) :]
            attrs = re.search(r"((?:#\s*\[[^\]]*\]\s*)*)(?:pub(?:\s*\([^)]*\))?\s*)?$", code[max(0, m.start() - 400) : m.start()])
            shift = max(0, m.start() - 400)
            attr_text = original[shift + attrs.start(1) : shift + attrs.end(1)] if attrs else ""
            explicit = PATH_ATTR.search(attr_text)
            if explicit:
                candidates = [os.path.join(base, *inner, explicit.group(1))]
            else:
                d = os.path.join(children, *inner)
                candidates = [os.path.join(d, name + ".rs"), os.path.join(d, name, "mod.rs")]
            for c in candidates:
                if os.path.exists(c):
                    self.load(where(m.start()) + (name,), c)
                    break
        # definitions, imports and paths
        for m in ITEM.finditer(code):
            self.items.setdefault(where(m.start()), set()).add(m.group(1))
        for s, _, name in inline:
            self.items.setdefault(where(s), set()).add(name)
        while m := USE.search(code):
            end = item_end(code, m.end())
            in_module = where(m.start())
            for segments, name in parse_use_tree(code[m.end() : end].rstrip(";")):
                if name is None:
                    self.globs.setdefault(in_module, []).append(segments)
                else:
                    self.imports.setdefault(in_module, {})[name] = segments
                self.paths.append((module, in_module, segments))
            code = blank(code, m.start(), end)
        for m in PATH.finditer(code):
            segments = [m.group(1)] + re.findall(IDENT, m.group(2))
            self.paths.append((module, where(m.start()), segments))

    def resolve(self, module, segments, seen=()):
        """(module the path reaches, whether the whole path named modules), or None if external."""
        key = (module, tuple(segments))
        if key in seen:
            return None
        seen = seen + (key,)
        first, rest = segments[0], list(segments[1:])
        if first in ("crate", "$crate"):
            current = ()
        elif first == "self":
            current = module
        elif first == "super":
            current = module[:-1]
            while rest and rest[0] == "super":
                current, rest = current[:-1], rest[1:]
        elif module + (first,) in self.modules:
            current = module + (first,)
        elif first in self.imports.get(module, {}):
            target = self.resolve(module, self.imports[module][first], seen)
            if target is None or not target[1]:
                return target
            current = target[0]
        else:
            return None  # another crate
        for seg in rest:
            step = self.step(current, seg, seen)
            if step is EXTERNAL:
                return None
            if step is None:
                return current, False
            current, whole = step
            if not whole:
                return current, False
        return current, True

    def step(self, current, seg, seen):
        """Where the name `seg` of module `current` leads: (module, is a module), EXTERNAL if
        to another crate, or None if `current` defines it (or it is not known)."""
        if current + (seg,) in self.modules:
            return current + (seg,), True
        if seg in self.items.get(current, set()):
            return None
        if seg in self.imports.get(current, {}):
            return self.resolve(current, self.imports[current][seg], seen) or EXTERNAL
        for glob in self.globs.get(current, []):
            source = self.resolve(current, glob, seen)
            if source and source[1] and source[0] != current:
                found = self.step(source[0], seg, seen + ((current, seg),))
                if found is not None:
                    return found
                if seg in self.items.get(source[0], set()):
                    return source[0], False
        return None

    def file_module(self, module):
        while module not in self.files:
            module = module[:-1]
        return module

    def graph(self):
        """{module name: set of module names it depends on}."""
        name = lambda m: "::".join(m) or "crate"
        graph = {name(m): set() for m in self.files}
        for file, in_module, segments in self.paths:
            target = self.resolve(in_module, segments)
            if target is None:
                continue
            target = self.file_module(target[0])
            if target != file:
                graph[name(file)].add(name(target))
        return graph


def crate_roots(src):
    """[(label, root file)] of the crates whose sources are under `src`."""
    roots = []
    for name in ("lib.rs", "main.rs"):
        if os.path.exists(os.path.join(src, name)):
            roots.append((f"{src}" + ("" if name == "lib.rs" else " (main.rs)"), os.path.join(src, name)))
    bins = os.path.join(src, "bin")
    if os.path.isdir(bins):
        for entry in sorted(os.listdir(bins)):
            path = os.path.join(bins, entry)
            main = path if entry.endswith(".rs") else os.path.join(path, "main.rs")
            if os.path.exists(main):
                roots.append((f"{src} (bin {entry.removesuffix('.rs')})", main))
    return roots


def circles(graph):
    """The strongly connected sets of two or more modules (Tarjan's algorithm)."""
    index, low, stack, on_stack, found = {}, {}, [], set(), []

    def visit(v):
        index[v] = low[v] = len(index)
        stack.append(v)
        on_stack.add(v)
        for w in sorted(graph[v]):
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
        for label, root in crate_roots(src):
            graph = Crate(root).graph()
            found = circles(graph)
            print(f"{label}: {len(graph)} modules, circles: {found or 'none'}")
            if found or verbose:
                width = max(len(m) for m in graph)
                for module in sorted(graph):
                    print(f"  {module:{width}} -> {', '.join(sorted(graph[module]))}")
            failed |= bool(found)
    return 1 if failed else 0


if __name__ == "__main__":
    sys.setrecursionlimit(10000)
    args = sys.argv[1:]
    verbose = "-v" in args
    sys.exit(main([a for a in args if a != "-v"] or ["src"], verbose))
