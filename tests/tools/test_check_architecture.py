#!/usr/bin/env python3
"""The architecture checker (check_architecture.py) on a miniature repository: a clean tree passes;
an include the table does not allow, a link line it does not allow, and a header used without
linking the library that builds it each fail with a line naming the file."""
import subprocess
import sys
import tempfile
from pathlib import Path

CHECKER = Path(__file__).with_name("check_architecture.py")
TABLE = """| room | library | owns | may use |
|---|---|---|---|
| `terrain/` | `runout_terrain` | terrain | GDAL |
| `jobs/digest/` | `runout_digest` | digests | OpenSSL |
| `jobs/scenario/` | `runout_scenario` | scenarios | `terrain`, `digest` |
"""


def tree(root, scenario_links="runout_terrain runout_digest", scenario_include="terrain/dem.hpp",
         digest_include=None, terrain_links=""):
    files = {
        "docs/design/architecture.md": TABLE,
        "terrain/CMakeLists.txt": "add_library(runout_terrain dem.cpp)\n"
        + (f"target_link_libraries(runout_terrain PRIVATE {terrain_links})\n" if terrain_links else ""),
        "terrain/dem.hpp": "int dem();\n",
        "terrain/dem.cpp": '#include "terrain/dem.hpp"\nint dem() { return 1; }\n',
        "jobs/digest/CMakeLists.txt": "add_library(runout_digest sha.cpp)\n",
        "jobs/digest/sha.hpp": "int sha();\n",
        "jobs/digest/sha.cpp": '#include "jobs/digest/sha.hpp"\n' + (f'#include "{digest_include}"\n' if digest_include else "")
        + "int sha() { return 2; }\n",
        "jobs/scenario/CMakeLists.txt": f"add_library(runout_scenario scenario.cpp)\n"
        f"target_link_libraries(runout_scenario PUBLIC {scenario_links})\n",
        "jobs/scenario/scenario.cpp": f'#include "{scenario_include}"\n#include "jobs/digest/sha.hpp"\n'
        "int scenario() { return 3; }\n",
    }
    for name, text in files.items():
        (root / name).parent.mkdir(parents=True, exist_ok=True)
        (root / name).write_text(text)


def check(**kw):
    with tempfile.TemporaryDirectory() as d:
        tree(Path(d), **kw)
        r = subprocess.run([sys.executable, str(CHECKER), d], capture_output=True, text=True)
        return r.returncode, r.stdout


def expect(case, result, code, needle):
    rc, out = result
    ok = rc == code and needle in out
    print(("ok   " if ok else "FAIL ") + case + ("" if ok else f": exit {rc}, output:\n{out}"))
    return ok


def main():
    results = [
        expect("clean tree", check(), 0, "0 use(s) outside the table"),
        expect("include outside the table", check(digest_include="jobs/scenario/scenario.hpp"), 1,
               "jobs/digest/sha.cpp:2: jobs/digest includes jobs/scenario/scenario.hpp"),
        expect("link outside the table", check(terrain_links="runout_digest"), 1,
               "terrain/CMakeLists.txt: runout_terrain (terrain) links runout_digest (jobs/digest), not in its 'may use'"),
        expect("header of a library not linked", check(scenario_links="runout_terrain"), 1,
               "jobs/scenario/scenario.cpp:2: runout_scenario uses jobs/digest/sha.hpp, built by runout_digest, "
               "which it does not link"),
    ]
    return 0 if all(results) else 1


if __name__ == "__main__":
    sys.exit(main())
