#!/usr/bin/python3
"""Layers.IncludesGoOnlyDownward: every project include in kernels/<layer>/ and host/<layer>/ (sub-folders included,
every C++ suffix, in quotes or angle brackets) names a file of its own layer or of one below it, in the order CMake
builds them (BUILD/layers.txt, from TRIAXDEM_LAYERS in CMakeLists.txt), and spells it from the source root
("host/<layer>/<file>" or "kernels/<layer>/<file>"); a header the build generates is left alone. A library from
outside the project is included only at or above the layer that links it (BUILD/layer_libs.txt: library, then the
layer or the files, comma-separated, that link it). Each test file includes nothing above the layer its executable links
(BUILD/test_layers.txt). Prints each offending include with its file and line, and the layer order.

    tests/layers_test.py SOURCE_DIR BUILD_DIR
"""
import os
import re
import sys

INCLUDE = re.compile(r'^\s*#\s*include\s+([<"])([^">]+)[">]')
SUFFIXES = (".cpp", ".hpp", ".h", ".hh", ".hxx", ".cc", ".cxx", ".inl", ".ipp", ".tpp")
NOT_BUILT = (".cc", ".cxx")  # a layer's library compiles *.cpp (CMakeLists.txt: GLOB_RECURSE)
# The headers of the libraries from outside, by the name layer_libs.txt gives each.
LIBRARY_HEADERS = [("kokkos", re.compile(r"^(Kokkos_|impl/Kokkos_)")), ("mpi", re.compile(r"^mpi\.h$")),
                   ("hdf5", re.compile(r"^(hdf5|H5)[A-Za-z0-9_]*\.h$")), ("toml", re.compile(r"^toml\+\+/")),
                   ("eigen", re.compile(r"^(Eigen|unsupported/Eigen)/")), ("cli11", re.compile(r"^CLI/"))]


def layer_of(path):
    parts = path.split("/")
    if len(parts) < 3:
        return None
    if parts[0] == "kernels":
        return "kernels/" + parts[1]
    if parts[0] == "host":
        return parts[1]
    return None


def is_project(name):
    return name.startswith("host/") or name.startswith("kernels/")


def library_of(name):
    return next((lib for lib, pattern in LIBRARY_HEADERS if pattern.match(name)), None)


def sources(src):
    """Every C++ file under host/ and kernels/, relative to the source root."""
    out = []
    for top in ("host", "kernels"):
        for d, _, names in os.walk(os.path.join(src, top)):
            out += [os.path.relpath(os.path.join(d, n), src) for n in names if n.endswith(SUFFIXES)]
    return sorted(out)


class Guard:
    def __init__(self, src, build):
        self.src = src
        with open(os.path.join(build, "layers.txt")) as f:
            self.order = [line.strip() for line in f if line.strip()]
        self.rank = {name: k for k, name in enumerate(self.order)}
        self.libs = {}
        with open(os.path.join(build, "layer_libs.txt")) as f:
            for line in f:
                if line.strip():
                    lib, owner = line.split()
                    self.libs[lib] = owner

    def library_include(self, where, rel, layer, name):
        """An include of an outside library by a file of `layer` (rel, the file): "" or what is wrong."""
        lib = library_of(name)
        owner = self.libs.get(lib)
        if owner is None:
            return ""  # not a library the layers link (the standard library, GoogleTest), or not in this build
        if owner in self.rank:
            if self.rank.get(layer, -1) >= self.rank[owner]:
                return ""
            return f"{where}: includes <{name}>: {lib} is linked by layer {owner}, above {layer}"
        if rel in owner.split(","):
            return ""
        return f"{where}: includes <{name}>: {lib} is linked by {owner.replace(',', ' and ')} alone"

    def check_layers(self):
        bad = []
        files = sources(self.src)
        bad += [f"{p}: outside every layer ({p.split('/')[0]}/<layer>/)" for p in files if layer_of(p) is None]
        files = [p for p in files if layer_of(p) is not None]
        bad += [f"{p}: a source no layer compiles (the layers build *.cpp)" for p in files if p.endswith(NOT_BUILT)]
        ours = {os.path.basename(p) for p in files}
        for rel in files:
            mine = layer_of(rel)
            if mine not in self.rank:
                bad.append(f"{rel}: its folder is no layer of layers.txt")
                continue
            with open(os.path.join(self.src, rel)) as f:
                for n, line in enumerate(f, 1):
                    m = INCLUDE.match(line)
                    if not m:
                        continue
                    quote, name = m.groups()
                    where = f"{rel}:{n}"
                    if quote == "<" and not is_project(name):
                        problem = self.library_include(where, rel, mine, name)
                        if problem:
                            bad.append(problem)
                        continue
                    if "/" not in name and name not in ours:
                        continue  # a header the build generates (triaxdem_commit.hpp)
                    theirs = layer_of(name)
                    if theirs is None or not is_project(name) or not os.path.exists(os.path.join(self.src, name)):
                        bad.append(f"{where}: \"{name}\" is not spelled from the source root (host/<layer>/<file> "
                                   "or kernels/<layer>/<file>)")
                    elif self.rank.get(theirs, len(self.order)) > self.rank[mine]:
                        bad.append(f"{where}: includes {name}: layer {theirs} lies above {mine}")
        return bad, len(files)

    def includes(self, rel, seen):
        """The includes of a test file and of the test headers it includes (tests/..., followed), with where."""
        out = []
        with open(os.path.join(self.src, rel)) as f:
            for n, line in enumerate(f, 1):
                m = INCLUDE.match(line)
                if not m:
                    continue
                name = m.group(2)
                local = next((p for p in (os.path.join(os.path.dirname(rel), name), name)
                              if p.startswith("tests/") and os.path.exists(os.path.join(self.src, p))), None)
                if local:
                    if local not in seen:
                        seen.add(local)
                        out += self.includes(local, seen)
                else:
                    out.append((f"{rel}:{n}", name))
        return out

    def check_tests(self, build):
        """Each test file, with the test headers it includes, names nothing above the layer its executable links
        (BUILD/test_layers.txt, from tests/CMakeLists.txt), its layer's libraries included."""
        bad = []
        with open(os.path.join(build, "test_layers.txt")) as f:
            for line in f:
                if not line.strip():
                    continue
                rel, layer = line.split()
                for where, name in self.includes(rel, set()):
                    theirs = layer_of(name) if is_project(name) else None
                    if theirs is not None and self.rank.get(theirs, len(self.rank)) > self.rank[layer]:
                        bad.append(f"{where}: includes {name}: layer {theirs} lies above {layer}, the layer {rel} "
                                   "links")
                    elif theirs is None:
                        problem = self.library_include(where, rel, layer, name)
                        if problem:
                            bad.append(problem + f" (the test links {layer})")
        return bad


def main():
    if len(sys.argv) != 3:
        sys.exit(__doc__)
    src, build = sys.argv[1], sys.argv[2]
    guard = Guard(src, build)
    bad, count = guard.check_layers()
    bad += guard.check_tests(build)
    if bad:
        print("\n".join(bad))
        print(f"layers, lowest first: {' < '.join(guard.order)}")
        sys.exit(1)
    print(f"{count} files in {len(guard.order)} layers ({' < '.join(guard.order)}), libraries "
          f"{', '.join(f'{k} from {v}' for k, v in guard.libs.items())}: every include goes down or sideways")


if __name__ == "__main__":
    main()
