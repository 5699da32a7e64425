#!/usr/bin/env python3
"""Checks the dependency direction of the source tree (issue 33), from the #include lines:

1. Folders: scenes < raster < gbuffer < lighting < experiments. A file may include its own
   folder and the folders below it, never one above (e.g. nothing in gbuffer/ includes lighting/).
   raster/ is independent of scenes/ too: it knows triangles, not scenes.
2. Rooms (a folder's subfolders): the graph of room-to-room includes has no cycle, so every room
   can be read after the rooms it includes. A folder's top level holds its interface (Scene.h,
   GBuffer.h, ShadingStage.h) and its entry points: rooms include it and it includes rooms, so it
   is not a node of this graph; what keeps it honest is rule 3.
3. Files: no include cycle between files anywhere (#pragma once would hide one).

Usage: include_layers.py SOURCE_DIR. Prints the room graph's order on success; on failure one line
per violation (file, line, include) and exit code 1. Run by ctest (style.IncludeLayers).
"""
import os
import re
import sys

FOLDERS = ["scenes", "raster", "gbuffer", "lighting", "experiments"]
# What each folder may include besides itself.
ALLOWED = {
    "scenes": set(),
    "raster": set(),
    "gbuffer": {"scenes", "raster"},
    "lighting": {"scenes", "raster", "gbuffer"},
    "experiments": {"scenes", "raster", "gbuffer", "lighting"},
}
INCLUDE = re.compile(r'^\s*#\s*include\s+"([^"]+)"')


def room_of(path):
    """'lighting/passes/X.h' -> 'lighting/passes'; 'lighting/X.h' -> 'lighting' (the top)."""
    parts = path.split("/")
    if len(parts) <= 2:
        return parts[0]
    return parts[0] + "/" + parts[1]


def find_cycles(graph, label, problems, order):
    """Iterative depth-first search; appends one line per back edge found."""
    state = {}
    for start in sorted(set(graph) | {b for bs in graph.values() for b in bs}):
        if start in state:
            continue
        stack = [(start, iter(sorted(graph.get(start, ()))))]
        path = [start]
        state[start] = "open"
        while stack:
            node, children = stack[-1]
            nxt = next(children, None)
            if nxt is None:
                stack.pop()
                path.pop()
                state[node] = "done"
                order.append(node)
            elif state.get(nxt) == "open":
                problems.append(label + ": " + " -> ".join(path[path.index(nxt):] + [nxt]))
            elif nxt not in state:
                state[nxt] = "open"
                path.append(nxt)
                stack.append((nxt, iter(sorted(graph.get(nxt, ())))))


def main():
    root = sys.argv[1]
    problems = []
    edges = {}
    file_edges = {}
    for folder in FOLDERS:
        for dirpath, _, files in os.walk(os.path.join(root, folder)):
            for name in files:
                if not name.endswith((".h", ".cpp")):
                    continue
                full = os.path.join(dirpath, name)
                rel = os.path.relpath(full, root)
                with open(full, encoding="utf-8", errors="replace") as f:
                    for number, line in enumerate(f, 1):
                        m = INCLUDE.match(line)
                        if not m:
                            continue
                        target = m.group(1)
                        top = target.split("/")[0]
                        if top not in FOLDERS:
                            continue  # generated files, system headers in quotes
                        if top != folder and top not in ALLOWED[folder]:
                            problems.append(f"{rel}:{number}: {folder}/ includes {target} "
                                            f"(a folder above it)")
                        file_edges.setdefault(rel, set()).add(target)
                        a, b = room_of(rel), room_of(target)
                        if a != b and "/" in a and "/" in b:
                            edges.setdefault(a, set()).add(b)
    # Cycle check (depth-first, reporting one cycle per strongly connected set).
    state = {}
    order = []
    find_cycles(file_edges, "file cycle", problems, [])

    def visit(node, stack):
        state[node] = "open"
        stack.append(node)
        for nxt in sorted(edges.get(node, ())):
            if state.get(nxt) == "open":
                cycle = stack[stack.index(nxt):] + [nxt]
                problems.append("room cycle: " + " -> ".join(cycle))
            elif nxt not in state:
                visit(nxt, stack)
        stack.pop()
        state[node] = "done"
        order.append(node)

    for node in sorted(set(edges) | {b for bs in edges.values() for b in bs}):
        if node not in state:
            visit(node, [])
    if problems:
        print("\n".join(problems), file=sys.stderr)
        return 1
    print("include_layers: no upward include, no room cycle; rooms in dependency order:")
    print("  " + " < ".join(order))
    return 0


if __name__ == "__main__":
    sys.exit(main())
