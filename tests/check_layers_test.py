#!/usr/bin/env python3
"""Self-test of scripts/check_layers.py: small fake trees, one per failure kind, plus a clean tree that passes."""
import os
import subprocess
import sys
import tempfile

SCRIPT = os.path.join(os.path.dirname(os.path.dirname(os.path.abspath(__file__))), "scripts", "check_layers.py")

TABLE_HEADER = "| module | what it holds | depends on |\n|---|---|---|\n"


def make_tree(root, modules, order=None, table=None, extra_files=None):
    """modules: {name: (deps, {file: text})}. table: {name: 'depends on' cell}; defaults to the deps."""
    src = os.path.join(root, "src", "lidarshop")
    for name, (deps, files) in modules.items():
        os.makedirs(os.path.join(src, name))
        with open(os.path.join(src, name, "CMakeLists.txt"), "w") as out:
            out.write(f"lidarshop_add_module(NAME {name} DEPS {' '.join(deps)} LIBS fmt::fmt)\n")
        for file_name, text in files.items():
            with open(os.path.join(src, name, file_name), "w") as out:
                out.write(text)
    for path, text in (extra_files or {}).items():
        os.makedirs(os.path.dirname(os.path.join(root, path)), exist_ok=True)
        with open(os.path.join(root, path), "w") as out:
            out.write(text)
    with open(os.path.join(src, "CMakeLists.txt"), "w") as out:
        for name in order or modules:
            out.write(f"add_subdirectory({name})\n")
    if table is None:
        table = {name: ", ".join(deps + ["fmt"]) for name, (deps, _) in modules.items()}
    with open(os.path.join(root, "ARCHITECTURE.md"), "w") as out:
        out.write("# Architecture\n\n" + TABLE_HEADER)
        for name, cell in table.items():
            out.write(f"| `{name}` | things | {cell} |\n")


def run(modules, **kwargs):
    with tempfile.TemporaryDirectory() as root:
        make_tree(root, modules, **kwargs)
        result = subprocess.run([sys.executable, SCRIPT, "--root", root], capture_output=True, text=True)
        return result.returncode, result.stdout


def clean():
    return {
        "util": ([], {"log.h": "#pragma once\n", "log.cc": '#include "lidarshop/util/log.h"\n'}),
        "scan": (["util"], {"scan.h": '#pragma once\n#include "lidarshop/util/log.h"\n'}),
        "fill": (["util", "scan"], {"fill.cc": '#include "lidarshop/scan/scan.h"\n#include "lidarshop/util/log.h"\n',
                                    "fill_test.cc": '#include "lidarshop/testing/scenes.h"\n'}),
    }


failures = []


def expect(title, code, output, want_code, want_text):
    if code != want_code or want_text not in output:
        failures.append(f"{title}: exit {code} (want {want_code}), output lacks {want_text!r}:\n{output}")
    else:
        print(f"ok: {title}")


# A clean tree passes (the include of `testing` in a *_test.cc is allowed, the eval/ subfolder is not checked).
code, output = run(clean(), extra_files={"src/lidarshop/fill/eval/main.cc": '#include "lidarshop/io/io.h"\n'})
expect("clean tree passes", code, output, 0, "agree")

# An include of a module that is not a declared dependency, reported with file:line.
modules = clean()
modules["util"][1]["log.h"] = '#pragma once\n\n#include "lidarshop/scan/scan.h"\n'
code, output = run(modules)
expect("undeclared include", code, output, 1, "src/lidarshop/util/log.h:3: util includes lidarshop/scan/")

# A declared dependency never included (unused link).
modules = clean()
modules["fill"][1]["fill.cc"] = '#include "lidarshop/scan/scan.h"\n'
code, output = run(modules)
expect("unused declared dep", code, output, 1, "fill declares DEPS util but no library source")

# CMake DEPS and the ARCHITECTURE.md table disagree.
table = {"util": "fmt", "scan": "util", "fill": "`scan` only"}
code, output = run(clean(), table=table)
expect("table disagrees", code, output, 1, "ARCHITECTURE.md:7: table says fill depends on ['scan']")

# A module missing from the table.
code, output = run(clean(), table={"util": "fmt", "scan": "util"})
expect("module missing from table", code, output, 1, "module fill is missing from the module table")

# A cycle (declared and included both ways).
modules = clean()
modules["util"] = (["fill"], {"log.h": '#pragma once\n#include "lidarshop/fill/fill.h"\n'})
code, output = run(modules)
expect("cycle", code, output, 1, "dependency cycle: fill -> scan -> util -> fill")

# add_subdirectory order puts a module before one of its deps.
code, output = run(clean(), order=["util", "fill", "scan"])
expect("order", code, output, 1, "add_subdirectory(fill) comes before its dependency scan")

if failures:
    print("\n".join(failures))
    sys.exit(1)
print("check_layers_test: all cases pass")
