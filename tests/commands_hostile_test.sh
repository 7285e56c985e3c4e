#!/usr/bin/env bash
# Issue 37, the command side: every command takes and applies --max-memory, an oversized sample count fails up
# front (never a bare std::bad_alloc), --json never overwrites the --options file, a full disk is said as such
# (/dev/full for stdout; a tiny tmpfs for atomic outputs, mounted in a user namespace or as root), and the
# temporaries of killed writers are removed by the next write, only theirs. Run by ctest as
# `commands_hostile_test`. Usage: commands_hostile_test.sh LIDARSHOP_BINARY
set -uo pipefail
lidarshop=$1
work=$(mktemp -d)
trap 'rm -rf "$work"' EXIT
passed=0
failed=0
# shellcheck source=check_lib.sh
source "$(dirname "$0")/check_lib.sh"

"$lidarshop" scan mailbox --rows 40 --columns 60 -o "$work/scan.ptx" -q 2>"$work/err" ||
  { echo "cannot make the test scan:"; cat "$work/err"; exit 1; }
"$lidarshop" render "$work/scan.ptx" --channel valid -o "$work/mask.png" >/dev/null 2>&1
printf 'v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 3\n' >"$work/tri.obj"

# --max-memory: every command parses it (a bad size is its usage error, before any other check).
commands=$("$lidarshop" --help | awk '/^Commands:/ {on = 1; next} on && NF >= 2 && /^  [a-z]/ {print $1}')
[ "$(echo "$commands" | wc -w)" -ge 20 ] || { echo "FAILED: no command list from lidarshop --help"; failed=$((failed + 1)); }
echo '{"steps": [{"command": "convert", "output": "{name}.ply"}]}' >"$work/pipeline.json"
for command in $commands; do
  case $command in
    batch)  # the Python driver; only when this build has it
      "$lidarshop" batch --help >/dev/null 2>&1 || continue
      args=(batch "$work/pipeline.json" "$work/scan.ptx" --out "$work/batch" --serial --max-memory lots) ;;
    *) args=("$command" --max-memory lots) ;;
  esac
  "$lidarshop" "${args[@]}" >"$work/out" 2>"$work/err"
  rc=$?
  check "$command --max-memory lots: usage error (exit 2), got $rc: $(head -c 200 "$work/err")" \
    test "$rc" -eq 2 -a "$(wc -l <"$work/err")" -eq 1
  check "$command --max-memory lots names the size: $(head -c 200 "$work/err")" \
    grep -q "'lots' is not a memory size" "$work/err"
done
# ... and applies it: the same command fits 1G and not 1M.
check "info --stats fits 1G" "$lidarshop" info --stats "$work/scan.ptx" --max-memory 1G
check "register fits 1G" "$lidarshop" register "$work/scan.ptx" "$work/scan.ptx" -o "$work/reg.ptx" --max-memory 1G
check "points voxel fits 1G" "$lidarshop" points voxel "$work/scan.ptx" -o "$work/voxel.ply" --max-memory 1G
fails_clearly "points sample-mesh: 1M is not enough for 100,000 samples" "memory budget of 1 MiB" \
  "$lidarshop" points sample-mesh "$work/tri.obj" -o "$work/samples.ply" --count 100000 --max-memory 1M
# A sample count past the default budget fails at once and clearly, under a 3 GB address-space limit.
start=$(date +%s)
fails_clearly "sample-mesh --count 300000000: up front" "--count 300000000: sampling 300000000 points needs" \
  bash -c "ulimit -v 3000000; exec '$lidarshop' points sample-mesh '$work/tri.obj' -o '$work/samples.ply' \
  --count 300000000"
check "sample-mesh --count 300000000 took under 5 s" test $(($(date +%s) - start)) -lt 5
fails_clearly "sample-mesh --count 300000000 --max-memory 256M" "memory budget of 256 MiB" \
  "$lidarshop" points sample-mesh "$work/tri.obj" -o "$work/samples.ply" --count 300000000 --max-memory 256M

# --json FILE never overwrites the --options FILE.
echo '{"method": "laplace"}' >"$work/fill_options.json"
cp "$work/fill_options.json" "$work/fill_options.orig"
fails_clearly "fill --json = --options" "would overwrite .*fill_options.json" "$lidarshop" fill "$work/scan.ptx" \
  --mask "$work/mask.png" -o "$work/filled.ptx" --options "$work/fill_options.json" \
  --json "$work/fill_options.json" -q
echo '{}' >"$work/convert_options.json"
cp "$work/convert_options.json" "$work/convert_options.orig"
fails_clearly "convert --json = --options" "would overwrite .*convert_options.json" "$lidarshop" convert \
  "$work/scan.ptx" "$work/c.e57" --options "$work/convert_options.json" --json "$work/convert_options.json"
check "the options files are unchanged" cmp -s "$work/fill_options.json" "$work/fill_options.orig"
check "the convert options file is unchanged" cmp -s "$work/convert_options.json" "$work/convert_options.orig"

# A full disk: stdout on /dev/full ...
fails_clearly "info --json - on /dev/full" "no space left on device" sh -c "'$lidarshop' info '$work/scan.ptx' >/dev/full"
# ... and an atomic output on a 16 KiB tmpfs (a user namespace, or root, may mount one).
mkdir -p "$work/tiny"
cat >"$work/full_disk.sh" <<EOF
mount -t tmpfs -o size=16k tmpfs '$work/tiny' || exit 77
'$lidarshop' convert '$work/scan.ptx' '$work/tiny/big.ply' >'$work/full.out' 2>'$work/full.err'
echo \$? >'$work/full.rc'
ls -A '$work/tiny' >'$work/full.ls'
umount '$work/tiny'
EOF
if [ "$(id -u)" -eq 0 ]; then bash "$work/full_disk.sh"; else unshare -rm bash "$work/full_disk.sh"; fi
if [ -f "$work/full.rc" ]; then
  check "convert onto a full tmpfs: exit 1, got $(cat "$work/full.rc")" test "$(cat "$work/full.rc")" -eq 1
  check "convert onto a full tmpfs says so: $(cat "$work/full.err")" grep -q "big.ply.*no space left on device" \
    "$work/full.err"
  check "convert onto a full tmpfs leaves nothing: $(cat "$work/full.ls")" test ! -s "$work/full.ls"
else
  echo "NOTE: no tmpfs could be mounted (not root, no user namespaces): the atomic full-disk case did not run"
fi

# Temporaries of killed writers: removed by the next write of the same target once their process is gone and
# they are a minute old; a live writer's, a fresh one's (maybe another machine's) and other targets' stay.
sleep 60 &
dead=$!
kill -9 "$dead"
wait "$dead" 2>/dev/null
mkdir -p "$work/outputs"
for name in ".c.tmp$dead-0.ply" ".c.tmp$dead-1.ply" ".c.tmp$$-0.ply" ".d.tmp$dead-0.ply"; do
  head -c 100000 /dev/zero >"$work/outputs/$name"
done
touch -d '-2 minutes' "$work/outputs/.c.tmp$dead-0.ply" "$work/outputs/.c.tmp$$-0.ply" "$work/outputs/.d.tmp$dead-0.ply"
check "convert beside stale temporaries" "$lidarshop" convert "$work/scan.ptx" "$work/outputs/c.ply"
check "the dead writer's old temporary is removed" test ! -e "$work/outputs/.c.tmp$dead-0.ply"
check "a fresh temporary stays" test -e "$work/outputs/.c.tmp$dead-1.ply"
check "a live writer's temporary stays" test -e "$work/outputs/.c.tmp$$-0.ply"
check "another target's temporary stays" test -e "$work/outputs/.d.tmp$dead-0.ply"
# A real kill -9 in the middle of a write leaves its temporary; the next write of the target, a minute on,
# removes it.
"$lidarshop" scan mailbox --rows 600 --columns 1200 -o "$work/big.ptx" -q 2>/dev/null
# The write takes a fraction of a second: a loaded machine can finish it before the kill lands, so up to five
# tries (each a new process) catch one in the middle.
left=""
for _attempt in 1 2 3 4 5; do
  "$lidarshop" convert "$work/big.ptx" "$work/outputs/big.ply" -q &
  writer=$!
  for _ in $(seq 1 4000); do
    compgen -G "$work/outputs/.big.tmp$writer-*.ply" >/dev/null && break
    sleep 0.002
  done
  kill -9 "$writer" 2>/dev/null
  wait "$writer" 2>/dev/null
  left=$(compgen -G "$work/outputs/.big.tmp$writer-*.ply" | head -1)
  [ -n "$left" ] && break
done
check "kill -9 mid-write leaves a temporary" test -n "$left"
if [ -n "$left" ]; then
  touch -d '-2 minutes' "$left"
  check "convert again" "$lidarshop" convert "$work/scan.ptx" "$work/outputs/big.ply"
  check "the killed writer's temporary is gone" test ! -e "$left"
fi

echo "commands_hostile_test: $passed passed, $failed failed"
[ "$failed" -eq 0 ]
