#!/usr/bin/env python3
"""Checks that the module layering of src/lidarshop is what ARCHITECTURE.md and CMake say.

For each module folder src/lidarshop/<m>/ with a `lidarshop_add_module(NAME m DEPS ...)` line it compares
  - the includes of its library sources (*.h, *.cc directly in the folder, not *_test.cc: tests may also use the
    `testing` fixtures; programs in subfolders such as fill/eval/ are consumers linked by hand and not checked),
  - the DEPS of its CMakeLists.txt,
  - the "depends on" column of the module table in ARCHITECTURE.md (names of module folders, in backticks or
    plain; other words such as external libraries are ignored),
and the order of add_subdirectory() in src/lidarshop/CMakeLists.txt. Folders without lidarshop_add_module
(`cli`, an executable that uses everything) are not modules here.

Prints one line per problem (file:line: message) and exits 1 if there is any; 0 and one summary line otherwise.
Usage: python3 scripts/check_layers.py [--root DIR]
"""
import argparse
import os
import re
import sys

INCLUDE_RE = re.compile(r'^\s*#\s*include\s*"lidarshop/([A-Za-z0-9_]+)/')
ADD_MODULE_RE = re.compile(r"lidarshop_add_module\s*\(([^)]*)\)", re.S)
KEYWORDS = {"NAME", "DEPS", "LIBS", "TEST_DEPS", "TEST_LIBS"}


def line_of(text, offset):
    return text.count("\n", 0, offset) + 1


def parse_cmake_module(path):
    """Returns (name, deps, line) of the lidarshop_add_module call in path, or None."""
    text = open(path, encoding="utf-8").read()
    match = ADD_MODULE_RE.search(text)
    if not match:
        return None
    words = re.sub(r"#[^\n]*", "", match.group(1)).split()
    name, deps, section = None, [], None
    for word in words:
        if word in KEYWORDS:
            section = word
        elif section == "NAME":
            name = word
        elif section == "DEPS":
            deps.append(word)
    return name, deps, line_of(text, match.start())


def parse_table(path, modules):
    """Returns {module: (deps set, line)} from the markdown table whose header has 'module' and 'depends on'."""
    rows = {}
    in_table = False
    dep_column = None
    for number, line in enumerate(open(path, encoding="utf-8"), start=1):
        stripped = line.strip()
        if not stripped.startswith("|"):
            in_table = False
            continue
        cells = [cell.strip() for cell in stripped.strip("|").split("|")]
        lowered = [cell.lower() for cell in cells]
        if "module" in lowered and "depends on" in lowered:
            in_table, dep_column = True, lowered.index("depends on")
            continue
        if not in_table or set(stripped) <= set("|-: "):
            continue
        name = cells[0].strip("` ")
        words = re.findall(r"[A-Za-z0-9_]+", re.sub(r"\([^)]*\)", "", cells[dep_column]))
        rows[name] = ({word for word in words if word in modules}, number)
    return rows


def find_cycle(graph):
    """Returns one cycle as a list of modules (first == last), or None."""
    state = {}

    def visit(node, stack):
        state[node] = "open"
        stack.append(node)
        for dep in sorted(graph.get(node, ())):
            if state.get(dep) == "open":
                return stack[stack.index(dep):] + [dep]
            if dep not in state:
                cycle = visit(dep, stack)
                if cycle:
                    return cycle
        stack.pop()
        state[node] = "done"
        return None

    for node in sorted(graph):
        if node not in state:
            cycle = visit(node, [])
            if cycle:
                return cycle
    return None


def check(root):
    problems = []
    src = os.path.join(root, "src", "lidarshop")

    def rel(path):
        return os.path.relpath(path, root)

    modules = {}  # name -> (declared deps, cmake path, line)
    for folder in sorted(os.listdir(src)):
        cmake = os.path.join(src, folder, "CMakeLists.txt")
        if not os.path.isfile(cmake):
            continue
        parsed = parse_cmake_module(cmake)
        if parsed is None:
            continue
        name, deps, line = parsed
        if name != folder:
            problems.append(f"{rel(cmake)}:{line}: module NAME {name} differs from its folder {folder}")
        modules[folder] = (deps, cmake, line)

    for name, (deps, cmake, line) in modules.items():
        for dep in deps:
            if dep not in modules:
                problems.append(f"{rel(cmake)}:{line}: {name} declares DEPS {dep}, which is not a module")
            if dep == name:
                problems.append(f"{rel(cmake)}:{line}: {name} declares itself as a dependency")

    # Includes of library sources against declared deps; declared deps never included are unused links.
    for name, (deps, cmake, line) in modules.items():
        folder = os.path.join(src, name)
        included = set()
        for file_name in sorted(os.listdir(folder)):
            if not file_name.endswith((".h", ".cc")) or file_name.endswith("_test.cc"):
                continue
            path = os.path.join(folder, file_name)
            for number, text in enumerate(open(path, encoding="utf-8", errors="replace"), start=1):
                match = INCLUDE_RE.match(text)
                if not match or match.group(1) == name:
                    continue
                target = match.group(1)
                included.add(target)
                if target not in deps:
                    problems.append(f"{rel(path)}:{number}: {name} includes lidarshop/{target}/, "
                                    f"which is not a declared dependency (DEPS in {rel(cmake)})")
        for dep in deps:
            if dep not in included and dep in modules:
                problems.append(f"{rel(cmake)}:{line}: {name} declares DEPS {dep} but no library source of "
                                f"{name} includes lidarshop/{dep}/ (unused link)")

    # ARCHITECTURE.md table against CMake.
    architecture = os.path.join(root, "ARCHITECTURE.md")
    table = parse_table(architecture, set(modules)) if os.path.isfile(architecture) else {}
    if not table:
        problems.append(f"{rel(architecture)}:1: no module table with a 'depends on' column")
    else:
        for name, (deps, cmake, line) in modules.items():
            if name not in table:
                problems.append(f"{rel(architecture)}:1: module {name} is missing from the module table")
                continue
            table_deps, table_line = table[name]
            if table_deps != set(deps):
                problems.append(f"{rel(architecture)}:{table_line}: table says {name} depends on "
                                f"{sorted(table_deps)} but {rel(cmake)}:{line} DEPS are {sorted(deps)}")
        for name, (_, table_line) in table.items():
            if name not in modules and not os.path.isdir(os.path.join(src, name)):
                problems.append(f"{rel(architecture)}:{table_line}: table lists {name}, which is not a folder "
                                f"of src/lidarshop")

    cycle = find_cycle({name: [d for d in deps if d in modules] for name, (deps, _, _) in modules.items()})
    if cycle:
        problems.append(f"{rel(modules[cycle[0]][1])}:{modules[cycle[0]][2]}: dependency cycle: "
                        + " -> ".join(cycle))

    # add_subdirectory order: every module after its deps.
    top = os.path.join(src, "CMakeLists.txt")
    position = {}
    if os.path.isfile(top):
        for number, text in enumerate(open(top, encoding="utf-8"), start=1):
            match = re.match(r"\s*add_subdirectory\s*\(\s*([A-Za-z0-9_]+)\s*\)", text)
            if match:
                position[match.group(1)] = number
    for name, (deps, cmake, line) in modules.items():
        if name not in position:
            problems.append(f"{rel(top)}:1: module {name} has no add_subdirectory({name})")
            continue
        for dep in deps:
            if dep in position and position[dep] > position[name]:
                problems.append(f"{rel(top)}:{position[name]}: add_subdirectory({name}) comes before its "
                                f"dependency {dep} (line {position[dep]})")
    return problems, len(modules)


def main():
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--root", default=os.path.dirname(os.path.dirname(os.path.abspath(__file__))),
                        help="repository root (default: the one holding this script)")
    args = parser.parse_args()
    problems, module_count = check(args.root)
    for problem in problems:
        print(problem)
    if problems:
        print(f"check_layers: {len(problems)} problem(s)", file=sys.stderr)
        return 1
    print(f"check_layers: {module_count} modules, includes, CMake DEPS, ARCHITECTURE.md and order agree; no cycle")
    return 0


if __name__ == "__main__":
    sys.exit(main())
