#!/usr/bin/env bash
# docs/options.md is what `lidarshop schema --markdown -o docs/options.md` makes of it: its part below the
# "Generated below" line is the reference of every described struct, so a field described (or changed) in a
# module's options_info.cc without regenerating the page fails here, with the command that brings it up to
# date. The part above the line is written by hand and kept. The binary comes from LIDARSHOP_CLI.
set -euo pipefail
cli=${LIDARSHOP_CLI:?LIDARSHOP_CLI names the lidarshop executable}
root=$(cd "$(dirname "$0")/.." && pwd)
committed=$root/docs/options.md
work=$(mktemp -d)
trap 'rm -rf "$work"' EXIT

cp "$committed" "$work/options.md"
"$cli" schema --markdown -o "$work/options.md" -q
if ! diff -u "$committed" "$work/options.md" >"$work/diff"; then
  head -n 60 "$work/diff"
  echo "FAIL: docs/options.md is stale; run: lidarshop schema --markdown -o docs/options.md"
  exit 1
fi
# Stdout gives the generated part alone, the same text.
"$cli" schema --markdown >"$work/reference.md"
marker=$(grep -n '^<!-- Generated below' "$committed" | cut -d: -f1)
tail -n +"$((marker + 1))" "$committed" | cmp - "$work/reference.md"
# A page without the line is refused, not overwritten.
printf '# no marker\n' >"$work/plain.md"
if "$cli" schema --markdown -o "$work/plain.md" -q 2>"$work/err"; then
  echo "FAIL: a page without the marker line was overwritten"
  exit 1
fi
grep -q "hand-written part" "$work/err"
grep -qx '# no marker' "$work/plain.md"
# Every options struct of the editor's API has its section (the list is the schema's, not this script's).
for name in $("$cli" schema --json - | python3 -c 'import json,sys; print(" ".join(s["name"] for s in json.load(sys.stdin)["structs"]))'); do
  grep -q "^### \`$name\`" "$committed" || { echo "FAIL: docs/options.md has no section for $name"; exit 1; }
done
echo "docs/options.md is current ($(grep -c '^### ' "$committed") structs)"
