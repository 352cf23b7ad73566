// libFuzzer harness: the dataset (pairs.txt), TUM trajectory (poses.tum) and pose-line parsers
// and the number parser on arbitrary text. std::runtime_error and std::invalid_argument are their documented answers.
#include <cstddef>
#include <cstdint>
#include <sstream>
#include <stdexcept>
#include <string>

#include "cube_scan_matcher/io/dataset.h"

using namespace cube_scan_matcher::io;

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  const std::string text(reinterpret_cast<const char*>(data), size);
  try {
    std::istringstream in(text);
    parsePairs(in, "pairs.txt", "dir");
  } catch (const std::runtime_error&) {
  }
  try {
    std::istringstream in(text);
    for (const StampedPose& p : parseTum(in, "poses.tum")) {
      if (!p.pose.matrix().allFinite()) __builtin_trap();  // parseTum rejects non-finite lines
    }
  } catch (const std::runtime_error&) {
  }
  {
    std::istringstream in(text);
    Eigen::Isometry3d T;
    double norm = 0.0;
    while (readPose(in, T, &norm)) {
    }
  }
  try {
    parseNumber("--fuzz", text);
  } catch (const std::invalid_argument&) {
  }
  return 0;
}
