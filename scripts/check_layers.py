#!/usr/bin/env python3
"""Checks that every folder of the source tree keeps the layers ARCHITECTURE.md states.

Every C++ file of the repository (outside build folders) belongs to one layer:
  - a module: the files directly in src/lidarshop/<m>/, whose CMakeLists.txt calls lidarshop_add_module(NAME m);
  - a program in a subfolder of a module (src/lidarshop/fill/eval/): a consumer of that module;
  - a face: a folder listed in ARCHITECTURE.md's face table (| face | folders | may include |), and its subfolders.
A C++ file in no layer is a problem: the check covers every folder, including ones added later.

For modules it compares
  - the includes of its library sources (not tests: *_test.cc, *_test_util.h) with the DEPS of its CMakeLists.txt
    (exactly: an undeclared include and a declared dependency never included are both problems),
  - the DEPS with the "depends on" column of the module table in ARCHITECTURE.md (names of module folders, in
    backticks or plain; other words such as external libraries are ignored),
  - the order of add_subdirectory() in src/lidarshop/CMakeLists.txt, and finds cycles;
and the rules for everything else:
  - the library never includes a face (library sources and module tests alike); a module's tests (*_test.cc)
    may include any module and `testing`;
  - a program in a module's subfolder includes its module, the modules that one depends on (directly or not) and
    `testing`;
  - a face includes its own files, the library (every module but `testing`) and what its "may include" cell
    names in backticks (modules or faces); its tests (*_test.cc) may also include `testing`.
An include is resolved as the compiler would find it: beside the file, then under src/, the repository root and
each face's folder; includes that resolve to no file of the tree (system headers) are not layers.
Known exceptions are the rows of ARCHITECTURE.md's table | known exception | includes | why ... |: the files
under the first cell may include the layers of the second. A row that no include needs any more is a problem
(remove it once the code is fixed).

Prints one line per problem (file:line: message) and exits 1 if there is any; 0 and one summary line otherwise.
Exits 2 with a message when it cannot run (no src/lidarshop, no module, no C++ file): a check that cannot run
fails, it does not pass.
Usage: python3 scripts/check_layers.py [--root DIR]
"""
import argparse
import os
import re
import sys

INCLUDE_RE = re.compile(r'^\s*#\s*include\s*"([^"]+)"')
ADD_MODULE_RE = re.compile(r"lidarshop_add_module\s*\(([^)]*)\)", re.S)
KEYWORDS = {"NAME", "DEPS", "LIBS", "TEST_DEPS", "TEST_LIBS"}
CPP_EXTENSIONS = (".h", ".hh", ".hpp", ".c", ".cc", ".cpp", ".cxx")
TESTING = "testing"  # the test fixtures module: tests and evaluation programs only
TEST_FILE_RE = re.compile(r"_test(_[A-Za-z0-9_]+)?\.[a-z]+$")  # foo_test.cc and test helpers (io_test_util.h)


class CannotRun(Exception):
    pass


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


def parse_tables(path):
    """Returns {header tuple: [(cells, line)]} for every markdown table of path (header cells lower case)."""
    tables = {}
    header = None
    for number, line in enumerate(open(path, encoding="utf-8"), start=1):
        stripped = line.strip()
        if not stripped.startswith("|"):
            header = None
            continue
        cells = [cell.strip() for cell in stripped.strip("|").split("|")]
        if header is None:
            header = tuple(cell.lower() for cell in cells)
            tables.setdefault(header, [])
        elif not set(stripped) <= set("|-: "):
            tables[header].append((cells, number))
    return tables


def find_table(tables, *columns):
    """The rows and the column indexes of the first table whose header has all `columns`; no rows if none has."""
    for header, rows in tables.items():
        if all(column in header for column in columns):
            return rows, [header.index(column) for column in columns]
    return [], [0] * len(columns)


def ticked(cell):
    """The names in backticks in a table cell, outside parentheses (which hold prose)."""
    return re.findall(r"`([^`]+)`", re.sub(r"\([^)]*\)", "", cell))


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


def cpp_files(root):
    """Every C++ file under root (relative paths, sorted), without build folders, .git and node_modules."""
    found = []
    for folder, subfolders, files in os.walk(root):
        relative = os.path.relpath(folder, root)
        subfolders[:] = sorted(
            d for d in subfolders
            if not d.startswith(".") and d != "node_modules" and not (relative == "." and
                                                                      (d.startswith("build") or d == "out")))
        found += [os.path.normpath(os.path.join(relative, f)) for f in files if f.endswith(CPP_EXTENSIONS)]
    return sorted(found)


def under(path, folder):
    return path == folder or path.startswith(folder + "/")


def check(root):
    problems = []
    src = os.path.join(root, "src", "lidarshop")
    if not os.path.isdir(src):
        raise CannotRun(f"no src/lidarshop under {root}: nothing to check")

    def rel(path):
        return os.path.relpath(path, root)

    # --- Modules: CMake, the module table, order and cycles.
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
    if not modules:
        raise CannotRun(f"no lidarshop_add_module() in any src/lidarshop/*/CMakeLists.txt under {root}")

    for name, (deps, cmake, line) in modules.items():
        for dep in deps:
            if dep not in modules:
                problems.append(f"{rel(cmake)}:{line}: {name} declares DEPS {dep}, which is not a module")
            if dep == name:
                problems.append(f"{rel(cmake)}:{line}: {name} declares itself as a dependency")

    architecture = os.path.join(root, "ARCHITECTURE.md")
    arch = rel(architecture)
    tables = parse_tables(architecture) if os.path.isfile(architecture) else {}
    module_rows, (name_col, dep_col) = find_table(tables, "module", "depends on")
    if not module_rows:
        problems.append(f"{arch}:1: no module table with a 'depends on' column")
    else:
        table = {}
        for cells, number in module_rows:
            words = re.findall(r"[A-Za-z0-9_]+", re.sub(r"\([^)]*\)", "", cells[dep_col]))
            table[cells[name_col].strip("` ")] = ({word for word in words if word in modules}, number)
        for name, (deps, cmake, line) in modules.items():
            if name not in table:
                problems.append(f"{arch}:1: module {name} is missing from the module table")
                continue
            table_deps, table_line = table[name]
            if table_deps != set(deps):
                problems.append(f"{arch}:{table_line}: table says {name} depends on "
                                f"{sorted(table_deps)} but {rel(cmake)}:{line} DEPS are {sorted(deps)}")
        for name, (_, table_line) in table.items():
            if name not in modules and not os.path.isdir(os.path.join(src, name)):
                problems.append(f"{arch}:{table_line}: table lists {name}, which is not a folder "
                                f"of src/lidarshop")

    graph = {name: [d for d in deps if d in modules] for name, (deps, _, _) in modules.items()}
    cycle = find_cycle(graph)
    if cycle:
        problems.append(f"{rel(modules[cycle[0]][1])}:{modules[cycle[0]][2]}: dependency cycle: "
                        + " -> ".join(cycle))

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

    # --- Faces and known exceptions (ARCHITECTURE.md).
    library = {name for name in modules if name != TESTING}
    faces = {}  # name -> (folders, allowed layers, line)
    face_rows, columns = find_table(tables, "face", "folders", "may include")
    if not face_rows:
        problems.append(f"{arch}:1: no face table (| face | folders | may include |)")
    else:
        for cells, number in face_rows:
            name = cells[columns[0]].strip("` ")
            folders = [folder.strip("/") for folder in ticked(cells[columns[1]])]
            allowed = set(ticked(cells[columns[2]]))
            if "library" in cells[columns[2]]:
                allowed |= library
            faces[name] = (folders, allowed, number)
            for folder in folders:
                if not os.path.isdir(os.path.join(root, folder)):
                    problems.append(f"{arch}:{number}: face {name} lists {folder}, which is not a folder")
                elif folder.split("/")[:2] == ["src", "lidarshop"] and folder.split("/")[2:] in [[m] for m in modules]:
                    problems.append(f"{arch}:{number}: face {name} lists {folder}, which is a module's folder")
    for name, (_, allowed, number) in faces.items():
        for layer in sorted(allowed - library - set(faces) - {TESTING}):
            problems.append(f"{arch}:{number}: face {name} may include `{layer}`, which is no module or face")

    exceptions = []  # [path prefix, allowed layers, line, used]
    exception_rows, columns = find_table(tables, "known exception", "includes")
    for cells, number in exception_rows:
        paths = ticked(cells[columns[0]])
        if len(paths) != 1:
            problems.append(f"{arch}:{number}: a known exception names one file or folder in backticks")
            continue
        exceptions.append([paths[0].strip("/"), set(ticked(cells[columns[1]])), number, set()])

    # --- Every C++ file: its layer, then its includes.
    face_folders = sorted(((folder, name) for name, (folders, _, _) in faces.items() for folder in folders),
                          key=lambda item: -len(item[0]))
    include_roots = ["src", "."] + [folder for folder, _ in face_folders]

    def layer_of(path):
        """('module', m) | ('program', m) | ('face', f) | None for a path relative to root."""
        for folder, name in face_folders:
            if under(path, folder):
                return ("face", name)
        parts = path.split("/")
        if len(parts) >= 4 and parts[:2] == ["src", "lidarshop"] and parts[2] in modules:
            return ("module", parts[2]) if len(parts) == 4 else ("program", parts[2])
        return None

    def closure(name):
        seen, stack = set(), [name]
        while stack:
            for dep in graph.get(stack.pop(), ()):
                if dep not in seen:
                    seen.add(dep)
                    stack.append(dep)
        return seen

    def describe(layer):
        return {"face": "face", "module": "module", "program": "a program of module"}[layer[0]] + " " + layer[1]

    modules_included = {}  # module -> the modules its library sources include
    files = cpp_files(root)
    if not files:
        raise CannotRun(f"no C++ file under {root}")
    unplaced = {}
    for path in files:
        layer = layer_of(path)
        if layer is None:
            unplaced.setdefault(os.path.dirname(path), path)
            continue
        kind, name = layer
        is_test = TEST_FILE_RE.search(path) is not None
        text_lines = open(os.path.join(root, path), encoding="utf-8", errors="replace").read().splitlines()
        for number, text in enumerate(text_lines, start=1):
            match = INCLUDE_RE.match(text)
            if not match:
                continue
            included = match.group(1)
            target = None
            for base in [os.path.dirname(path)] + include_roots:
                candidate = os.path.normpath(os.path.join(base, included))
                if os.path.isfile(os.path.join(root, candidate)):
                    target = layer_of(candidate)
                    break
            module_include = re.match(r"lidarshop/([A-Za-z0-9_]+)/", included)
            if kind == "module" and not is_test:
                # Library sources: exactly the declared DEPS (also for includes of files that do not exist).
                if module_include and module_include.group(1) in modules:
                    dep = module_include.group(1)
                    if dep != name:
                        modules_included.setdefault(name, set()).add(dep)
                        if dep not in modules[name][0]:
                            problems.append(f"{path}:{number}: {name} includes lidarshop/{dep}/, which is not a "
                                            f"declared dependency (DEPS in {rel(modules[name][1])})")
                    continue
                if target and target[0] == "face":
                    problems.append(f"{path}:{number}: module {name} includes \"{included}\" of face "
                                    f"{target[1]}: the library never includes a face")
                elif module_include and not target:
                    problems.append(f"{path}:{number}: {name} includes {included}, which is in no module")
                continue
            if target is None or target == layer:
                continue
            target_kind, target_name = target
            if target_kind == "program":
                allowed = False
            elif kind == "module":  # a module's test
                allowed = target_kind == "module"
            elif kind == "program":
                allowed = target_kind == "module" and target_name in {name, TESTING} | closure(name)
            else:  # a face
                allowed = target_name in faces[name][1] or (is_test and target_name == TESTING)
            if allowed:
                continue
            excused = False
            for exception in exceptions:
                if under(path, exception[0]) and target_name in exception[1]:
                    exception[3].add(target_name)
                    excused = True
            if excused:
                continue
            if kind == "module":
                why = "the library never includes a face" if target_kind == "face" else "not a layer it may use"
            elif kind == "program":
                why = (f"a program in a subfolder of module {name} may include {name}, what it depends on and "
                       f"{TESTING}")
            else:
                why = f"not in face {name}'s 'may include' ({arch}:{faces[name][2]})"
            problems.append(f"{path}:{number}: {'test of ' if is_test else ''}{describe(layer)} includes "
                            f"\"{included}\" of {describe(target)}: {why}")
    for folder, example in sorted(unplaced.items()):
        problems.append(f"{folder or '.'}: holds C++ files ({os.path.basename(example)}) but is in no layer: make "
                        f"it a module or add it to the face table of {arch}")
    for name, (deps, cmake, line) in modules.items():
        for dep in deps:
            if dep in modules and dep not in modules_included.get(name, set()):
                problems.append(f"{rel(cmake)}:{line}: {name} declares DEPS {dep} but no library source of "
                                f"{name} includes lidarshop/{dep}/ (unused link)")
    for path, layers, number, used in exceptions:
        for layer in sorted(layers - used):
            problems.append(f"{arch}:{number}: known exception `{path}` including `{layer}` no longer happens: "
                            f"remove it from the table")
    return problems, len(modules), len(faces), len(files)


def main():
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--root", default=os.path.dirname(os.path.dirname(os.path.abspath(__file__))),
                        help="repository root (default: the one holding this script)")
    args = parser.parse_args()
    try:
        problems, module_count, face_count, file_count = check(os.path.abspath(args.root))
    except (CannotRun, OSError) as error:
        print(f"check_layers: FAILED, the check cannot run: {error}", file=sys.stderr)
        return 2
    for problem in problems:
        print(problem)
    if problems:
        print(f"check_layers: {len(problems)} problem(s)", file=sys.stderr)
        return 1
    print(f"check_layers: {file_count} C++ files in {module_count} modules and {face_count} faces; includes, "
          f"CMake DEPS, ARCHITECTURE.md and order agree; no cycle")
    return 0


if __name__ == "__main__":
    sys.exit(main())
