#!/usr/bin/env python3
"""Self-test of scripts/check_layers.py: small fake trees, one per failure kind, plus a clean tree that passes;
then a copy of the repository's own tree, which passes, and the same copy with a wrong include in src/server/,
which fails (and one that cannot run, which fails too)."""
import os
import shutil
import subprocess
import sys
import tempfile

REPO = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
SCRIPT = os.path.join(REPO, "scripts", "check_layers.py")

TABLE_HEADER = "| module | what it holds | depends on |\n|---|---|---|\n"
FACES = {
    "cli": ("src/lidarshop/cli", "the library; `server` (the serve command)"),
    "server": ("src/server", "the library"),
    "python": ("src/python", "the library"),
}
FACE_FILES = {
    "src/lidarshop/cli/main.cc": '#include "lidarshop/fill/fill.h"\n#include "server.h"\n',
    "src/server/server.h": '#pragma once\n#include "lidarshop/scan/scan.h"\n',
    "src/server/server.cc": '#include "server.h"\n#include "lidarshop/util/log.h"\n',
    "src/server/server_test.cc": '#include "server.h"\n#include "lidarshop/testing/scenes.h"\n',
    "src/python/module.cc": '#include "bindings.h"\n#include "lidarshop/scan/scan.h"\n',
    "src/python/bindings.h": "#pragma once\n",
}


def make_tree(root, modules, order=None, table=None, extra_files=None, faces=None, exceptions=None):
    """modules: {name: (deps, {file: text})}. table: {name: 'depends on' cell}; defaults to the deps.
    faces: {name: (folder, 'may include' cell)} with FACE_FILES; exceptions: [(path, includes cell)]."""
    src = os.path.join(root, "src", "lidarshop")
    for name, (deps, files) in modules.items():
        os.makedirs(os.path.join(src, name))
        with open(os.path.join(src, name, "CMakeLists.txt"), "w") as out:
            out.write(f"lidarshop_add_module(NAME {name} DEPS {' '.join(deps)} LIBS fmt::fmt)\n")
        for file_name, text in files.items():
            with open(os.path.join(src, name, file_name), "w") as out:
                out.write(text)
    faces = FACES if faces is None else faces
    files = dict(FACE_FILES) if faces is FACES else {}
    files.update(extra_files or {})
    for path, text in files.items():
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
        out.write("\nFaces:\n\n| face | folders | may include |\n|---|---|---|\n")
        for name, (folder, cell) in faces.items():
            out.write(f"| `{name}` | `{folder}` | {cell} |\n")
        if exceptions:
            out.write("\n| known exception | includes | why |\n|---|---|---|\n")
            for path, cell in exceptions:
                out.write(f"| `{path}` | {cell} | a reason |\n")


def run_script(root):
    result = subprocess.run([sys.executable, SCRIPT, "--root", root], capture_output=True, text=True)
    return result.returncode, result.stdout + result.stderr


def run(modules, **kwargs):
    with tempfile.TemporaryDirectory() as root:
        make_tree(root, modules, **kwargs)
        return run_script(root)


def clean():
    return {
        "util": ([], {"log.h": "#pragma once\n", "log.cc": '#include "lidarshop/util/log.h"\n'}),
        "scan": (["util"], {"scan.h": '#pragma once\n#include "lidarshop/util/log.h"\n'}),
        "testing": (["scan"], {"scenes.h": '#pragma once\n#include "lidarshop/scan/scan.h"\n'}),
        "fill": (["util", "scan"], {"fill.h": "#pragma once\n",
                                    "fill.cc": '#include "lidarshop/scan/scan.h"\n#include "lidarshop/util/log.h"\n',
                                    "fill_test.cc": '#include "lidarshop/testing/scenes.h"\n'}),
    }


failures = []


def expect(title, code, output, want_code, want_text):
    if code != want_code or want_text not in output:
        failures.append(f"{title}: exit {code} (want {want_code}), output lacks {want_text!r}:\n{output}")
    else:
        print(f"ok: {title}")


# A clean tree passes: a module test includes `testing`; the eval/ program includes its module and what that
# depends on (util through scan); cli includes the server (its row allows it); the server's test uses testing.
code, output = run(clean(), extra_files={"src/lidarshop/fill/eval/main.cc":
                                         '#include "lidarshop/fill/fill.h"\n#include "lidarshop/util/log.h"\n'})
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
table = {"util": "fmt", "scan": "util", "testing": "scan", "fill": "`scan` only"}
code, output = run(clean(), table=table)
expect("table disagrees", code, output, 1, "ARCHITECTURE.md:8: table says fill depends on ['scan']")

# A module missing from the table.
code, output = run(clean(), table={"util": "fmt", "scan": "util", "testing": "scan"})
expect("module missing from table", code, output, 1, "module fill is missing from the module table")

# A cycle (declared and included both ways).
modules = clean()
modules["util"] = (["fill"], {"log.h": '#pragma once\n#include "lidarshop/fill/fill.h"\n'})
code, output = run(modules)
expect("cycle", code, output, 1, "dependency cycle: fill -> scan -> util -> fill")

# add_subdirectory order puts a module before one of its deps.
code, output = run(clean(), order=["util", "fill", "scan", "testing"])
expect("order", code, output, 1, "add_subdirectory(fill) comes before its dependency scan")

# A face includes another face its row does not name: the server includes the CLI.
code, output = run(clean(), extra_files={"src/lidarshop/cli/commands.h": "#pragma once\n",
                                         "src/server/routes.cc": '#include "server.h"\n\n'
                                                                 '#include "lidarshop/cli/commands.h"\n'})
expect("server includes cli", code, output, 1,
       'src/server/routes.cc:3: face server includes "lidarshop/cli/commands.h" of face cli')

# A shipped face includes the test fixtures outside a test.
code, output = run(clean(), extra_files={"src/python/scenes.cc": '#include "lidarshop/testing/scenes.h"\n'})
expect("face includes testing", code, output, 1, 'src/python/scenes.cc:1: face python includes')

# The library includes a face, by a bare name the compiler would find in the face's folder.
modules = clean()
modules["fill"][1]["fill.h"] = '#pragma once\n#include "server.h"\n'
code, output = run(modules)
expect("library includes a face", code, output, 1, "the library never includes a face")

# A module's test includes a face.
modules = clean()
modules["fill"][1]["fill_test.cc"] = '#include "lidarshop/testing/scenes.h"\n#include "bindings.h"\n'
code, output = run(modules, extra_files={"src/lidarshop/fill/bindings.h": "#pragma once\n"})
expect("own folder first", code, output, 0, "agree")  # "bindings.h" beside the test is fill's own file
modules["fill"][1]["fill_test.cc"] = '#include "lidarshop/cli/main.cc"\n'
code, output = run(modules)
expect("module test includes a face", code, output, 1, "test of module fill includes")

# A program in a module's subfolder includes a module its module does not depend on; a known exception row
# excuses it; a row that nothing needs is stale.
eval_files = {"src/lidarshop/scan/eval/main.cc": '#include "lidarshop/fill/fill.h"\n'}
code, output = run(clean(), extra_files=eval_files)
expect("eval program depends upwards", code, output, 1,
       'src/lidarshop/scan/eval/main.cc:1: a program of module scan includes "lidarshop/fill/fill.h" of module fill')
code, output = run(clean(), extra_files=eval_files, exceptions=[("src/lidarshop/scan/eval", "`fill`")])
expect("known exception excuses it", code, output, 0, "agree")
code, output = run(clean(), exceptions=[("src/lidarshop/scan/eval", "`fill`")])
expect("stale known exception", code, output, 1, "known exception `src/lidarshop/scan/eval` including `fill` no "
                                                 "longer happens")

# C++ in a folder that is neither a module nor a face; a face row naming a folder that does not exist.
code, output = run(clean(), extra_files={"tools/convert.cc": '#include "lidarshop/scan/scan.h"\n'})
expect("folder in no layer", code, output, 1, "tools: holds C++ files (convert.cc) but is in no layer")
faces = dict(FACES, eval=("eval", "the library, `testing`"))
code, output = run(clean(), faces=faces, extra_files=FACE_FILES)
expect("face folder missing", code, output, 1, "face eval lists eval, which is not a folder")

# A check that cannot run fails (exit 2): no tree, no module.
code, output = run_script(os.path.join(tempfile.gettempdir(), "no-such-lidarshop-tree"))
expect("cannot run: no tree", code, output, 2, "FAILED, the check cannot run: no src/lidarshop")
with tempfile.TemporaryDirectory() as root:
    os.makedirs(os.path.join(root, "src", "lidarshop", "util"))
    code, output = run_script(root)
expect("cannot run: no module", code, output, 2, "no lidarshop_add_module()")

# The repository's own tree (a copy): passes; with one wrong include in src/server/, fails naming it.
with tempfile.TemporaryDirectory() as root:
    ignore = shutil.ignore_patterns("build*", ".git", "node_modules", "*.png", "*.e57", "*.ply", "*.ptx")
    for folder in ("src", "bench", "fuzz", "tests", "eval"):
        if os.path.isdir(os.path.join(REPO, folder)):
            shutil.copytree(os.path.join(REPO, folder), os.path.join(root, folder), ignore=ignore)
    shutil.copy(os.path.join(REPO, "ARCHITECTURE.md"), root)
    code, output = run_script(root)
    expect("the repository's tree passes", code, output, 0, "agree")
    server = os.path.join(root, "src", "server", "server.cc")
    with open(server) as f:
        lines = f.read().splitlines(keepends=True)
    lines.insert(1, '#include "lidarshop/cli/commands.h"\n')
    with open(server, "w") as f:
        f.writelines(lines)
    code, output = run_script(root)
    expect("a wrong include in src/server fails", code, output, 1,
           'src/server/server.cc:2: face server includes "lidarshop/cli/commands.h" of face cli')

if failures:
    print("\n".join(failures))
    sys.exit(1)
print("check_layers_test: all cases pass")
