// E57 reading and writing speed: the real pumpA scan and a synthetic 10 M point scan written by our writer.
// Peers in the same program: reading the file's bytes only (the I/O floor), and CRC-32C slicing-by-8 against
// the one-byte table loop.
//
//   build/<you>/bench/e57_bench --benchmark_counters_tabular=true
#include <cmath>
#include <filesystem>
#include <fstream>
#include <random>

#include <benchmark/benchmark.h>

#include "lidarshop/io/e57.h"
#include "lidarshop/io/e57_format.h"

namespace lidarshop {
namespace {

const std::string kPumpA = LIDARSHOP_SHARED_DATA_DIR "/e57/pumpA.e57";

std::vector<uint8_t> ReadBytes(const std::string& path) {
  std::ifstream in(path, std::ios::binary);
  return std::vector<uint8_t>(std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>());
}

// SYNTHETIC: a 2700 x 4000 organized scan (10.8 M cells, ~95 % returns: > 10 M points) of a room-sized scene
// with intensity and colour, seed 1.
const Scan& SyntheticScan() {
  static const Scan scan = [] {
    const int rows = 2700, cols = 4000;
    Scan s = MakeScan(rows, cols, true);
    s.name = "synthetic_10M";
    s.grid = UniformGrid(rows, cols, -M_PI + 1e-3, M_PI, -0.9, 1.4);
    s.direction = DirectionsFromGrid(s.grid);
    std::mt19937 rng(1);
    std::uniform_real_distribution<float> u(0.0f, 1.0f);
    for (int r = 0; r < rows; ++r) {
      for (int c = 0; c < cols; ++c) {
        if (u(rng) < 0.05f) continue;
        const cv::Vec3f d = s.direction.at<cv::Vec3f>(r, c);
        const float range = 2.0f + 30.0f * u(rng);
        s.valid.at<uint8_t>(r, c) = kValid;
        s.point.at<cv::Vec3f>(r, c) = d * range;
        s.range.at<float>(r, c) = range;
        s.intensity.at<float>(r, c) = u(rng);
        s.color.at<cv::Vec3b>(r, c) = cv::Vec3b(rng() & 255, rng() & 255, rng() & 255);
      }
    }
    return s;
  }();
  return scan;
}

std::string SyntheticPath(bool scaled) {
  static std::string paths[2];
  std::string& path = paths[scaled];
  if (path.empty()) {
    path = (std::filesystem::temp_directory_path() /
            (scaled ? "lidarshop_e57_bench_scaled.e57" : "lidarshop_e57_bench_float.e57"))
               .string();
    E57WriteOptions options;
    options.coordinate_scale_m = scaled ? 1e-4 : 0.0;
    WriteE57(path, {SyntheticScan()}, options);
  }
  return path;
}

void ReportRates(benchmark::State& state, int64_t bytes, int64_t points) {
  state.SetBytesProcessed(state.iterations() * bytes);
  state.SetItemsProcessed(state.iterations() * points);
  state.counters["file_MB"] = bytes / 1e6;
  state.counters["points"] = static_cast<double>(points);
}

void BM_ReadPumpA(benchmark::State& state) {
  const int64_t bytes = static_cast<int64_t>(std::filesystem::file_size(kPumpA));
  int64_t points = 0;
  for (auto _ : state) {
    E57File f = ReadE57(kPumpA);
    points = f.scans[0].CountValid();
    benchmark::DoNotOptimize(f);
  }
  ReportRates(state, bytes, points);
}
BENCHMARK(BM_ReadPumpA)->Unit(benchmark::kMillisecond);

void BM_ReadSynthetic10M(benchmark::State& state) {
  const std::string path = SyntheticPath(state.range(0) != 0);
  const int64_t bytes = static_cast<int64_t>(std::filesystem::file_size(path));
  int64_t points = 0;
  for (auto _ : state) {
    E57File f = ReadE57(path);
    points = f.scans[0].CountValid();
    benchmark::DoNotOptimize(f);
  }
  ReportRates(state, bytes, points);
}
// Arg 0: float coordinates; 1: scaled integers at 0.1 mm.
BENCHMARK(BM_ReadSynthetic10M)->Arg(0)->Arg(1)->Unit(benchmark::kMillisecond)->Iterations(2);

void BM_WriteSynthetic10M(benchmark::State& state) {
  const Scan& scan = SyntheticScan();
  E57WriteOptions options;
  options.coordinate_scale_m = state.range(0) ? 1e-4 : 0.0;
  int64_t bytes = 0;
  for (auto _ : state) {
    const std::vector<uint8_t> out = EncodeE57({scan}, options);
    bytes = static_cast<int64_t>(out.size());
    benchmark::DoNotOptimize(out.data());
  }
  ReportRates(state, bytes, scan.CountValid());
}
BENCHMARK(BM_WriteSynthetic10M)->Arg(0)->Arg(1)->Unit(benchmark::kMillisecond)->Iterations(2);

// Peer: the I/O floor, reading the synthetic file's bytes only.
void BM_ReadBytesOnly10M(benchmark::State& state) {
  const std::string path = SyntheticPath(false);
  const int64_t bytes = static_cast<int64_t>(std::filesystem::file_size(path));
  for (auto _ : state) {
    std::vector<uint8_t> b(bytes);
    std::ifstream in(path, std::ios::binary);
    in.read(reinterpret_cast<char*>(b.data()), bytes);
    benchmark::DoNotOptimize(b.data());
  }
  ReportRates(state, bytes, SyntheticScan().CountValid());
}
BENCHMARK(BM_ReadBytesOnly10M)->Unit(benchmark::kMillisecond)->Iterations(3);

// CRC-32C over 1020-byte pages: slicing-by-8 (ours) against the one-byte table loop.
void BM_Crc32cSlicing8(benchmark::State& state) {
  const std::vector<uint8_t> bytes = ReadBytes(kPumpA);
  for (auto _ : state) {
    uint32_t sum = 0;
    for (size_t p = 0; p + 1024 <= bytes.size(); p += 1024) sum ^= e57::Crc32c(bytes.data() + p, 1020);
    benchmark::DoNotOptimize(sum);
  }
  state.SetBytesProcessed(state.iterations() * static_cast<int64_t>(bytes.size()));
}
BENCHMARK(BM_Crc32cSlicing8);

void BM_Crc32cBytewise(benchmark::State& state) {
  const std::vector<uint8_t> bytes = ReadBytes(kPumpA);
  uint32_t table[256];
  for (uint32_t b = 0; b < 256; ++b) {
    uint32_t c = b;
    for (int k = 0; k < 8; ++k) c = (c & 1) ? (c >> 1) ^ 0x82F63B78u : c >> 1;
    table[b] = c;
  }
  for (auto _ : state) {
    uint32_t sum = 0;
    for (size_t p = 0; p + 1024 <= bytes.size(); p += 1024) {
      uint32_t crc = 0xFFFFFFFFu;
      for (size_t i = p; i < p + 1020; ++i) crc = table[(crc ^ bytes[i]) & 0xFF] ^ (crc >> 8);
      sum ^= crc;
    }
    benchmark::DoNotOptimize(sum);
  }
  state.SetBytesProcessed(state.iterations() * static_cast<int64_t>(bytes.size()));
}
BENCHMARK(BM_Crc32cBytewise);

}  // namespace
}  // namespace lidarshop

BENCHMARK_MAIN();
