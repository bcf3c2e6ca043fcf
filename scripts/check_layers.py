#!/usr/bin/env python3
"""Checks the library's layering (docs/architecture.md, "Layers"): every #include under
src/amalgam points to the same layer or a lower one, the include graph has no cycle, a header
compiled once per instruction set (AMALGAM_ISA_BEGIN, util/isa.h) is included in src/ only by
such headers or by render/render_isa.inl (file and function lengths: check_sizes.py). Prints
each violation and exits 1 if there is any.   Usage: check_layers.py [SOURCE_DIR]"""
import os
import re
import sys

LAYERS = ["util", "math", "geometry", "stats", "scene", "hierarchy", "builtin", "traverse",
          "render", "analysis", "io", "load"]
# The files that compile the per-instruction-set copies (embree_tracer.cpp: the integrator and
# pass loop over Embree, its portable copy only; lit_ratio.cpp: the traversal for a bake, its
# portable copy only).
ISA_ENTRIES = {"amalgam/render/render_isa.inl", "amalgam/render/render_portable.cpp",
               "amalgam/render/render_avx2.cpp", "amalgam/render/embree_tracer.cpp",
               "amalgam/traverse/lit_ratio.cpp"}

root = os.path.join(sys.argv[1] if len(sys.argv) > 1 else os.getcwd(), "src")
inc = re.compile(r'^\s*#\s*include\s+"(amalgam/[^"]+)"', re.M)
files = {}
for d, _, names in os.walk(os.path.join(root, "amalgam")):
    for n in names:
        if n.endswith((".h", ".cpp", ".inl")):
            rel = os.path.relpath(os.path.join(d, n), root)
            files[rel] = open(os.path.join(root, rel), encoding="utf-8").read()

def layer(rel):
    top = rel.split("/")[1]
    if top not in LAYERS:
        return None
    return LAYERS.index(top)

def isa(rel):
    return "AMALGAM_ISA_BEGIN" in files.get(rel, "") and not rel.endswith("util/isa.h")

errors = []
graph = {}
for rel, text in sorted(files.items()):
    me = layer(rel)
    if me is None:
        errors.append(f"{rel}: not in a known layer ({', '.join(LAYERS)})")
        continue
    graph[rel] = []
    for target in inc.findall(text):
        if target not in files:
            errors.append(f"{rel}: includes {target}, which does not exist")
            continue
        graph[rel].append(target)
        them = layer(target)
        if them is not None and them > me:
            errors.append(f"{rel} ({LAYERS[me]}) includes {target} ({LAYERS[them]}): upward")
        if isa(target) and not (isa(rel) or rel in ISA_ENTRIES):
            errors.append(f"{rel} includes {target}, a per-instruction-set header (util/isa.h)")

# Cycles: depth-first search over the include graph.
state = {}
def visit(node, path):
    state[node] = 1
    for nxt in graph.get(node, []):
        if state.get(nxt) == 1:
            cyc = path[path.index(nxt):] + [nxt] if nxt in path else [node, nxt]
            errors.append("include cycle: " + " -> ".join(cyc))
        elif nxt not in state:
            visit(nxt, path + [nxt])
    state[node] = 2
for f in sorted(graph):
    if f not in state:
        visit(f, [f])

for e in errors:
    print(e)
print(f"layers: {len(files)} files, {sum(len(v) for v in graph.values())} includes, "
      f"{len(errors)} violations")
sys.exit(1 if errors else 0)
