#!/usr/bin/python3
"""Layers.IncludesGoOnlyDownward: every project include in kernels/<layer>/ and host/<layer>/ names a file of its own
layer or of one below it, in the order CMake builds them (BUILD/layers.txt, from TRIAXDEM_LAYERS in
CMakeLists.txt), and spells it from the source root ("host/<layer>/<file>" or "kernels/<layer>/<file>"); a header
the build generates is left alone. Each test file includes nothing above the layer its executable links
(BUILD/test_layers.txt). Prints each offending include with its file and line, and the layer order.

    tests/layers_test.py SOURCE_DIR BUILD_DIR
"""
import glob
import os
import re
import sys

INCLUDE = re.compile(r'^\s*#\s*include\s+"([^"]+)"')


def layer_of(path):
    parts = path.split("/")
    if parts[0] == "kernels" and len(parts) == 3:
        return "kernels/" + parts[1]
    if parts[0] == "host" and len(parts) == 3:
        return parts[1]
    return None


def includes(src, rel, seen):
    """The project includes of a test file and of the test headers it includes (tests/..., followed), with where."""
    out = []
    with open(os.path.join(src, rel)) as f:
        for n, line in enumerate(f, 1):
            m = INCLUDE.match(line)
            if not m:
                continue
            name = m.group(1)
            local = next((p for p in (os.path.join(os.path.dirname(rel), name), name)
                          if p.startswith("tests/") and os.path.exists(os.path.join(src, p))), None)
            if local:
                if local not in seen:
                    seen.add(local)
                    out += includes(src, local, seen)
            else:
                out.append((f"{rel}:{n}", name))
    return out


def check_tests(src, build, rank):
    """Each test file, with the test headers it includes, names nothing above the layer its executable links
    (BUILD/test_layers.txt, from tests/CMakeLists.txt)."""
    bad = []
    with open(os.path.join(build, "test_layers.txt")) as f:
        for line in f:
            if not line.strip():
                continue
            rel, layer = line.split()
            for where, name in includes(src, rel, set()):
                theirs = layer_of(name)
                if theirs is not None and rank.get(theirs, len(rank)) > rank[layer]:
                    bad.append(f"{where}: includes {name}: layer {theirs} lies above {layer}, the layer {rel} links")
    return bad


def main():
    if len(sys.argv) != 3:
        sys.exit(__doc__)
    src, build = sys.argv[1], sys.argv[2]
    with open(os.path.join(build, "layers.txt")) as f:
        order = [line.strip() for line in f if line.strip()]
    rank = {name: k for k, name in enumerate(order)}
    bad = []
    stray = sorted(os.path.relpath(p, src) for top in ("host", "kernels")
                   for p in glob.glob(os.path.join(src, top, "*.[ch]pp")))
    bad += [f"{p}: outside every layer ({p.split('/')[0]}/<layer>/)" for p in stray]
    files = glob.glob(os.path.join(src, "kernels", "*", "*.[ch]pp")) + glob.glob(os.path.join(src, "host", "*", "*.[ch]pp"))
    ours = {os.path.basename(p) for p in files}
    for path in sorted(files):
        rel = os.path.relpath(path, src)
        mine = layer_of(rel)
        if mine not in rank:
            bad.append(f"{rel}: its folder is no layer of {os.path.join(build, 'layers.txt')}")
            continue
        with open(path) as f:
            for n, line in enumerate(f, 1):
                m = INCLUDE.match(line)
                if not m:
                    continue
                name = m.group(1)
                if "/" not in name and name not in ours:
                    continue  # a header the build generates (triaxdem_commit.hpp)
                theirs = layer_of(name)
                if theirs is None or not os.path.exists(os.path.join(src, name)):
                    bad.append(f"{rel}:{n}: \"{name}\" is not spelled from the source root (host/<layer>/<file> or "
                               "kernels/<layer>/<file>)")
                elif rank.get(theirs, len(order)) > rank[mine]:
                    bad.append(f"{rel}:{n}: includes {name}: layer {theirs} lies above {mine}")
    bad += check_tests(src, build, rank)
    if bad:
        print("\n".join(bad))
        print(f"layers, lowest first: {' < '.join(order)}")
        sys.exit(1)
    print(f"{len(files)} files in {len(order)} layers ({' < '.join(order)}): every include goes down or sideways")


if __name__ == "__main__":
    main()
