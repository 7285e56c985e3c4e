// FILE#N on the command line: scan N of a file of several (a site's stations, docs/stations.md).
//
// ReadScanFileAndWarn (commands.h) takes FILE#N: the file then holds scan N alone (so --scan 0, the default,
// picks it), an N out of range is an OptionsError, and FILE is protected from every output. Every command
// that reads scans reads them there, so each takes FILE#N as well as --scan N. common.cc.
#pragma once

#include <string>

namespace lidarshop::cli {

// A scan file argument "FILE#N" (FILE.e57#2: scan 2, from 0) split into FILE and N; index -1 when `path` has
// no such suffix or names an existing file as given (a file may have '#' in its name).
struct ScanSelector {
  std::string path;
  int index = -1;
};
ScanSelector SplitScanSelector(const std::string& path);

// Where a station read from `input` goes in an output folder (register of a site, clean): its file's name, or
// for FILE#N (scan N of a site's file) FILE's stem + _N + its extension.
std::string StationOutputName(const std::string& input);

}  // namespace lidarshop::cli
