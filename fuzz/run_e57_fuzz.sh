#!/bin/bash
# Builds the E57 reader fuzzer with Debian's clang 14 (libFuzzer + AddressSanitizer + UBSan), seeds it with the
# shared E57 files (as logical streams, see e57_fuzz.cc) and runs it for a bounded time.
#
#   fuzz/run_e57_fuzz.sh [seconds=300] [work dir=/tmp/lidarshop_e57_fuzz]
#
# Crashes are written to <work dir>/crash-*; turn each into a regression file under data/fuzz_regressions/.
set -euo pipefail
SECONDS_TO_RUN=${1:-300}
WORK=${2:-/tmp/lidarshop_e57_fuzz}
ROOT=$(cd "$(dirname "$0")/.." && pwd)
SHARED=${LIDARSHOP_SHARED_DATA_DIR:-$ROOT/../shared/data}
CXX=${CXX_FUZZ:-clang++-14}
mkdir -p "$WORK/obj" "$WORK/corpus" "$WORK/artifacts"

FLAGS="-std=c++20 -O1 -g -fsanitize=fuzzer-no-link,address,undefined -fno-sanitize-recover=undefined
  -I$ROOT/src -I/usr/include/eigen3 -I/usr/include/opencv4 -w"
SOURCES="src/lidarshop/io/e57_reader.cc src/lidarshop/io/e57_pages.cc src/lidarshop/io/e57_codec.cc
  src/lidarshop/scan/scan.cc src/lidarshop/scan/grid_fit.cc src/lidarshop/util/error.cc fuzz/e57_fuzz.cc"
OBJECTS=""
for s in $SOURCES; do
  o="$WORK/obj/$(basename "${s%.cc}").o"
  if [[ ! -f "$o" || "$ROOT/$s" -nt "$o" || "$ROOT/src/lidarshop/io/e57_format.h" -nt "$o" ]]; then
    echo "compile $s"
    $CXX $FLAGS -c "$ROOT/$s" -o "$o"
  fi
  OBJECTS="$OBJECTS $o"
done
$CXX -fsanitize=fuzzer,address,undefined $OBJECTS -o "$WORK/e57_fuzz" \
  -lpugixml -lopencv_imgcodecs -lopencv_imgproc -lopencv_core -lfmt

# Seeds: the logical streams of the shared files, plus the regression inputs.
for f in "$SHARED"/e57/*.e57; do
  python3 - "$f" "$WORK/corpus/$(basename "$f").logical" <<'PY'
import sys
d = open(sys.argv[1], 'rb').read()
open(sys.argv[2], 'wb').write(b''.join(d[i:i + 1020] for i in range(0, len(d), 1024)))
PY
done
if compgen -G "$ROOT/data/fuzz_regressions/e57_*" > /dev/null; then cp "$ROOT"/data/fuzz_regressions/e57_* "$WORK/corpus/"; fi

# Large images in a fuzzed blob must not exhaust memory inside OpenCV.
export OPENCV_IO_MAX_IMAGE_PIXELS=$((1 << 22))
"$WORK/e57_fuzz" "$WORK/corpus" -max_total_time="$SECONDS_TO_RUN" -max_len=$((1 << 20)) -rss_limit_mb=2048 \
  -timeout=20 -artifact_prefix="$WORK/artifacts/" -print_final_stats=1
