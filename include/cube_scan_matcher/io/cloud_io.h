// PCD and PLY reading for the ROS-free tools, with a bounds check on everything a file declares
// (no PCL: a corrupt or lying file gets a one-line error, never a crash or a huge allocation).
//
// Supported: PCD v0.7 (and headers without VERSION) with DATA ascii, binary or
// binary_compressed (LZF); PLY 1.0 ascii, binary_little_endian and binary_big_endian. Only the
// x, y, z fields are read (float or double; other fields are skipped by their declared size).
#pragma once

#include <cstddef>
#include <stdexcept>
#include <string>

#include "cube_scan_matcher/core/point_array.h"

namespace cube_scan_matcher::io {

/// A file that cannot be read as a cloud; what() is "NAME: problem" on one line.
class CloudFileError : public std::runtime_error {
 public:
  using std::runtime_error::runtime_error;
};

/// Limits on what a file may declare (they bound the memory a file can make the reader take).
struct CloudReadLimits {
  std::size_t max_points = 100000000;    ///< declared points, > 0.
  double max_abs_coordinate = 1e6;       ///< [m]; a larger finite coordinate is an error.
  std::size_t max_header_bytes = 65536;  ///< header length before DATA / end_header.
};

/// Reads every point's x, y, z [m] of a .pcd or .ply file (by extension, case-insensitive).
/// Non-finite points are kept (filter them later). Throws CloudFileError naming the file and
/// the problem: missing, a directory, unreadable, empty, unknown extension, bad header,
/// declared sizes that disagree with the file's length, no x/y/z field, no point, no finite
/// point, or a coordinate beyond limits.max_abs_coordinate.
PointArray readCloudFile(const std::string& path, const CloudReadLimits& limits = {});

/// The same on bytes in memory; `name` labels the messages and its extension picks the format.
PointArray parseCloud(const std::string& name, const std::string& bytes,
                      const CloudReadLimits& limits = {});

}  // namespace cube_scan_matcher::io
