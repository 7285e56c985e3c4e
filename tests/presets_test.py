#!/usr/bin/env python3
"""Checks that CMakePresets.json and the scripts that configure build folders agree (the ctest `presets_test`).

  - the presets release, asan and fuzz exist, use Ninja and build in build/<name>;
  - every script in scripts/ configures only through `cmake --preset NAME` (no `cmake -S/-B`, no -D of its own),
    with a preset that exists;
  - every build folder a script builds or tests (`cmake --build DIR`, `ctest --test-dir DIR`) is the binaryDir of
    a preset that script configured.
Runs its own rules on two small wrong scripts first, so that it cannot pass by checking nothing.
Usage: python3 tests/presets_test.py [ROOT]
"""
import json
import os
import re
import sys

REQUIRED = ("release", "asan", "fuzz")


def load_presets(root):
    """Returns {name: {generator, binaryDir, cacheVariables}} with `inherits` resolved."""
    with open(os.path.join(root, "CMakePresets.json"), encoding="utf-8") as f:
        raw = {p["name"]: p for p in json.load(f)["configurePresets"]}

    def resolve(name):
        preset = raw[name]
        parents = preset.get("inherits", [])
        merged = {}
        for parent in [parents] if isinstance(parents, str) else parents:
            merged.update(resolve(parent))
        cache = dict(merged.get("cacheVariables", {}))
        cache.update(preset.get("cacheVariables", {}))
        merged.update({k: v for k, v in preset.items() if k != "cacheVariables"})
        merged["cacheVariables"] = cache
        return merged

    resolved = {}
    for name, preset in raw.items():
        if preset.get("hidden"):
            continue
        p = resolve(name)
        binary = p.get("binaryDir", "").replace("${sourceDir}/", "").replace("${presetName}", name)
        resolved[name] = {"generator": p.get("generator"), "binaryDir": binary, "cache": p["cacheVariables"]}
    return resolved


def check_script(name, text, presets, configured_by=None):
    """Problems of one script's text (configure lines and the build folders it then uses). configured_by:
    {script name: build folders it configures}, for the scripts this one runs (`bash scripts/build.sh`)."""
    problems = []
    # Join continued lines; drop comments.
    lines = re.sub(r"\\\n", " ", text).splitlines()
    assigned = dict(re.findall(r"^\s*([A-Za-z_]+)=([^\s;]+)\s*$", "\n".join(lines), re.M))
    configured = set()
    for number, line in enumerate(lines, start=1):
        code = line.split("#", 1)[0] if not line.lstrip().startswith("#") else ""
        code = re.sub(r'"?\$\{?([A-Za-z_]+)\}?"?', lambda m: assigned.get(m.group(1), m.group(0)), code)
        for called in re.findall(r"scripts/([A-Za-z0-9_]+\.sh)", code):
            configured |= (configured_by or {}).get(called, set())
        if not re.search(r"(^|[\s;(&|])cmake\s", code):
            pass
        elif "--preset" in code:
            preset = re.search(r"--preset[ =](\S+)", code).group(1)
            if preset not in presets:
                problems.append(f"scripts/{name}:{number}: cmake --preset {preset}: no such configure preset")
            else:
                configured.add(presets[preset]["binaryDir"])
            if re.search(r"\s-D\S", code):
                problems.append(f"scripts/{name}:{number}: a -D beside --preset: put it in CMakePresets.json")
        elif re.search(r"\scmake\s+(-S|-B|-G|-D)|^\s*cmake\s+(-S|-B|-G|-D)", code):
            problems.append(f"scripts/{name}:{number}: configures a build folder without a preset "
                            f"(use cmake --preset, CMakePresets.json)")
        for used in re.findall(r"(?:cmake\s+--build|--test-dir)\s+(build/[A-Za-z0-9_-]+)", code):
            if used not in configured:
                problems.append(f"scripts/{name}:{number}: uses {used}, which no preset this script "
                                f"configured builds in (configured: {sorted(configured) or 'none'})")
    return problems


def main():
    root = sys.argv[1] if len(sys.argv) > 1 else os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
    problems = []
    presets = load_presets(root)
    for name in REQUIRED:
        if name not in presets:
            problems.append(f"CMakePresets.json: no configure preset {name}")
            continue
        if presets[name]["binaryDir"] != f"build/{name}":
            problems.append(f"CMakePresets.json: preset {name} builds in {presets[name]['binaryDir']}, "
                            f"not build/{name}")
        if presets[name]["generator"] != "Ninja":
            problems.append(f"CMakePresets.json: preset {name} does not use Ninja")

    # The rules themselves, on two wrong scripts: a configure without a preset, a folder of another preset.
    wrong = check_script("wrong.sh", "cmake -S . -B build/release -G Ninja\n", presets)
    wrong += check_script("wrong2.sh", "cmake --preset asan\ncmake --build build/release\n", presets)
    if len(wrong) != 2 or "without a preset" not in wrong[0] or "uses build/release" not in wrong[1]:
        problems.append(f"presets_test: its own rules missed a wrong script: {wrong}")

    scripts = os.path.join(root, "scripts")
    texts = {name: open(os.path.join(scripts, name), encoding="utf-8").read()
             for name in sorted(os.listdir(scripts)) if name.endswith(".sh")}
    configured_by = {name: {presets[p]["binaryDir"] for p in re.findall(r"--preset[ =](\S+)", text) if p in presets}
                     for name, text in texts.items()}
    configuring = sum(1 for dirs in configured_by.values() if dirs)
    for name, text in texts.items():
        problems += check_script(name, text, presets, configured_by)
    if configuring == 0:
        problems.append("scripts/: no script configures with a preset (nothing was checked)")
    for problem in problems:
        print(problem)
    if problems:
        print(f"presets_test: {len(problems)} problem(s)", file=sys.stderr)
        return 1
    print(f"presets_test: {', '.join(sorted(presets))} presets; {configuring} scripts configure through them")
    return 0


if __name__ == "__main__":
    sys.exit(main())
