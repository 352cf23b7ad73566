// Dataset folders in the format of shared/data/README.md: pairs.txt lines
//   source.pcd target.pcd tx ty tz qx qy qz qw      (T_target_source, metres, Hamilton)
#pragma once

#include <istream>
#include <string>
#include <vector>

#include <Eigen/Geometry>

namespace cube_scan_matcher::io {

struct PairEntry {
  std::string source;  ///< newer scan (path joined with the folder)
  std::string target;  ///< reference scan
  Eigen::Isometry3d T_target_source = Eigen::Isometry3d::Identity();
  std::string name;    ///< "source->target" file names
};

/// Reads "tx ty tz qx qy qz qw" (metres, Hamilton quaternion) from `in` into T (the quaternion
/// normalised). Returns false if the seven numbers are not there; `quaternion_norm`, if given,
/// receives the norm before normalising.
bool readPose(std::istream& in, Eigen::Isometry3d& T, double* quaternion_norm = nullptr);

/// Reads a number or throws std::invalid_argument naming `what` (an option or a field).
double parseNumber(const std::string& what, const std::string& text);

/// Reads DIR/pairs.txt. Throws std::runtime_error naming the file and line on bad input.
std::vector<PairEntry> readPairs(const std::string& dir);
/// The same from a stream: `file` labels the messages, `dir` is joined to the cloud names.
std::vector<PairEntry> parsePairs(std::istream& in, const std::string& file,
                                  const std::string& dir);

}  // namespace cube_scan_matcher::io
