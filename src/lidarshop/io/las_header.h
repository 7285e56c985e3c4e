// The LAS public header block and its variable length records, parsed and checked (internal to the io
// module): what ReadLas reads the points with and what `info` prints of a LAS or LAZ file.
#pragma once

#include <cstdint>
#include <string>
#include <vector>

#include "lidarshop/scan/scan.h"

namespace lidarshop::las {

struct LasHeader {
  int minor_version = 0;
  int header_size = 0;
  int64_t offset_to_points = 0;
  int format = 0;
  int record_length = 0;
  int64_t count = 0;
  // LAZ: the point format byte has LASzip's bits; the points are decoded with the laszip VLR's payload.
  bool laz = false;
  std::string laszip_payload;
  double scale[3] = {1, 1, 1};
  double offset[3] = {0, 0, 0};
  uint16_t global_encoding = 0;
  uint16_t file_source_id = 0;
  std::vector<SourceRecord> records;  // VLRs and EVLRs, in file order
  std::vector<std::string> warnings;
};

// Parses and checks the header and the records. `bytes` holds the file or (header readers) its start up to the
// point data; `file_size` is the whole file's size (-1: bytes.size()). LAS 1.4's extended records are read only
// from a whole file. Throws InputError naming the file, the header byte and the field.
LasHeader ParseHeader(const std::string& bytes, const std::string& file, int64_t file_size = -1);

// The start of the file `path` (of `file_size` bytes) up to its point data: the header and the variable length
// records, what ParseHeader needs of a file not read whole.
std::string ReadHeaderPrefix(const std::string& path, int64_t file_size);
// LAS 1.4's extended records of a file parsed from its prefix (`prefix`): read from the file's tail into
// header->records (warnings for those that do not fit). Throws InputError when the file cannot be read.
void ReadExtendedRecordsFromFile(const std::string& path, int64_t file_size, const std::string& prefix,
                                 LasHeader* header);

}  // namespace lidarshop::las
