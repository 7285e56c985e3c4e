#!/usr/bin/env bash
# End to end, `demo` on a small built-in scene: its summary and the page that links and shows every file.
# Run by ctest as `demo_cli_test` (tests/cli_fixture.sh says how to run it by hand).
source "$(dirname "$0")/cli_fixture.sh"

# The demo on a small built-in scene.
check "demo" "$lidarshop" demo --scene mailbox --out "$work/demo" --quiet
json_check "demo summary" "$work/demo/summary.json" "d['scene'] == 'mailbox' and d['scan']['valid'] > 0"
# The page links every file the demo wrote and shows every picture.
for file in "$work"/demo/*; do
  name=$(basename "$file")
  [ "$name" = index.html ] && continue
  check "demo index links $name" grep -qF "href=\"$name\"" "$work/demo/index.html"
  case "$name" in *.png) check "demo index shows $name" grep -qF "src=\"$name\"" "$work/demo/index.html" ;; esac
done
check "demo wrote a second viewpoint and float range" test -s "$work/demo/top_view.png" -a -s "$work/demo/range.exr"
# The page's text as one line: the template breaks its paragraphs where it likes.
tr '\n' ' ' <"$work/demo/index.html" >"$work/index_text.html"
check "demo index explains the verification thresholds" grep -qE "passes above 0\.75.*passes above 0\.30" "$work/index_text.html"
check "demo index colours pass and fail" grep -qE "<td>(pass|fail)</td>" "$work/demo/index.html"
json_stdout "demo --json -" scan "$lidarshop" demo --scene mailbox --out "$work/j_demo" --json - --quiet

finish
