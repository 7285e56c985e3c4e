#!/usr/bin/env python3
"""Each module's tests are one program (lidarshop_<module>_tests) and each test file one ctest that runs it with a
--gtest_filter naming that file's tests (cmake/LidarshopHelpers.cmake). This checks that the filters cover every
test the programs hold exactly once: a test no filter names would never run, one named twice would run twice.

Usage: gtest_filters_test.py BUILD_DIR (ctest --show-only=json-v1 there gives each ctest's command)."""
import collections
import json
import subprocess
import sys

build_dir = sys.argv[1]
ctests = json.loads(subprocess.run(["ctest", "--show-only=json-v1"], cwd=build_dir, check=True,
                                   capture_output=True, text=True).stdout)["tests"]


def listed(command):
    """The full names of the tests `command` would run (gtest's --gtest_list_tests: suites, then indented
    names; parameterised names carry a '  # GetParam() = ...' comment)."""
    out = subprocess.run(command + ["--gtest_list_tests"], check=True, capture_output=True, text=True).stdout
    names, suite = [], ""
    for line in out.splitlines():
        if not line.startswith(" "):
            suite = line.split("#")[0].strip()
        else:
            names.append(suite + line.split("#")[0].strip())
    return names


runs = collections.defaultdict(collections.Counter)  # program -> test -> how many ctests run it
owners = collections.defaultdict(list)
for test in ctests:
    command = test.get("command") or []
    if not command or not command[0].endswith("_tests") or "/lidarshop_" not in command[0]:
        continue
    for name in listed(command):
        runs[command[0]][name] += 1
        owners[(command[0], name)].append(test["name"])

failed = 0
if not runs:
    print("FAILED: no ctest runs a module's test program (lidarshop_<module>_tests)")
    failed += 1
total = 0
for program, counted in sorted(runs.items()):
    every = listed([program])
    total += len(every)
    for name in every:
        if counted[name] != 1:
            print(f"FAILED: {name} of {program} is run by {counted[name]} ctests {owners[(program, name)]}")
            failed += 1
    for name in set(counted) - set(every):
        print(f"FAILED: {name} is named by a filter but {program} has no such test")
        failed += 1
print(f"{total} tests in {len(runs)} programs, each run by one ctest; {failed} problems")
sys.exit(1 if failed else 0)
