#!/usr/bin/env python3
"""The layer test: lash's modules depend only downward (DESIGN.md, cmake/layers.txt).

Usage: check_layers.py SOURCE_DIR MODULE_GRAPH   (MODULE_GRAPH = build/lash_modules.txt,
written by src/CMakeLists.txt: "name|used modules|source folder|sources" per module).

Fails (exit 1, one line per finding) when
  - a file of module M (src/M/..., include/lash/M/...) includes "lash/N/..." or <lash/N/...>
    where N is above M in cmake/layers.txt, or not among the modules M links (USES, transitively);
  - a module's link list (USES) names a module the layer table does not allow;
  - the module graph has a cycle;
  - a module compiles a source outside src/M/;
  - a folder under src/ or include/lash/ is not a module of the build.
"""
import os
import re
import sys

src_dir, graph_file = sys.argv[1], sys.argv[2]

levels, only = {}, {}
level = 0
for raw in open(os.path.join(src_dir, "cmake", "layers.txt")):
    line = raw.split("#", 1)[0].strip()
    if not line:
        continue
    m = re.match(r"only ([a-z_]+):\s*(.*)$", line)
    if m:
        only[m.group(1)] = set(m.group(2).split())
        continue
    m = re.match(r"[a-z]+:\s*(.*)$", line)
    level += 1
    for mod in m.group(1).split():
        levels[mod] = level


def allowed(m, n):
    """May module m use module n according to the layer table?"""
    if n == m:
        return True
    if n not in levels or levels[n] > levels[m]:
        return False
    return n in only[m] if m in only else True


uses, folders, sources = {}, {}, {}
for line in open(graph_file):
    line = line.rstrip("\n")
    if not line:
        continue
    name, u, folder, srcs = line.split("|")
    uses[name] = set(u.split())
    folders[name] = folder
    sources[name] = srcs.split()

errors = []


def closure(m, seen=None):
    seen = set() if seen is None else seen
    for n in uses.get(m, ()):
        if n not in seen:
            seen.add(n)
            closure(n, seen)
    return seen


for m in uses:
    if m not in levels:
        errors.append(f"module {m} is built but not in cmake/layers.txt")
    for n in sorted(uses[m]):
        if not allowed(m, n):
            errors.append(f"module {m} links {n}, which cmake/layers.txt does not allow")
    if m in closure(m):
        errors.append(f"module {m} depends on itself (a cycle in the module graph)")
    for s in sources[m]:
        p = os.path.normpath(s if os.path.isabs(s) else os.path.join(folders[m], s))
        if not p.startswith(os.path.join(src_dir, "src", m) + os.sep):
            errors.append(f"module {m} compiles {os.path.relpath(p, src_dir)}, outside src/{m}/")

include_re = re.compile(r'^\s*#\s*include\s*[<"]lash/([a-z_]+)(/|\.hpp)')


def module_of(rel):
    parts = rel.split(os.sep)
    if parts[0] == "src" and len(parts) > 2:
        return parts[1]
    if parts[:2] == ["include", "lash"]:
        return parts[2] if len(parts) > 3 else os.path.splitext(parts[2])[0]  # lash/blocks.hpp → blocks
    return None


for top in ("src", os.path.join("include", "lash")):
    base = os.path.join(src_dir, top)
    for entry in sorted(os.listdir(base)):
        if os.path.isdir(os.path.join(base, entry)) and entry not in uses:
            errors.append(f"{top}/{entry}/ is not a module of the build (add it with lash_module)")
    for root, _, files in os.walk(base):
        for f in sorted(files):
            if not f.endswith((".hpp", ".cpp", ".h")):
                continue
            path = os.path.join(root, f)
            rel = os.path.relpath(path, src_dir)
            m = module_of(rel)
            if m is None:
                continue
            reach = closure(m) | {m}
            for no, line in enumerate(open(path, encoding="utf-8"), 1):
                hit = include_re.match(line)
                if not hit:
                    continue
                n = hit.group(1)
                if not allowed(m, n):
                    errors.append(f"{rel}:{no}: module {m} includes a header of {n}, which is not below it "
                                  f"(cmake/layers.txt)")
                elif n not in reach:
                    errors.append(f"{rel}:{no}: module {m} includes a header of {n} but does not link it "
                                  f"(add {n} to the USES of lash_module({m}))")

for e in errors:
    print(e)
if errors:
    sys.exit(1)
print(f"layers: {len(uses)} modules, every include and link points down")
