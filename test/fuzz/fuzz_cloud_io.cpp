// libFuzzer harness: the PCD/PLY reader on arbitrary bytes. The first byte picks the format.
// A CloudFileError is the expected answer to a bad file; anything else (a crash, a sanitizer
// report, another exception, a hang) is a bug.
#include <cstddef>
#include <cstdint>
#include <string>

#include "cube_scan_matcher/io/cloud_io.h"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  if (size == 0) return 0;
  const std::string name = data[0] & 1 ? "fuzz.ply" : "fuzz.pcd";
  const std::string bytes(reinterpret_cast<const char*>(data + 1), size - 1);
  cube_scan_matcher::io::CloudReadLimits limits;
  limits.max_points = 1 << 20;  // keep each input's work small
  try {
    cube_scan_matcher::io::parseCloud(name, bytes, limits);
  } catch (const cube_scan_matcher::io::CloudFileError&) {
  }
  return 0;
}
