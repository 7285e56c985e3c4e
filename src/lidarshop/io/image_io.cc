#include "lidarshop/io/image_io.h"

#include <unistd.h>

#include <algorithm>
#include <cctype>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <functional>
#include <mutex>

#include <fmt/format.h>
#include <opencv2/imgcodecs.hpp>
#include <opencv2/imgproc.hpp>

#include "lidarshop/io/scan_io.h"
#include "lidarshop/util/atomic_file.h"
#include "lidarshop/util/error.h"
#include "lidarshop/util/input_file.h"
#include "lidarshop/util/memory_budget.h"
#include "lidarshop/util/plugin.h"

namespace lidarshop {

cv::Mat CvImRead(const std::string& path, int flags) {
  static const auto read = OpenCvPluginFunction<void(const std::string*, int, cv::Mat*)>("lidarshop_imread");
  cv::Mat image;
  read(&path, flags, &image);
  return image;
}

cv::Mat CvImDecode(const cv::Mat& bytes, int flags) {
  static const auto decode = OpenCvPluginFunction<void(const cv::Mat*, int, cv::Mat*)>("lidarshop_imdecode");
  cv::Mat image;
  decode(&bytes, flags, &image);
  return image;
}

bool CvImWrite(const std::string& path, const cv::Mat& image) {
  static const auto write =
      OpenCvPluginFunction<bool(const std::string*, const cv::Mat*)>("lidarshop_imwrite");
  return write(&path, &image);
}

bool CvImEncode(const std::string& extension, const cv::Mat& image, std::vector<uchar>* bytes) {
  static const auto encode =
      OpenCvPluginFunction<bool(const std::string*, const cv::Mat*, std::vector<uchar>*)>(
          "lidarshop_imencode");
  return encode(&extension, &image, bytes);
}
namespace {

// OpenCV's BGR(A) <-> lidarshop's RGB(A); the conversion is its own inverse.
cv::Mat SwapRedBlue(const cv::Mat& image) {
  cv::Mat swapped;
  if (image.channels() == 3) {
    cv::cvtColor(image, swapped, cv::COLOR_BGR2RGB);
  } else if (image.channels() == 4) {
    cv::cvtColor(image, swapped, cv::COLOR_BGRA2RGBA);
  } else {
    swapped = image;
  }
  return swapped;
}

// Bounds-checked big/little-endian loads from the encoded bytes; `at` past the end throws "truncated".
struct Bytes {
  const uint8_t* data;
  size_t size;
  const std::string& what;
  const char* format;

  void Need(uint64_t at, uint64_t count) const {
    if (at > size || count > size - at) {
      ThrowInputError(what, fmt::format("byte {}", at), format, "the image header is truncated");
    }
  }
  uint64_t Load(uint64_t at, int count, bool little) const {
    Need(at, count);
    uint64_t v = 0;
    for (int i = 0; i < count; ++i) {
      v |= static_cast<uint64_t>(data[at + i]) << (8 * (little ? i : count - 1 - i));
    }
    return v;
  }
  uint64_t Be(uint64_t at, int count) const { return Load(at, count, false); }
  uint64_t Le(uint64_t at, int count) const { return Load(at, count, true); }
  bool Starts(std::initializer_list<uint8_t> magic) const {
    return size >= magic.size() && std::equal(magic.begin(), magic.end(), data);
  }
};

void ReadPngHeader(const Bytes& b, ImageHeader* h) {
  if (b.Be(8, 4) != 13 || b.Be(12, 4) != 0x49484452) {  // "IHDR"
    ThrowInputError(b.what, "byte 8", "IHDR", "a PNG must start with its IHDR chunk");
  }
  h->width = static_cast<int64_t>(b.Be(16, 4));
  h->height = static_cast<int64_t>(b.Be(20, 4));
  const int depth = static_cast<int>(b.Be(24, 1)), colour = static_cast<int>(b.Be(25, 1));
  h->channels = colour == 0 ? 1 : colour == 4 ? 2 : colour == 6 ? 4 : 3;
  h->bytes_per_channel = depth == 16 ? 2 : 1;
  // libpng reports a truncated file on stderr itself before OpenCV fails, which would make two lines of one
  // error: a PNG must end with its IEND chunk.
  static const uint8_t kEnd[] = {'I', 'E', 'N', 'D', 0xae, 0x42, 0x60, 0x82};
  if (b.size < 57 || std::memcmp(b.data + b.size - 8, kEnd, 8) != 0) {
    ThrowInputError(b.what, "", "", "a truncated PNG (the file does not end with the IEND chunk)");
  }
}

void ReadJpegHeader(const Bytes& b, ImageHeader* h) {
  uint64_t at = 2;
  while (true) {
    if (b.Be(at, 1) != 0xff) {
      ThrowInputError(b.what, fmt::format("byte {}", at), "JPEG", "not a marker where one must start");
    }
    while (b.Be(at, 1) == 0xff) ++at;  // fill bytes
    const uint64_t marker = b.Be(at, 1);
    ++at;
    if (marker == 0x01 || (marker >= 0xd0 && marker <= 0xd8)) continue;  // no length
    if (marker == 0xd9 || marker == 0xda) {
      ThrowInputError(b.what, fmt::format("byte {}", at - 1), "JPEG",
                      "no frame header (SOF) before the data");
    }
    const uint64_t length = b.Be(at, 2);
    if (length < 2)
      ThrowInputError(b.what, fmt::format("byte {}", at), "JPEG", "a segment shorter than 2 bytes");
    if (marker >= 0xc0 && marker <= 0xcf && marker != 0xc4 && marker != 0xc8 && marker != 0xcc) {
      h->bytes_per_channel = b.Be(at + 2, 1) > 8 ? 2 : 1;
      h->height = static_cast<int64_t>(b.Be(at + 3, 2));
      h->width = static_cast<int64_t>(b.Be(at + 5, 2));
      h->channels = static_cast<int>(b.Be(at + 7, 1));
      return;
    }
    at += length;
  }
}

void ReadBmpHeader(const Bytes& b, ImageHeader* h) {
  const uint64_t info = b.Le(14, 4);
  if (info == 12) {  // OS/2 BITMAPCOREHEADER
    h->width = static_cast<int64_t>(b.Le(18, 2));
    h->height = static_cast<int64_t>(b.Le(20, 2));
    h->channels = b.Le(24, 2) == 32 ? 4 : 3;
  } else {
    h->width = static_cast<int32_t>(b.Le(18, 4));
    h->height = std::abs(static_cast<int64_t>(static_cast<int32_t>(b.Le(22, 4))));  // < 0: top-down rows
    h->channels = b.Le(28, 2) == 32 ? 4 : 3;
  }
}

// TIFF (classic, and BigTIFF with 8-byte offsets): the first IFD's ImageWidth, ImageLength, BitsPerSample and
// SamplesPerPixel.
void ReadTiffHeader(const Bytes& b, ImageHeader* h) {
  const bool little = b.data[0] == 'I';
  const bool big = b.Load(2, 2, little) == 43;
  const int offset_bytes = big ? 8 : 4, entry_bytes = big ? 20 : 12;
  const uint64_t ifd = b.Load(big ? 8 : 4, offset_bytes, little);
  const uint64_t entries = b.Load(ifd, big ? 8 : 2, little);
  const uint64_t first = ifd + (big ? 8 : 2);
  b.Need(first, std::min<uint64_t>(entries, b.size) * entry_bytes);
  int64_t bits = 8;
  h->channels = 1;
  for (uint64_t i = 0; i < entries; ++i) {
    const uint64_t entry = first + i * entry_bytes;
    const uint64_t tag = b.Load(entry, 2, little), type = b.Load(entry + 2, 2, little);
    const uint64_t count = b.Load(entry + 4, big ? 8 : 4, little);
    const int size = type == 3 ? 2 : type == 4 ? 4 : type == 16 ? 8 : 0;  // SHORT, LONG, LONG8
    if (size == 0 || count == 0 || (tag != 256 && tag != 257 && tag != 258 && tag != 277)) continue;
    const uint64_t value_at = entry + 4 + offset_bytes;
    // A value longer than the field is stored at an offset (BitsPerSample of an RGB image).
    const uint64_t at = count <= static_cast<uint64_t>(offset_bytes / size)
                            ? value_at
                            : b.Load(value_at, offset_bytes, little);
    const int64_t value = static_cast<int64_t>(std::min<uint64_t>(b.Load(at, size, little), INT64_MAX));
    if (tag == 256) h->width = value;
    if (tag == 257) h->height = value;
    if (tag == 258) bits = value;
    if (tag == 277) h->channels = static_cast<int>(std::clamp<int64_t>(value, 1, 64));
  }
  h->bytes_per_channel = static_cast<int>(std::clamp<int64_t>((bits + 7) / 8, 1, 8));
}

// OpenEXR: the attributes of the (first part's) header up to the empty name that ends it.
void ReadExrHeader(const Bytes& b, ImageHeader* h) {
  h->bytes_per_channel = 4;  // OpenCV decodes half and float channels as float
  auto text = [&](uint64_t* at) {
    b.Need(*at, 1);
    const auto* end = static_cast<const uint8_t*>(std::memchr(b.data + *at, 0, b.size - *at));
    if (end == nullptr)
      ThrowInputError(b.what, fmt::format("byte {}", *at), "exr", "the header is truncated");
    std::string s(reinterpret_cast<const char*>(b.data + *at), end - (b.data + *at));
    *at = end - b.data + 1;
    return s;
  };
  bool window = false;
  for (uint64_t at = 8;;) {
    const std::string name = text(&at);
    if (name.empty()) break;
    const std::string type = text(&at);
    const uint64_t size = b.Le(at, 4);
    at += 4;
    b.Need(at, size);
    if (name == "dataWindow" && type == "box2i" && size == 16) {
      const auto corner = [&](int i) {
        return static_cast<int64_t>(static_cast<int32_t>(b.Le(at + 4 * i, 4)));
      };
      h->width = corner(2) - corner(0) + 1;
      h->height = corner(3) - corner(1) + 1;
      window = true;
    } else if (name == "channels" && type == "chlist") {
      h->channels = 0;
      // Each channel: its name, a 0 byte and 16 bytes (pixel type, linear flag, sampling); a 0 byte ends the list.
      for (uint64_t c = at, end = at + size; c < end && b.data[c] != 0; ++h->channels) {
        const void* nul = std::memchr(b.data + c, 0, end - c);
        if (nul == nullptr) break;
        c = static_cast<const uint8_t*>(nul) - b.data + 1 + 16;
      }
    }
    at += size;
  }
  if (!window) ThrowInputError(b.what, "header", "dataWindow", "an OpenEXR header without its dataWindow");
}

// Runs `decode` with the process's stderr (file descriptor 2) sent to a temporary file: libpng and libjpeg
// print warnings and errors there themselves ("libpng error: ...", "Corrupt JPEG data: ..."), which would
// stand beside the one line of our error. Returns what they printed. One decode at a time, as fd 2 is the
// process's: another thread's lines printed meanwhile end up in the returned text too.
std::string QuietDecode(const std::function<void()>& decode) {
  static std::mutex mutex;
  std::lock_guard lock(mutex);
  std::fflush(stderr);
  const int saved = dup(2);
  std::FILE* capture = std::tmpfile();
  if (saved < 0 || capture == nullptr) {  // cannot redirect: decode anyway
    if (saved >= 0) close(saved);
    if (capture != nullptr) std::fclose(capture);
    decode();
    return "";
  }
  dup2(fileno(capture), 2);
  std::string printed;
  auto restore = [&] {
    std::fflush(stderr);
    dup2(saved, 2);
    close(saved);
    std::rewind(capture);
    char buffer[512];
    const size_t n = std::fread(buffer, 1, sizeof(buffer), capture);
    printed.assign(buffer, n);
    std::fclose(capture);
  };
  try {
    decode();
  } catch (...) {
    restore();
    throw;
  }
  restore();
  return printed;
}

// The first line the image libraries printed, as "; libpng: ..." to append to an error, or "".
std::string FirstLine(const std::string& printed) {
  std::string line = printed.substr(0, printed.find('\n'));
  while (!line.empty() && std::isspace(static_cast<unsigned char>(line.back()))) line.pop_back();
  return line.empty() ? "" : "; the decoder said: " + line;
}

// Decodes after the header check; `flags` as cv::imdecode / cv::imread. OpenEXR is read from `path` (OpenCV
// decodes it only from a file), everything else from the bytes already read.
cv::Mat Decode(const uint8_t* data, size_t size, const std::string& what, const std::string& path,
               const ImageHeader& header, int flags) {
  if (header.format == "exr") setenv("OPENCV_IO_ENABLE_OPENEXR", "1", 0);  // OpenCV 4.6: before first use
  cv::Mat image;
  std::string opencv_error;
  const std::string printed = QuietDecode([&] {
    try {
      if (header.format == "exr" && !path.empty()) {
        image = CvImRead(path, flags);
      } else {
        image = CvImDecode(cv::Mat(1, static_cast<int>(size), CV_8U, const_cast<uint8_t*>(data)), flags);
      }
    } catch (const cv::Exception& error) {
      image.release();
      opencv_error = error.err;  // OpenCV's message without its multi-line location banner
    }
  });
  if (image.empty()) {
    ThrowInputError(
        what, "", "",
        fmt::format("not a readable {} image{}{}", header.format,
                    opencv_error.empty() ? "" : " (OpenCV: " + opencv_error + ")", FirstLine(printed)));
  }
  return image;
}

}  // namespace

int64_t ImageHeader::DecodedBytes() const {
  return SaturatingBytes(SaturatingBytes(SaturatingBytes(width, height), channels + 1),
                         int64_t{2} * bytes_per_channel);
}

ImageHeader ReadImageHeader(const uint8_t* data, size_t size, const std::string& what) {
  ImageHeader h;
  Bytes b{data, size, what, ""};
  if (b.Starts({0x89, 'P', 'N', 'G', '\r', '\n', 0x1a, '\n'})) {
    h.format = b.format = "png";
    ReadPngHeader(b, &h);
  } else if (b.Starts({0xff, 0xd8, 0xff})) {
    h.format = b.format = "jpeg";
    ReadJpegHeader(b, &h);
  } else if (b.Starts({'I', 'I', 42, 0}) || b.Starts({'M', 'M', 0, 42}) || b.Starts({'I', 'I', 43, 0}) ||
             b.Starts({'M', 'M', 0, 43})) {
    h.format = b.format = "tiff";
    ReadTiffHeader(b, &h);
  } else if (b.Starts({0x76, 0x2f, 0x31, 0x01})) {
    h.format = b.format = "exr";
    ReadExrHeader(b, &h);
  } else if (b.Starts({'B', 'M'})) {
    h.format = b.format = "bmp";
    ReadBmpHeader(b, &h);
  } else {
    // OpenCV picks a decoder by the content, not the name, and some of its decoders abort on malformed input
    // (gdcm asserts on a broken DICOM): only the formats lidarshop writes and documents reach OpenCV.
    ThrowInputError(what, "byte 0", "signature", "not a PNG, JPEG, TIFF, OpenEXR or BMP image");
  }
  if (h.width <= 0 || h.height <= 0 || h.channels <= 0) {
    ThrowInputError(what, "header", h.format,
                    fmt::format("an image of {} x {} pixels and {} channels", h.width, h.height, h.channels));
  }
  return h;
}

void CheckImageHeader(const ImageHeader& header, const std::string& what, cv::Size expected,
                      const std::string& expected_what) {
  if (!expected.empty() && (header.width != expected.width || header.height != expected.height)) {
    ThrowInputError(what, "", "",
                    fmt::format("the image is {}x{} but {} is {}x{}", header.width, header.height,
                                expected_what, expected.width, expected.height));
  }
  if (header.width > kMaxImagePixels || header.height > kMaxImagePixels ||
      header.width * header.height > kMaxImagePixels) {
    ThrowInputError(what, "header", header.format,
                    fmt::format("an image of {} x {} pixels: more than the {} pixels lidarshop decodes",
                                header.width, header.height, kMaxImagePixels));
  }
  CheckMemoryBudget(header.DecodedBytes(),
                    fmt::format("{}: a {} x {} {} image", what, header.width, header.height, header.format));
}

cv::Mat ReadImage(const std::string& path, cv::Size expected, const std::string& expected_what) {
  const std::string bytes = ReadRegularFile(path);
  const auto* data = reinterpret_cast<const uint8_t*>(bytes.data());
  const ImageHeader header = ReadImageHeader(data, bytes.size(), path);
  CheckImageHeader(header, path, expected, expected_what);
  if (bytes.size() > static_cast<size_t>(INT32_MAX))
    ThrowInputError(path, "", "", "an image file past 2 GiB");
  return SwapRedBlue(Decode(data, bytes.size(), path, path, header, cv::IMREAD_UNCHANGED));
}

cv::Mat ReadImage(const std::string& path) { return ReadImage(path, {}, ""); }

void WriteImage(const std::string& path, const cv::Mat& image) {
  if (image.empty()) ThrowInputError(path, "", "", "cannot write an empty image");
  const std::string extension = FileExtension(path);
  if (extension == "exr") setenv("OPENCV_IO_ENABLE_OPENEXR", "1", 0);
  if ((extension == "jpg" || extension == "jpeg") && image.depth() != CV_8U) {
    ThrowInputError(path, "", "", "JPEG holds 8-bit images only; use .png (16-bit) or .exr (float)");
  }
  if (extension == "png" && image.depth() != CV_8U && image.depth() != CV_16U) {
    ThrowInputError(path, "", "", "PNG holds 8- or 16-bit images only; use .exr or .tif for float images");
  }
  const cv::Mat bgr = SwapRedBlue(image);
  WritePathAtomically(path, [&](const std::string& temporary) {
    try {
      return CvImWrite(temporary, bgr);
    } catch (const cv::Exception& error) {
      ThrowInputError(path, "", "", fmt::format("cannot write the image ({})", error.what()));
    }
  });
}

cv::Mat DecodeImage(const uint8_t* data, size_t size, const std::string& what, bool color) {
  if (size == 0) ThrowInputError(what, "", "", "empty image data");
  ImageHeader header = ReadImageHeader(data, size, what);
  if (color) header.channels = std::max(header.channels, 3);
  CheckImageHeader(header, what);
  if (size > static_cast<size_t>(INT32_MAX)) ThrowInputError(what, "", "", "an image past 2 GiB");
  const cv::Mat image = Decode(data, size, what, "", header, color ? cv::IMREAD_COLOR : cv::IMREAD_UNCHANGED);
  return SwapRedBlue(image);
}

cv::Mat DecodeImage(const std::vector<uint8_t>& bytes, const std::string& what) {
  return DecodeImage(bytes.data(), bytes.size(), what);
}

cv::Mat ReadMask(const std::string& path, cv::Size expected, const std::string& what) {
  cv::Mat mask = ReadImage(path, expected, what);
  if (mask.depth() != CV_8U) ThrowInputError(path, "", "", "a mask must be an 8-bit image");
  if (mask.channels() > 1) {
    std::vector<cv::Mat> planes;
    cv::split(mask, planes);
    mask = planes[0];
    for (size_t c = 1; c < std::min<size_t>(planes.size(), 3); ++c) cv::max(mask, planes[c], mask);
  }
  cv::Mat binary;
  cv::threshold(mask, binary, 127, 255, cv::THRESH_BINARY);
  return binary;
}

}  // namespace lidarshop
