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

/// One line of a TUM trajectory: "stamp tx ty tz qx qy qz qw" (seconds, metres, Hamilton).
struct StampedPose {
  double stamp = 0.0;
  Eigen::Isometry3d pose = Eigen::Isometry3d::Identity();
};
/// Reads a TUM trajectory file ('#' comments and blank lines skipped). Throws
/// std::runtime_error naming the file and line on a bad line, a non-unit quaternion or stamps
/// that do not increase.
std::vector<StampedPose> readTum(const std::string& file);
std::vector<StampedPose> parseTum(std::istream& in, const std::string& file);

/// A sequence folder: the clouds (*.pcd, *.ply, sorted by name: time order) and DIR/poses.tum
/// with one pose per cloud, in the same order. Throws std::runtime_error when the counts differ.
struct Sequence {
  std::vector<std::string> clouds;
  std::vector<StampedPose> truth;
};
Sequence readSequence(const std::string& dir);

}  // namespace cube_scan_matcher::io
