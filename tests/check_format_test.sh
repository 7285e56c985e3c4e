#!/usr/bin/env bash
# Self-test of scripts/check_format.sh on small fake trees that use the repository's .clang-format: an
# unformatted file is named and fails the check, a formatted one passes, and a hand-laid comment table longer
# than the column limit is left alone (ReflowComments: false), so formatting never mangles comments; a
# missing clang-format and a broken .clang-format fail with exit 2.
#
#   tests/check_format_test.sh [CLANG_FORMAT]
set -euo pipefail
here=$(cd "$(dirname "$0")/.." && pwd)
clang_format=${1:-clang-format}
work=$(mktemp -d)
trap 'rm -rf "$work"' EXIT
fail() { echo "check_format_test: $*" >&2; exit 1; }

mkdir -p "$work/src" "$work/bench"
cp "$here/.clang-format" "$work/"
cat > "$work/src/table.h" <<'CPP'
// A table whose rows are wider than the column limit and must stay rows:
//   direction   CV_32FC3  unit ray direction in the scanner frame, known for EVERY cell (also without a return), always
//   valid       CV_8U     255 = the ray returned, 0 = no return
int Answer();
CPP
cp "$work/src/table.h" "$work/table.orig"
"$here/scripts/check_format.sh" "$work" "$clang_format" > "$work/out" || fail "a clean tree failed: $(cat "$work/out")"
"$clang_format" -i "$work/src/table.h"
cmp -s "$work/src/table.h" "$work/table.orig" || fail "clang-format changed the comment table"

printf 'int  Answer( ) {return 42;}\n' > "$work/bench/ugly.cc"
if "$here/scripts/check_format.sh" "$work" "$clang_format" > "$work/out"; then fail "an unformatted file passed"; fi
grep -q "bench/ugly.cc" "$work/out" || fail "the unformatted file is not named: $(cat "$work/out")"
grep -q "src/table.h" "$work/out" && fail "a clean file was named: $(cat "$work/out")"
"$clang_format" -i "$work/bench/ugly.cc"
"$here/scripts/check_format.sh" "$work" "$clang_format" > /dev/null || fail "the file still fails after clang-format -i"
# A clang-format that is not there: the check cannot run, so it fails (exit 2) and says why.
status=0
"$here/scripts/check_format.sh" "$work" "$work/no-such-clang-format" > "$work/out" 2>&1 || status=$?
[ "$status" -eq 2 ] || fail "a missing clang-format gave exit $status, not 2: $(cat "$work/out")"
grep -q "not found" "$work/out" || fail "a missing clang-format is not named: $(cat "$work/out")"
# A check that cannot run is a failure of its own (exit 2), never a pass: a broken .clang-format.
echo "BasedOnStyle: [not, a, style" > "$work/.clang-format"
status=0
"$here/scripts/check_format.sh" "$work" "$clang_format" > "$work/out" 2>&1 || status=$?
[ "$status" -eq 2 ] || fail "a broken .clang-format gave exit $status: $(cat "$work/out")"
echo "check_format_test: ok"
