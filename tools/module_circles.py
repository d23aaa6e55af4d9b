#!/usr/bin/env python3
"""Import circles between the top-level modules of a crate's src/ (code, not comments)."""
import os, re, sys
src = sys.argv[1]
graph = {}
for root, _, files in os.walk(src):
    if '/bin' in root: continue
    for f in files:
        if not f.endswith('.rs'): continue
        path = os.path.join(root, f)
        rel = os.path.relpath(path, src)
        top = rel.split('/')[0].removesuffix('.rs')
        if top in ('lib', 'main'): continue
        code = '\n'.join(l.split('//')[0] for l in open(path).read().split('\n'))
        # test modules may use anything
        code = code.split('#[cfg(test)]')[0]
        deps = set(re.findall(r'crate::([a-z_]+)', code))
        for m in re.findall(r'use crate::\{([^}]*)\}', code):
            deps |= set(re.findall(r'\b([a-z_]+)\b', m))
        graph.setdefault(top, set()).update(d for d in deps if d != top)
# Tarjan SCC
index = {}; low = {}; stack = []; on = set(); sccs = []; i = [0]
def strong(v):
    index[v] = low[v] = i[0]; i[0] += 1; stack.append(v); on.add(v)
    for w in graph.get(v, ()):
        if w not in graph: continue
        if w not in index: strong(w); low[v] = min(low[v], low[w])
        elif w in on: low[v] = min(low[v], index[w])
    if low[v] == index[v]:
        c = []
        while True:
            w = stack.pop(); on.discard(w); c.append(w)
            if w == v: break
        if len(c) > 1: sccs.append(sorted(c))
for v in sorted(graph):
    if v not in index: strong(v)
for v in sorted(graph):
    print(f"{v:10} -> {', '.join(sorted(d for d in graph[v] if d in graph))}")
print("circles:", sccs or "none")
sys.exit(1 if sccs else 0)
