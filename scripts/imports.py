#!/usr/bin/env python3
"""Import cycles and arrows that do not point down, per crate and per folder.

    scripts/imports.py [--verbose] [ROOT]

Reads every crate of the workspace (and the Python package and the facade), builds the graph
of which source file uses which (through `use` and through paths written in the code,
followed through re-exports to the file that defines the item; tests, doc comments and the
re-export lists of `mod.rs` and `lib.rs` left out), and reports:

* cycles: sets of files that reach each other through their imports (strongly connected
  components of more than one file), by the folder that holds them;
* arrows not pointing down: imports that go against the floors ARCHITECTURE.md gives the
  folders of a crate (`FLOORS` below, its copy), a floor's groups side by side using only
  what is below them; and, between crates, a dependency on a crate that is not below.

Exit status 1 when any cycle or upward arrow is found, so CI can hold the count at zero.
"""

import re
import sys
import tomllib
from collections import defaultdict
from pathlib import Path

# The floors of each crate's folders, lowest first; each floor a list of groups that stand
# side by side (a group may use itself and any floor below, not its neighbours). A module
# path names a folder (and everything in it) or a file; the longest match wins. Modules
# named in no group are not judged (only their cycles count). Names of files that a
# restructuring moved stay listed, so that an older tree is judged by the same floors.
FLOORS = {
    "truenorth-cli": [
        # io's ground floor.
        [["io::error", "io::console", "io::temporaries", "io::closest_name", "io::spill",
          "io::reading_spill", "io::scratch"]],
        # io/reading, from bytes to samples.
        [["io::reading::records", "io::records"], ["io::reading::number_parse",
                                                    "io::number_parse"],
         ["io::reading::source", "io::source"]],
        [["io::reading::chunks", "io::chunks"], ["io::reading::plain_rows", "io::plain_rows"],
         ["io::reading::columns", "io::columns"], ["io::reading::wheels", "io::wheel_columns"],
         ["io::reading::logs::options"], ["io::reading::logs::rows", "io::log_rows"]],
        [["io::reading::row_blocks", "io::row_blocks"], ["io::reading::options"],
         ["io::reading::logs", "io::log_input"]],
        [["io::reading::row_parser"], ["io::reading::logs::blocks"]],
        [["io::reading::reader", "io::reader"]],
        [["io::reading::table", "io::table"], ["io::reading::samples"]],
        [["io::reading::kinds"], ["io::reading::input"], ["io::reading"]],
        # io's upper rooms, side by side.
        [["io::writing", "io::atomic_write", "io::output_target", "io::write_behind",
          "io::csv_output", "io::number_format", "io::json_input", "io::calibration_file",
          "io::vehicle_file", "io::learned_file"],
         ["io::checking", "io::unit_check", "io::inertial_units", "io::gyro_axes",
          "io::direction_spans", "io::yaw_rate_check", "io::compass_physics",
          "commands::mag_unit"]],
        [["io"]],
        [["registry"], ["plot"], ["inspect"]],
        [["commands"], ["demo"], ["eval"]],
    ],
    "truenorth-calib": [
        [["numerics"]],
        [["quality"]],
        [["fits"]],
        [["online"], ["seed"]],
    ],
    "truenorth-checks": [
        [["units"], ["spans"], ["compass"]],
        [["axes"]],
        [["finding"]],
        [["inertial"], ["yaw_rate"], ["field_unit"]],
    ],
}

# The crates from the bottom up (ARCHITECTURE.md, "Layering"): a crate may depend only on
# crates of a lower floor; sim and logs stand beside the stack on core (and the sensor
# crates' models), used by the CLI, the Python package and tests.
CRATE_FLOORS = [
    ["truenorth-core"],
    ["truenorth-geomag"],
    ["truenorth-compass", "truenorth-gyro", "truenorth-odometer", "truenorth-accel"],
    ["truenorth-calib"],
    ["truenorth-fusion"],
    ["truenorth-checks", "truenorth-sim", "truenorth-logs"],
    ["truenorth"],
    ["truenorth-cli", "truenorth-py"],
]


def strip(text):
    """The code of a file without comments, string and char literals, and test modules."""
    out, i, n = [], 0, len(text)
    while i < n:
        c = text[i]
        if text.startswith("//", i):
            j = text.find("\n", i)
            i = n if j < 0 else j
        elif text.startswith("/*", i):
            depth, i = 1, i + 2
            while i < n and depth:
                if text.startswith("/*", i):
                    depth, i = depth + 1, i + 2
                elif text.startswith("*/", i):
                    depth, i = depth - 1, i + 2
                else:
                    i += 1
        elif c == "r" and re.match(r'r#*"', text[i:i + 10]) and (i == 0 or not (
                text[i - 1].isalnum() or text[i - 1] == "_")):
            m = re.match(r'r(#*)"', text[i:])
            end = '"' + m.group(1)
            j = text.find(end, i + len(m.group(0)))
            out.append('""')
            i = n if j < 0 else j + len(end)
        elif c == '"':
            j = i + 1
            while j < n and text[j] != '"':
                j += 2 if text[j] == "\\" else 1
            out.append('""')
            i = j + 1
        elif c == "'" and re.match(r"'(\\.|[^\\'])'", text[i:i + 4]):
            m = re.match(r"'(\\.|[^\\'])'", text[i:])
            out.append("' '")
            i += len(m.group(0))
        else:
            out.append(c)
            i += 1
    code = "".join(out)
    # Items under #[cfg(test)]: a `mod name { ... }`, a `mod name;`, a `use`.
    while True:
        m = re.search(r"#\[cfg\(test\)\]\s*(pub(\([^)]*\))?\s+)?(mod\s+\w+\s*\{|mod\s+\w+\s*;|use\s[^;]*;)",
                      code)
        if not m:
            break
        start, end = m.start(), m.end()
        if code[end - 1] == "{":
            depth, j = 1, end
            while j < len(code) and depth:
                depth += {"{": 1, "}": -1}.get(code[j], 0)
                j += 1
            end = j
        code = code[:start] + code[end:]
    return code


def expand_use(tree):
    """`a::{b, c::{d, e as f}, self}` → ['a::b', 'a::c::d', 'a::c::e', 'a'] (a renamed
    import is followed by its own name)."""
    tree = re.sub(r"\s+as\s+\w+", "", tree)
    tree = re.sub(r"\s+", "", tree)
    out = []

    def walk(prefix, t):
        for part in split_top(t):
            k = part.find("{")
            if k < 0:
                full = prefix.rstrip(":") if part == "self" else prefix + part
                if full:
                    out.append(full)
            else:
                walk(prefix + part[:k], part[k + 1:-1])

    walk("", tree)
    return out


def split_top(t):
    parts, depth, cur = [], 0, ""
    for ch in t:
        if ch == "{":
            depth += 1
        elif ch == "}":
            depth -= 1
        if ch == "," and depth == 0:
            parts.append(cur)
            cur = ""
        else:
            cur += ch
    if cur:
        parts.append(cur)
    return parts


class Crate:
    def __init__(self, name, src, root_file):
        self.name, self.src = name, src
        self.files = {}  # module path (tuple) → file
        self.children = defaultdict(set)  # module path → child names
        self.uses = {}  # module path → {name: target path tuple} (its `use` imports)
        self.code = {}
        self.reexport_only = set()
        self._load((), root_file)

    def _load(self, path, file):
        if not file.exists():
            return
        self.files[path] = file
        text = strip(file.read_text())
        self.code[path] = text
        base = file.parent if file.name in ("mod.rs", "lib.rs", "main.rs") else file.with_suffix("")
        for m in re.finditer(r"(?:#\[path\s*=\s*\"\"\]\s*)?(?:pub(?:\([^)]*\))?\s+)?mod\s+(\w+)\s*;", text):
            name = m.group(1)
            cand = [base / f"{name}.rs", base / name / "mod.rs"]
            f = next((c for c in cand if c.exists()), None)
            if f:
                self.children[path].add(name)
                self._load(path + (name,), f)

    def module_of(self, path):
        """The longest prefix of `path` that is a module, and the rest."""
        for k in range(len(path), -1, -1):
            if path[:k] in self.files:
                return path[:k], path[k:]
        return (), path

    def absolute(self, here, segs):
        """Segments of a path written in module `here`, made absolute (None for an
        external crate)."""
        if not segs:
            return None
        first = segs[0]
        if first in ("crate", "$crate"):
            return tuple(segs[1:])
        if first == "self":
            return here + tuple(segs[1:])
        if first == "super":
            up, k = here, 0
            while k < len(segs) and segs[k] == "super":
                up, k = up[:-1], k + 1
            return up + tuple(segs[k:])
        # A child module of `here`, or a name imported into `here`.
        if first in self.children[here]:
            return here + tuple(segs)
        imported = self.imports(here).get(first)
        if imported is not None:
            return imported + tuple(segs[1:])
        return None

    def imports(self, mod):
        if mod not in self.uses:
            self.uses[mod] = {}
            for m in re.finditer(r"(?:pub(?:\([^)]*\))?\s+)?use\s+([^;]*);", self.code.get(mod, "")):
                for p in expand_use(m.group(1)):
                    segs = [s for s in p.split("::") if s]
                    if not segs or segs[-1] == "*":
                        continue
                    target = self.absolute_no_imports(mod, segs)
                    if target is not None:
                        self.uses[mod][segs[-1]] = target
        return self.uses[mod]

    def absolute_no_imports(self, here, segs):
        first = segs[0]
        if first in ("crate", "$crate", "self", "super"):
            return self.absolute(here, segs)
        if first in self.children[here]:
            return here + tuple(segs)
        return None

    def resolve(self, path, seen=None):
        """The file-defining module of an absolute item path, through re-exports."""
        seen = seen or set()
        mod, rest = self.module_of(path)
        if not rest or path in seen:
            return mod
        seen.add(path)
        nxt = self.imports(mod).get(rest[0])
        if nxt is not None:
            return self.resolve(nxt + rest[1:], seen)
        return mod

    def edges(self):
        """(from module, to module, what) for every import of another file."""
        out = set()
        for mod, code in self.code.items():
            front = self.files[mod].name in ("mod.rs", "lib.rs", "main.rs")
            paths = []
            for m in re.finditer(r"(pub(?:\([^)]*\))?\s+)?use\s+([^;]*);", code):
                if front and m.group(1):
                    continue  # a folder's list of what it offers
                paths += [p for p in expand_use(m.group(2))]
            body = re.sub(r"(?:pub(?:\([^)]*\))?\s+)?use\s+[^;]*;", "", code)
            paths += re.findall(r"(?<![\w:])((?:\$crate|crate|super|self)(?:::\w+)+)", body)
            for p in paths:
                segs = [s for s in p.split("::") if s and s != "*"]
                if not segs or segs[0] not in ("crate", "$crate", "super", "self"):
                    continue
                target = self.absolute(mod, segs)
                if target is None:
                    continue
                to = self.resolve(target)
                if to != mod and to in self.files and not is_ancestor(to, mod):
                    out.add((mod, to, "::".join(target)))
        return out


def is_ancestor(a, b):
    return len(a) < len(b) and b[: len(a)] == a


def sccs(nodes, adj):
    index, low, stack, on, out, counter = {}, {}, [], set(), [], [0]
    sys.setrecursionlimit(10000)

    def visit(v):
        index[v] = low[v] = counter[0]
        counter[0] += 1
        stack.append(v)
        on.add(v)
        for w in adj.get(v, ()):
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
            out.append(comp)

    for v in nodes:
        if v not in index:
            visit(v)
    return [c for c in out if len(c) > 1]


def floor_of(name, mod):
    spec = FLOORS.get(name)
    if not spec:
        return None
    best = None
    for f, groups in enumerate(spec):
        for g, prefixes in enumerate(groups):
            for p in prefixes:
                pt = tuple(p.split("::"))
                if mod[: len(pt)] == pt and (best is None or len(pt) > best[2]):
                    best = (f, g, len(pt))
    return best[:2] if best else None


def show(mod):
    return "::".join(mod) or "(root)"


def common_folder(mods):
    k = 0
    while all(len(m) > k for m in mods) and len({m[k] for m in mods}) == 1:
        k += 1
    return mods[0][:k]


def crates(root):
    found = []
    for toml in sorted(list(root.glob("crates/*/Cargo.toml")) + [root / "Cargo.toml"]):
        data = tomllib.loads(toml.read_text())
        pkg = data.get("package")
        if not pkg:
            continue
        d = toml.parent
        lib = d / "src/lib.rs"
        deps = set(data.get("dependencies", {}))
        found.append((pkg["name"], d, lib if lib.exists() else d / "src/main.rs", deps))
        if (d / "src/main.rs").exists() and lib.exists() and pkg["name"] != "truenorth-cli":
            pass
    return found


def main():
    args = [a for a in sys.argv[1:] if not a.startswith("--")]
    verbose = "--verbose" in sys.argv
    root = Path(args[0] if args else Path(__file__).resolve().parent.parent)
    total_cycles = total_up = 0
    crate_floor = {c: f for f, cs in enumerate(CRATE_FLOORS) for c in cs}
    lines = []
    for name, d, rootfile, deps in crates(root):
        crate = Crate(name, d / "src", rootfile)
        edges = crate.edges()
        adj = defaultdict(set)
        for a, b, _ in edges:
            adj[a].add(b)
        cycles = sccs(sorted(crate.files), adj)
        up = []
        for a, b, what in sorted(edges):
            fa, fb = floor_of(name, a), floor_of(name, b)
            if fa is None or fb is None or fa == fb:
                continue
            if fb[0] >= fa[0]:
                up.append((a, b, what))
        crate_up = sorted(x for x in deps & set(crate_floor) if name in crate_floor and
                          crate_floor[x] >= crate_floor[name] and x != name)
        n_files = sum(len(c) for c in cycles)
        total_cycles += len(cycles)
        total_up += len(up) + len(crate_up)
        lines.append(f"{name}: {len(cycles)} import cycles ({n_files} files), "
                     f"{len(up)} arrows not pointing down between its folders, "
                     f"{len(crate_up)} dependencies on crates not below it"
                     f" ({len(crate.files)} files)")
        per_folder = defaultdict(lambda: [0, 0])
        for c in cycles:
            per_folder[common_folder(c)][0] += 1
        for a, b, _ in up:
            per_folder[common_folder([a, b])][1] += 1
        for folder, (nc, nu) in sorted(per_folder.items()):
            lines.append(f"  {name}/{show(folder)}: {nc} cycles, {nu} arrows not pointing down")
        if verbose:
            for c in cycles:
                lines.append("    cycle: " + ", ".join(sorted(show(m) for m in c)))
            for a, b, what in up:
                lines.append(f"    up: {show(a)} -> {show(b)} ({what})")
            for x in crate_up:
                lines.append(f"    crate up: {name} -> {x}")
    print("\n".join(lines))
    print(f"total: {total_cycles} import cycles, {total_up} arrows not pointing down")
    return 1 if total_cycles or total_up else 0


if __name__ == "__main__":
    sys.exit(main())
