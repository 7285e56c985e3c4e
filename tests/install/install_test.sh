#!/usr/bin/env bash
# The ctest `install_test`: installs a build's library into a temporary prefix and builds a program of its own
# against the installed package, as a user of lidarshop would, then runs it.
#   tests/install/install_test.sh BUILD_DIR CXX_COMPILER [CXX_FLAGS]
# Installs the component Development (the library, its public headers and lidarshopConfig.cmake; the whole
# `cmake --install` also puts the Python module in place, which needs that module built); checks that every
# installed header finds the lidarshop headers it includes and that no test helper or internal header is
# installed; configures tests/install/consumer with CMAKE_PREFIX_PATH = the prefix (ccache, -j 2), checks that
# it compiled against the installed headers and not the source tree, and runs it (a scan through PLY and back).
# CXX_FLAGS go to the consumer (the sanitizer builds pass -fsanitize=...). Where the CPU has AVX2 the consumer is
# also compiled with -mavx2, under which Eigen would align to 32 bytes where the library (built without) aligns
# to 16: the scan then comes back only if the package pins the library's Eigen alignment (its ABI).
set -euo pipefail
build=$(cd "$1" && pwd)
cxx=$2
cxx_flags=${3:-}
grep -qw avx2 /proc/cpuinfo 2>/dev/null && cxx_flags="$cxx_flags -mavx2"
source_dir=$(cd "$(dirname "$0")/../.." && pwd)
tmp=$(mktemp -d "${TMPDIR:-/tmp}/lidarshop_install_test.XXXXXX")
trap 'rm -rf "$tmp"' EXIT
fail() { echo "install_test: $*" >&2; exit 1; }

cmake --install "$build" --prefix "$tmp/prefix" --component Development >"$tmp/install.log" ||
  { cat "$tmp/install.log"; fail "cmake --install $build --prefix $tmp/prefix failed"; }
[[ -f $tmp/prefix/lib/cmake/lidarshop/lidarshopConfig.cmake ]] || fail "no lib/cmake/lidarshop/lidarshopConfig.cmake"
headers=$(cd "$tmp/prefix/include" && find lidarshop -name '*.h' | sort)
[[ $(wc -l <<<"$headers") -ge 20 ]] || fail "only $(wc -l <<<"$headers") headers installed under include/lidarshop"
while read -r header; do
  [[ $header != *_test*.h ]] || fail "a test helper is installed: include/$header"
  if head -c 2000 "$tmp/prefix/include/$header" | grep -qE '[Ii]nternals? (to|of) '; then
    fail "a header internal to its module is installed: include/$header"
  fi
  while read -r included; do
    [[ -f $tmp/prefix/include/$included ]] ||
      fail "include/$header includes \"$included\", which is not installed (internal or missing)"
  done < <(sed -nE 's/^\s*#\s*include\s*"(lidarshop\/[^"]+)".*/\1/p' "$tmp/prefix/include/$header")
done <<<"$headers"

launcher=()
command -v ccache >/dev/null && launcher=(-DCMAKE_CXX_COMPILER_LAUNCHER=ccache)
# Paths relative to the temporary folder in ccache's hash: the next run's objects come from the cache.
export CCACHE_BASEDIR="$tmp" CCACHE_NOHASHDIR=true
cmake -S "$source_dir/tests/install/consumer" -B "$tmp/build" -G Ninja -DCMAKE_BUILD_TYPE=Release \
  -DCMAKE_CXX_COMPILER="$cxx" -DCMAKE_PREFIX_PATH="$tmp/prefix" -DCMAKE_EXPORT_COMPILE_COMMANDS=ON \
  -DCMAKE_CXX_FLAGS="$cxx_flags" "${launcher[@]}" >"$tmp/configure.log" 2>&1 ||
  { cat "$tmp/configure.log"; fail "find_package(lidarshop) against $tmp/prefix failed"; }
cmake --build "$tmp/build" -j 2 >"$tmp/build.log" 2>&1 || { cat "$tmp/build.log"; fail "the consumer did not build"; }
if grep -q -- "$source_dir/src" "$tmp/build/compile_commands.json"; then
  fail "the consumer was compiled with the source tree's headers ($source_dir/src), not the installed ones"
fi
grep -q -- "$tmp/prefix/include" "$tmp/build/compile_commands.json" || fail "the consumer did not use PREFIX/include"
mkdir "$tmp/out"
"$tmp/build/lidarshop_consumer" "$tmp/out" || fail "the consumer ran but its scan did not come back from PLY"
echo "install_test: $(wc -l <<<"$headers") headers and the libraries installed; a program built against them" \
  "(flags:${cxx_flags:- none}) ran"
