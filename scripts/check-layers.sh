#!/usr/bin/env bash
# SPDX-License-Identifier: MIT
# The layers of docs/DEVELOPING.md ("Layers"), checked from the #include lines: fails
# (exit 1), naming each file and line, on
#   - an include from sdk/ into base/, framework/ or plugins/ (the SDK stands alone);
#   - an include from base/ into framework/ or plugins/ (the base layer uses the SDK and
#     itself only);
#   - an include from a plugin into framework/, or into another plugin's folder other
#     than plugins/common/ (a plugin uses the SDK, base/ and plugins/common/ only);
#   - an include from framework/pipeline/ into framework/rosbag/ (rosbag builds on the
#     pipeline's interfaces, never the reverse);
#   - an include of framework/app/ from any framework module but cli/ (the application
#     layer is on top: the CLI and the Python module call it, nothing below does);
#   - an include of core/output_folder.hpp from the front ends, framework/cli/ and
#     python/ (the application layer claims the output folder: a front end fills a
#     request and calls it);
#   - an include from python/ into plugins/ (the Python module, a front end like the CLI,
#     uses the framework, base/ and the SDK);
#   - a module name used by both base/ and framework/ ("<module>/x.hpp" would find one
#     of them by the search order alone);
#   - any cycle between modules (base/<module>/ and framework/<module>/ together): the
#     module graph is made from the includes, and each cycle is reported with the
#     includes that make it.
# An include is resolved as the compiler would find it: beside the including file, then
# under sdk/include, base/, framework/ and plugins/ (and, for python/, the tree's root:
# "python/run.hpp"); one that resolves to no file of the tree (the standard library,
# OpenCV, pybind11 ...) is not looked at.
# Usage: scripts/check-layers.sh [SOURCE_DIR]  (default: the tree holding this script).
# Run by CTest as `check_layers`; tests/layers/planted_includes.sh checks that it fails
# on includes planted in a copy of the tree (CTest `check_layers_planted`).
set -euo pipefail
root="${1:-$(cd "$(dirname "$0")/.." && pwd)}"
exec python3 - "$root" <<'PY'
import os
import re
import sys

ROOT = os.path.abspath(sys.argv[1])
SHARED_PLUGIN_FOLDER = "common"  # plugins/common/: what every plugin may include
FORBIDDEN_MODULE_EDGES = {("pipeline", "rosbag")}  # (from, to): never
APPLICATION_MODULE, APPLICATION_CALLERS = "app", {"cli"}  # framework/app/: included by cli/ (and python/) only
OUTPUT_FOLDER = os.path.join("framework", "core", "output_folder.hpp")  # claimed by app/ only
FRONT_ENDS = {("framework", "cli"), ("python", None)}  # what parses arguments into app/ requests
SUFFIXES = (".h", ".hpp", ".c", ".cpp", ".cc", ".inl")
INCLUDE = re.compile(r'^\s*#\s*include\s*([<"])([^>"]+)[>"]')
SEARCH = [os.path.join(ROOT, p) for p in ("sdk/include", "base", "framework", "plugins")]
MODULAR = ("base", "framework")  # layers made of modules, one folder each

for top in ("sdk", "base", "framework", "plugins", "python"):
    if not os.path.isdir(os.path.join(ROOT, top)):
        sys.exit(f"check-layers: {ROOT}: no {top}/ folder: expected the root of a Binocle tree")


def files_under(top):
    for base, dirs, names in os.walk(os.path.join(ROOT, top)):
        dirs.sort()
        for name in sorted(names):
            if name.endswith(SUFFIXES):
                yield os.path.join(base, name)


def resolve(including, quote, path, layer):
    candidates = ([os.path.dirname(including)] if quote == '"' else []) + SEARCH
    if layer == "python":  # the module's include path has the tree's root too
        candidates.append(ROOT)
    for base in candidates:
        target = os.path.normpath(os.path.join(base, path))
        if os.path.isfile(target):
            return os.path.relpath(target, ROOT)
    return None


def where(rel):
    """(layer, module): ('framework', 'core'), ('base', 'input'), ('plugins', 'sim'), ('sdk', None)."""
    parts = rel.split(os.sep)
    if parts[0] in MODULAR + ("plugins",) and len(parts) > 2:
        return parts[0], parts[1]
    return parts[0], None


problems = []
edges = {}  # (from module, to module) -> [(file, line, include)]


def modules_of(layer):
    top = os.path.join(ROOT, layer)
    return {d for d in os.listdir(top) if os.path.isdir(os.path.join(top, d))}


for name in sorted(modules_of("base") & modules_of("framework")):
    problems.append(f"base/{name}/ and framework/{name}/: one module name in two layers; "
                    f'"{name}/..." includes would find one of them by the search order alone: rename one')

for top in ("sdk", "base", "plugins", "framework", "python"):
    for f in files_under(top):
        rel = os.path.relpath(f, ROOT)
        layer, module = where(rel)
        with open(f, encoding="utf-8", errors="replace") as text:
            for number, line in enumerate(text, 1):
                m = INCLUDE.match(line)
                if not m:
                    continue
                target = resolve(f, m.group(1), m.group(2), layer)
                if target is None:
                    continue
                to_layer, to_module = where(target)
                close = ">" if m.group(1) == "<" else '"'
                at = f"{rel}:{number}: #include {m.group(1)}{m.group(2)}{close}"
                if (layer, module) in FRONT_ENDS and target == OUTPUT_FOLDER:
                    front = f"framework/{module}/" if module else f"{layer}/"
                    problems.append(f"{at} ({target}): {front} includes the output folder's claim; the application "
                                    f"layer (framework/{APPLICATION_MODULE}/) claims it: a front end fills a request and calls it")
                if layer == "python" and to_layer not in ("sdk", "base", "framework", "python"):
                    problems.append(f"{at} ({target}): python/ includes {to_layer}/; "
                                    "the Python module may include the SDK, base/ and framework/ only")
                if layer == "sdk" and to_layer != "sdk":
                    problems.append(f"{at} ({target}): the SDK includes {to_layer}/; the SDK must stand alone")
                elif layer == "base" and to_layer not in ("sdk", "base"):
                    problems.append(f"{at} ({target}): base/{module}/ includes {to_layer}/; "
                                    "the base layer may include the SDK and base/ only")
                elif layer == "plugins" and to_layer == "framework":
                    problems.append(f"{at} ({target}): plugin '{module}' includes framework/{to_module}/; "
                                    f"a plugin may include the SDK, base/ and plugins/{SHARED_PLUGIN_FOLDER}/ only")
                elif layer == "plugins" and to_layer == "plugins" and to_module not in (module, SHARED_PLUGIN_FOLDER):
                    problems.append(f"{at} ({target}): plugin '{module}' includes plugins/{to_module}/; "
                                    f"a plugin may include the SDK, base/ and plugins/{SHARED_PLUGIN_FOLDER}/ only")
                elif (layer == "framework" and to_layer == "framework" and to_module == APPLICATION_MODULE
                      and module not in APPLICATION_CALLERS | {APPLICATION_MODULE}):
                    problems.append(f"{at} ({target}): framework/{module}/ includes framework/{APPLICATION_MODULE}/; "
                                    f"the application layer is called by framework/cli/ and python/ only")
                elif layer in MODULAR and to_layer in MODULAR and module and to_module and module != to_module:
                    if (module, to_module) in FORBIDDEN_MODULE_EDGES:
                        problems.append(f"{at} ({target}): {layer}/{module}/ includes {to_layer}/{to_module}/; "
                                        f"{to_module}/ builds on {module}/, never the reverse")
                    edges.setdefault((module, to_module), []).append(at)

# Cycles: the strongly connected components of the module graph (Tarjan). For each, the
# module dependencies that alone close every cycle of it are named with one cycle through
# them; when no single one does, cycles are reported until every dependency inside it is
# on one. Each dependency is shown with an include that makes it.
graph = {}
for a, b in edges:
    graph.setdefault(a, set()).add(b)
    graph.setdefault(b, set())
index, low, stack, on_stack, components = {}, {}, [], set(), []


def connect(v):
    index[v] = low[v] = len(index)
    stack.append(v)
    on_stack.add(v)
    for w in sorted(graph[v]):
        if w not in index:
            connect(w)
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
            components.append(sorted(component))


sys.setrecursionlimit(10000)
for v in sorted(graph):
    if v not in index:
        connect(v)


def shortest_path(a, b, inside):
    previous, frontier = {a: None}, [a]
    while frontier:
        nxt = []
        for v in frontier:
            for w in sorted(graph[v] & inside):
                if w not in previous:
                    previous[w] = v
                    nxt.append(w)
        frontier = nxt
    path, v = [], b
    while v is not None:
        path.append(v)
        v = previous[v]
    return path[::-1]


def acyclic(inside, without):
    state = {}  # 1: on the path, 2: done

    def visit(v):
        state[v] = 1
        for w in graph[v] & inside:
            if (v, w) == without or state.get(w) == 2:
                continue
            if state.get(w) == 1 or not visit(w):
                return False
        state[v] = 2
        return True

    return all(state.get(v) == 2 or visit(v) for v in sorted(inside))


def cycle_report(cycle):
    lines = [f"include cycle between modules (base/, framework/): {' -> '.join(cycle)}"]
    for a, b in zip(cycle, cycle[1:]):
        sites = edges[(a, b)]
        more = f" (and {len(sites) - 1} more)" if len(sites) > 1 else ""
        lines.append(f"    {a} -> {b}: {sites[0]}{more}")
    return lines


for component in components:
    inside = set(component)
    inner = [(a, b) for a in component for b in sorted(graph[a] & inside)]
    # The includes whose removal alone breaks every cycle of the component, if any: one
    # cycle through them is reported, and they are named.
    closing = [e for e in inner if acyclic(inside, e)]
    if closing:
        a, b = closing[0]
        lines = cycle_report([a] + shortest_path(b, a, inside))
        lines.append("    removing any one of these module dependencies breaks every cycle among "
                     f"{', '.join(component)}: " + ", ".join(f"{x} -> {y}" for x, y in closing))
        problems.append("\n".join(lines))
        continue
    # Otherwise one cycle per include edge of the component not yet on a cycle reported,
    # closed by the shortest way back: every edge that takes part is shown.
    covered = set()
    for a, b in inner:
        if (a, b) in covered:
            continue
        cycle = [a] + shortest_path(b, a, inside)
        covered.update(zip(cycle, cycle[1:]))
        problems.append("\n".join(cycle_report(cycle)))

if problems:
    for p in problems:
        print(f"check-layers: {p}")
    print(f"check-layers: {len(problems)} problem(s) in {ROOT} (the layers: docs/DEVELOPING.md)")
    sys.exit(1)
modules = sorted(graph)
print(f"check-layers: ok: {sum(len(v) for v in edges.values())} includes between {len(modules)} modules of base/ and "
      "framework/, no cycle; sdk/ stands alone; base/ uses the SDK only; plugins use the SDK, base/ and "
      f"plugins/{SHARED_PLUGIN_FOLDER}/ only; framework/{APPLICATION_MODULE}/ is included by cli/ and python/ only and "
      "claims the output folder (they do not); python/ uses the SDK, base/ and framework/ only")
PY
