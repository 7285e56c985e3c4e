// File-format speed: PTX parsing (MB/s on one core, target >= 100 MB/s), PLY and PCD reading, LAZ decoding
// beside LAS reading (the shared autzen_trim pair: 110000 points of format 3, LASzip 3 chunks).
//
// The input is generated here: a synthetic 1000 x 1000 PTX scan with colour (7-field lines, ~10 % no-return
// cells), printed by lidarshop's own writer. Peers in the same run: a naive std::istringstream parser (what a
// first PTX reader usually looks like) and strtod, so that the ratios come from one run.
#include <unistd.h>

#include <cstdlib>
#include <filesystem>
#include <random>
#include <sstream>

#include <benchmark/benchmark.h>

#include "lidarshop/io/io_common.h"
#include "lidarshop/io/laz.h"
#include "lidarshop/io/pcd.h"
#include "lidarshop/io/ptx.h"
#include "lidarshop/io/scan_io.h"
#include "lidarshop/util/parallel.h"

namespace lidarshop {
namespace {

Scan SyntheticScan(int rows, int cols) {
  Scan scan = MakeScan(rows, cols, /*with_color=*/true);
  scan.direction = DirectionsFromGrid(UniformGrid(rows, cols, -1.2, 1.2, -0.6, 0.6));
  std::mt19937 random(1);
  std::uniform_real_distribution<float> range(1.0f, 60.0f), unit(0.0f, 1.0f);
  for (int row = 0; row < rows; ++row) {
    for (int col = 0; col < cols; ++col) {
      if (unit(random) < 0.1f) continue;
      const float r = range(random);
      scan.valid.at<uint8_t>(row, col) = kValid;
      scan.point.at<cv::Vec3f>(row, col) = scan.direction.at<cv::Vec3f>(row, col) * r;
      scan.range.at<float>(row, col) = r;
      scan.intensity.at<float>(row, col) = unit(random);
      scan.color.at<cv::Vec3b>(row, col) = cv::Vec3b(random() & 255, random() & 255, random() & 255);
    }
  }
  return scan;
}

const Scan& BenchScan() {
  static const Scan scan = SyntheticScan(1000, 1000);
  return scan;
}

const std::string& PtxText() {
  static const std::string text = FormatPtx({BenchScan()});
  return text;
}

std::string TempPath(const std::string& name) {
  const std::string folder = std::filesystem::is_directory("/dev/shm") ? "/dev/shm" : "/tmp";
  return folder + "/lidarshop_io_bench_" + std::to_string(getpid()) + "_" + name;
}

void BM_PtxParse(benchmark::State& state) {
  ThreadLimit one_core(1);
  const std::string& text = PtxText();
  PtxReadOptions options;
  options.fit_grid = false;
  for (auto _ : state) benchmark::DoNotOptimize(ParsePtx(text, "bench.ptx", options));
  state.SetBytesProcessed(state.iterations() * static_cast<int64_t>(text.size()));
  state.counters["file_MB"] = text.size() / 1e6;
}
BENCHMARK(BM_PtxParse)->Unit(benchmark::kMillisecond)->MinTime(2.0);

void BM_PtxParseWithGridFit(benchmark::State& state) {
  ThreadLimit one_core(1);
  const std::string& text = PtxText();
  for (auto _ : state) benchmark::DoNotOptimize(ParsePtx(text, "bench.ptx"));
  state.SetBytesProcessed(state.iterations() * static_cast<int64_t>(text.size()));
}
BENCHMARK(BM_PtxParseWithGridFit)->Unit(benchmark::kMillisecond)->MinTime(2.0);

void BM_PtxReadFile(benchmark::State& state) {
  ThreadLimit one_core(1);
  const std::string path = TempPath("read.ptx");
  WritePtx(path, {BenchScan()});
  const auto size = static_cast<int64_t>(std::filesystem::file_size(path));
  for (auto _ : state) benchmark::DoNotOptimize(ReadScanFile(path));
  state.SetBytesProcessed(state.iterations() * size);
  std::filesystem::remove(path);
}
BENCHMARK(BM_PtxReadFile)->Unit(benchmark::kMillisecond)->MinTime(2.0);

// Peer: the naive reader, numbers through std::istringstream (locale-aware, virtual calls per character).
void BM_PtxNaiveIstream(benchmark::State& state) {
  const std::string& text = PtxText();
  for (auto _ : state) {
    std::istringstream stream(text);
    int cols = 0, rows = 0;
    stream >> cols >> rows;
    double header[3 + 9 + 16];
    for (double& value : header) stream >> value;
    std::vector<float> values(static_cast<size_t>(rows) * cols * 7);
    for (size_t i = 0; i < values.size(); i += 7) {
      std::string line;
      stream >> values[i] >> values[i + 1] >> values[i + 2] >> values[i + 3];
      if (stream.peek() == ' ') stream >> values[i + 4] >> values[i + 5] >> values[i + 6];
    }
    benchmark::DoNotOptimize(values.data());
  }
  state.SetBytesProcessed(state.iterations() * static_cast<int64_t>(text.size()));
}
BENCHMARK(BM_PtxNaiveIstream)->Unit(benchmark::kMillisecond)->MinTime(2.0);

// Peer: strtod/strtol over the buffer (C locale lookups per call), no tokenizing beyond that.
void BM_PtxStrtod(benchmark::State& state) {
  const std::string& text = PtxText();
  for (auto _ : state) {
    const char* p = text.c_str();
    char* end = nullptr;
    double sum = 0;
    for (;;) {
      const double value = std::strtod(p, &end);
      if (end == p) break;
      sum += value;
      p = end;
    }
    benchmark::DoNotOptimize(sum);
  }
  state.SetBytesProcessed(state.iterations() * static_cast<int64_t>(text.size()));
}
BENCHMARK(BM_PtxStrtod)->Unit(benchmark::kMillisecond)->MinTime(2.0);

void BM_PtxWrite(benchmark::State& state) {
  ThreadLimit one_core(1);
  int64_t bytes = 0;
  for (auto _ : state) {
    const std::string text = FormatPtx({BenchScan()});
    bytes += static_cast<int64_t>(text.size());
    benchmark::DoNotOptimize(text.data());
  }
  state.SetBytesProcessed(bytes);
}
BENCHMARK(BM_PtxWrite)->Unit(benchmark::kMillisecond)->MinTime(2.0);

void BM_ReadScanFile(benchmark::State& state, const std::string& extension) {
  ThreadLimit one_core(1);
  const std::string path = TempPath("read." + extension);
  WriteScanFile(path, {BenchScan()});
  const auto size = static_cast<int64_t>(std::filesystem::file_size(path));
  for (auto _ : state) benchmark::DoNotOptimize(ReadScanFile(path));
  state.SetBytesProcessed(state.iterations() * size);
  state.counters["file_MB"] = size / 1e6;
  state.counters["points_per_s"] = benchmark::Counter(static_cast<double>(BenchScan().num_cells()),
                                                      benchmark::Counter::kIsIterationInvariantRate);
  std::filesystem::remove(path);
}
BENCHMARK_CAPTURE(BM_ReadScanFile, ply_binary, std::string("ply"))
    ->Unit(benchmark::kMillisecond)
    ->MinTime(2.0);
BENCHMARK_CAPTURE(BM_ReadScanFile, pcd_binary, std::string("pcd"))
    ->Unit(benchmark::kMillisecond)
    ->MinTime(2.0);

// The real binary_compressed (LZF) organized cloud of the shared data, 640 x 480.
void BM_PcdReadBinaryCompressed(benchmark::State& state) {
  ThreadLimit one_core(1);
  const std::string path = LIDARSHOP_SHARED_DATA_DIR "/rgbd/table_scene_mug_stereo_textured.pcd";
  if (!std::filesystem::exists(path)) {
    state.SkipWithError("shared data missing");
    return;
  }
  for (auto _ : state) benchmark::DoNotOptimize(ReadPcd(path));
  state.SetBytesProcessed(state.iterations() * static_cast<int64_t>(std::filesystem::file_size(path)));
  state.counters["points_per_s"] =
      benchmark::Counter(640.0 * 480.0, benchmark::Counter::kIsIterationInvariantRate);
}
BENCHMARK(BM_PcdReadBinaryCompressed)->Unit(benchmark::kMillisecond)->MinTime(2.0);

// LAZ: ReadScanFile of the .laz beside its uncompressed .las twin (the difference is the decoding), and the
// decoder alone (DecodeLazPoints: compressed bytes to LAS records).
void BM_LasLazRead(benchmark::State& state, const std::string& name) {
  ThreadLimit one_core(1);
  const std::string path = LIDARSHOP_SHARED_DATA_DIR "/interop/" + name;
  if (!std::filesystem::exists(path)) {
    state.SkipWithError("shared data missing");
    return;
  }
  for (auto _ : state) benchmark::DoNotOptimize(ReadScanFile(path));
  state.SetBytesProcessed(state.iterations() * static_cast<int64_t>(std::filesystem::file_size(path)));
  state.counters["points_per_s"] =
      benchmark::Counter(110000.0, benchmark::Counter::kIsIterationInvariantRate);
}
BENCHMARK_CAPTURE(BM_LasLazRead, las, std::string("las/autzen_trim.las"))
    ->Unit(benchmark::kMillisecond)
    ->MinTime(2.0);
BENCHMARK_CAPTURE(BM_LasLazRead, laz, std::string("laz/autzen_trim.laz"))
    ->Unit(benchmark::kMillisecond)
    ->MinTime(2.0);

void BM_LazDecode(benchmark::State& state) {
  ThreadLimit one_core(1);
  const std::string path = LIDARSHOP_SHARED_DATA_DIR "/interop/laz/autzen_trim.laz";
  if (!std::filesystem::exists(path)) {
    state.SkipWithError("shared data missing");
    return;
  }
  const std::string bytes = io_internal::ReadFileToString(path);
  auto u16 = [&](size_t at) {
    return static_cast<uint16_t>(static_cast<uint8_t>(bytes[at]) | static_cast<uint8_t>(bytes[at + 1]) << 8);
  };
  auto u32 = [&](size_t at) { return static_cast<uint32_t>(u16(at) | u16(at + 2) << 16); };
  // The LAS 1.2 header's fields and the laszip VLR (the first VLR with record id 22204).
  std::string_view payload;
  for (size_t at = u16(94), i = 0; i < u32(100); ++i, at += 54 + u16(at + 20)) {
    if (u16(at + 18) == laz::kLazVlrRecordId) payload = std::string_view(bytes).substr(at + 54, u16(at + 20));
  }
  const uint32_t count = u32(107);
  for (auto _ : state) {
    benchmark::DoNotOptimize(
        laz::DecodeLazPoints(payload, bytes, u32(96), count, bytes[104] & 0x3F, u16(105), path));
  }
  state.counters["points_per_s"] = benchmark::Counter(count, benchmark::Counter::kIsIterationInvariantRate);
}
BENCHMARK(BM_LazDecode)->Unit(benchmark::kMillisecond)->MinTime(2.0);

}  // namespace
}  // namespace lidarshop

BENCHMARK_MAIN();
