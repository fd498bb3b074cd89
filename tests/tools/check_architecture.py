#!/usr/bin/env python3
"""Checks docs/design/architecture.md's "may use" column against the code: every #include of another
room's header, and every CMake link line between runout's libraries, must name a room the table lets
that room use; and every target that uses a header whose functions another target builds must link
that target itself (link completeness). Prints each violation (file:line, room, used room) and exits 1 when there is one.
Run from the repository root: python3 tests/tools/check_architecture.py"""
import re
import sys
from pathlib import Path

ROOT = Path(sys.argv[1]) if len(sys.argv) > 1 else Path(".")
# The short names the "may use" column uses for rooms.
SHORT = {"proto": "service/proto", "engine": "engine", "engine/vof": "engine/vof", "terrain": "terrain", "digest": "jobs/digest",
         "scenario": "jobs/scenario", "formats": "jobs/formats", "figures": "jobs/figures", "products": "jobs/products",
         "ensemble": "jobs/ensemble", "drivers": "jobs/drivers", "system": "jobs/system", "regression": "jobs/regression"}


def table():
    """room path -> set of room paths it may use ("*": everything)."""
    rooms = {}
    for line in (ROOT / "docs/design/architecture.md").read_text().splitlines():
        cells = [c.strip() for c in line.split("|")]
        if len(cells) < 6 or not cells[1].startswith("`"):
            continue
        room = cells[1].strip("`").rstrip("/")
        if not (ROOT / room).exists():
            continue
        may = cells[4]
        if "everything" in may:
            rooms[room] = {"*"}
            continue
        used = set()
        for name in re.findall(r"`([a-z/_.]+)`", may.split("**Never**")[0]):
            if name in SHORT:
                used.add(SHORT[name])
            elif (ROOT / name).is_file() and name in [c.strip("`") for c in cells[1:2]] + list_rooms_named(name):
                used.add(name)
        rooms[room] = used
    return rooms


def list_rooms_named(name):
    """A room that is one header (e.g. jobs/scenario/inputs.hpp) is named by its path."""
    return [name] if name.endswith((".hpp", ".h")) else []


def room_of(path, rooms):
    best = None
    for r in rooms:
        if path == r or path.startswith(r + "/"):
            if best is None or len(r) > len(best):
                best = r
    return best


def allowed(room, target, rooms):
    if target == room or "*" in rooms[room]:
        return True
    # A room inside another (engine/vof in engine) is its own room; a room may use its own inner ones
    # only where the table says so.
    # A room that is one header inside a room it may use (jobs/scenario/inputs.hpp in jobs/scenario).
    return target in rooms[room] or any(target.startswith(u + "/") for u in rooms[room])


def main():
    rooms = table()
    bad = []
    for room in rooms:
        if not (ROOT / room).is_dir():
            continue
        for f in sorted((ROOT / room).rglob("*")):
            if f.suffix not in (".cpp", ".hpp", ".h") or room_of(str(f.relative_to(ROOT)), rooms) != room:
                continue
            for n, line in enumerate(f.read_text(errors="replace").splitlines(), 1):
                m = re.match(r'\s*#include\s+"([^"]+)"', line)
                if not m:
                    continue
                inc = m.group(1)
                if inc.startswith("runout/v1/"):
                    target = "service/proto"
                else:
                    target = room_of(inc, rooms)
                if target and not allowed(room, target, rooms):
                    bad.append(f"{f.relative_to(ROOT)}:{n}: {room} includes {inc} ({target}), not in its 'may use'")
    libs = {}  # CMake library -> room
    for cm in ROOT.rglob("CMakeLists.txt"):
        rel = str(cm.parent.relative_to(ROOT))
        if rel.startswith(("build", "tests", "bench")):
            continue
        for m in re.finditer(r"add_library\((runout_\w+)", cm.read_text()):
            libs[m.group(1)] = room_of(rel, rooms) or rel
    for cm in ROOT.rglob("CMakeLists.txt"):
        rel = str(cm.parent.relative_to(ROOT))
        if rel.startswith(("build", "tests", "bench")):
            continue
        text = cm.read_text()
        for m in re.finditer(r"target_link_libraries\((runout_\w+)([^)]*)\)", text):
            lib, deps = m.group(1), m.group(2)
            room = libs.get(lib)
            if room not in rooms:
                continue
            for dep in re.findall(r"runout_\w+", deps):
                target = libs.get(dep)
                if target in rooms and not allowed(room, target, rooms):
                    bad.append(f"{cm.relative_to(ROOT)}: {lib} ({room}) links {dep} ({target}), not in its 'may use'")
    bad += link_completeness()
    for b in bad:
        print(b)
    print(f"architecture: {len(rooms)} rooms, {len(bad)} use(s) outside the table")
    return 1 if bad else 0


def cmake_targets():
    """runout's production targets (libraries and programs outside tests/ and bench/): name ->
    (its source files, relative to the root; the runout_* targets it links)."""
    targets = {}
    for cm in ROOT.rglob("CMakeLists.txt"):
        rel = cm.parent.relative_to(ROOT)
        if str(rel).startswith(("build", "tests", "bench")):
            continue
        text = re.sub(r"#[^\n]*", "", cm.read_text())
        for m in re.finditer(r"add_(?:library|executable)\((runout\w*)\s([^)]*)\)", text):
            srcs = [str(rel / f) if str(rel) != "." else f for f in m.group(2).split() if f.endswith(".cpp")]
            targets[m.group(1)] = (srcs, set())
        for m in re.finditer(r"target_link_libraries\((runout\w*)([^)]*)\)", text):
            if m.group(1) in targets:
                targets[m.group(1)][1].update(re.findall(r"\brunout_\w+", m.group(2)))
    return targets


def link_completeness():
    """Every target that includes a header whose functions another target compiles (foo.hpp where
    that target builds foo.cpp) names that target on its own link line. Without it the program
    links only because some other library happens to bring it, and the table above says nothing
    true about the link lines."""
    targets = cmake_targets()
    owner = {src: name for name, (srcs, _) in targets.items() for src in srcs}
    bad = []
    for name, (srcs, links) in sorted(targets.items()):
        files = set(srcs) | {s[:-4] + ".hpp" for s in srcs if (ROOT / (s[:-4] + ".hpp")).is_file()}
        for f in sorted(files):
            for n, line in enumerate((ROOT / f).read_text(errors="replace").splitlines(), 1):
                m = re.match(r'\s*#include\s+"([^"]+)\.hpp"', line)
                if not m:
                    continue
                dep = owner.get(m.group(1) + ".cpp")
                if dep and dep != name and dep not in links:
                    bad.append(f"{f}:{n}: {name} uses {m.group(1)}.hpp, built by {dep}, which it does not link")
    return bad


if __name__ == "__main__":
    sys.exit(main())
