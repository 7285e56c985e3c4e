#!/usr/bin/env python3
"""A field described once (a module's options_info.cc) is in all four faces: the CLI's help, the command's
--json, the Python class and the editor's TypeScript types (web/src/api_types.generated.ts).

The fields are read from the description itself (`lidarshop schema --json`), never listed here, so a field
added to AlignOptions or FillOptions (or any struct nested in FillOptions) is checked by this test the moment
it is described; forgetting the generated TypeScript fails here and in api_types_test. Environment:
LIDARSHOP_CLI (the executable), PYTHONPATH with the built module (src/python/CMakeLists.txt)."""
import json
import os
import re
import subprocess
import sys
import tempfile

ROOT = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
sys.path.insert(0, os.path.join(ROOT, "tests"))
import png_grey  # noqa: E402

CLI = os.environ["LIDARSHOP_CLI"]
import lidarshop  # noqa: E402  (PYTHONPATH)

passed = failed = 0


def check(what, ok, detail=""):
    global passed, failed
    if ok:
        passed += 1
    else:
        failed += 1
        print(f"FAILED: {what} {detail}")


def run(*args):
    return subprocess.run([CLI, *args], check=True, capture_output=True, text=True).stdout


descriptions = {}


def collect(struct):
    descriptions.setdefault(struct["name"], struct)
    for field in struct["fields"]:
        if "struct" in field:
            collect(field["struct"])


for struct in json.loads(run("schema", "--json", "-"))["structs"]:
    collect(struct)

# TypeScript: each interface's members, in order.
with open(os.path.join(ROOT, "web", "src", "api_types.generated.ts")) as file:
    typescript = file.read()
interfaces = {
    name: re.findall(r"^  (\w+):", body, re.M)
    for name, body in re.findall(r"^export interface (\w+) \{\n(.*?)^\}", typescript, re.M | re.S)
}


def keys_of(value, name):
    """The key tree of a JSON object whose description is `name`, as (path, keys) pairs."""
    out = [(name, list(value.keys()))]
    for field in descriptions[name]["fields"]:
        if "struct" in field:
            out += keys_of(value[field["key"]], field["struct"]["name"])
    return out


def described_tree(name):
    out = [(name, [field["key"] for field in descriptions[name]["fields"]])]
    for field in descriptions[name]["fields"]:
        if "struct" in field:
            out += described_tree(field["struct"]["name"])
    return out


def check_struct(name, command, help_text, options_json):
    tree = described_tree(name)
    check(f"{name} is described", len(tree[0][1]) > 0)
    # 1. The command's --json "options": every key of the struct and of its nested structs, in order.
    check(f"{command} --json options = {name}'s keys", keys_of(options_json, name) == tree,
          f"{keys_of(options_json, name)} != {tree}")
    # 2. Python: the class's fields and its to_dict(), nested too.
    cls = getattr(lidarshop, name)
    check(f"Python {name}.fields", list(cls.fields) == tree[0][1], f"{list(cls.fields)}")
    check(f"Python {name}().to_dict()", keys_of(cls().to_dict(), name) == tree)
    # 3. TypeScript: an interface per struct with its members in order.
    for struct_name, keys in tree:
        check(f"TypeScript interface {struct_name}", interfaces.get(struct_name) == keys,
              f"{interfaces.get(struct_name)} != {keys}")
    # 4. CLI help: every top-level field that is not a struct has its doc line there (under its flag).
    for field in descriptions[name]["fields"]:
        if "struct" not in field:
            check(f"{command} --help shows {field['key']}", field["doc"] in help_text, field["doc"])


with tempfile.TemporaryDirectory() as work:
    # AlignOptions: lidarshop align on four landmarks.
    landmarks = os.path.join(work, "landmarks.json")
    with open(landmarks, "w") as file:
        json.dump({"pairs": [{"source": [0, 0, 0], "target": [1, 2, 3]}, {"source": [1, 0, 0], "target": [2, 2, 3]},
                             {"source": [0, 1, 0], "target": [1, 3, 3]}, {"source": [0, 0, 1], "target": [1, 2, 4]}]},
                  file)
    align = json.loads(run("align", "--correspondences", landmarks, "-o", os.path.join(work, "T.txt"), "-q"))
    check_struct("AlignOptions", "align", run("align", "--help"), align["options"])
    # FillOptions (and its nested structs): lidarshop fill of a small hole in a synthetic scan.
    scan = os.path.join(work, "scan.ptx")
    run("scan", "mailbox", "--rows", "40", "--columns", "60", "-o", scan, "-q")
    mask = os.path.join(work, "hole.png")
    png_grey.write(mask, [[255 if 15 <= r < 20 and 25 <= c < 30 else 0 for c in range(60)] for r in range(40)])
    fill = json.loads(run("fill", scan, "--mask", mask, "--method", "laplace", "-o", os.path.join(work, "f.ptx"),
                          "--json", "-", "-q"))
    check_struct("FillOptions", "fill", run("fill", "--help"), fill["options"])

print(f"{passed} passed, {failed} failed")
sys.exit(1 if failed else 0)
