#include "cube_scan_matcher/io/dataset.h"

#include <algorithm>
#include <cmath>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <sstream>
#include <stdexcept>

namespace cube_scan_matcher::io {

double parseNumber(const std::string& what, const std::string& text) {
  char* end = nullptr;
  const double v = std::strtod(text.c_str(), &end);
  if (text.empty() || *end != '\0') {
    throw std::invalid_argument(what + ": '" + text + "' is not a number");
  }
  return v;
}

bool readPose(std::istream& in, Eigen::Isometry3d& T, double* quaternion_norm) {
  double t[3], q[4];
  if (!(in >> t[0] >> t[1] >> t[2] >> q[0] >> q[1] >> q[2] >> q[3])) return false;
  const Eigen::Quaterniond quat(q[3], q[0], q[1], q[2]);
  if (quaternion_norm) *quaternion_norm = quat.norm();
  T = Eigen::Isometry3d::Identity();
  T.linear() = quat.normalized().toRotationMatrix();
  T.translation() = Eigen::Vector3d(t[0], t[1], t[2]);
  return true;
}

std::vector<PairEntry> readPairs(const std::string& dir) {
  const std::string file = dir + "/pairs.txt";
  std::ifstream in(file);
  if (!in) throw std::runtime_error(file + ": cannot open (is " + dir + " a dataset folder?)");
  return parsePairs(in, file, dir);
}

std::vector<PairEntry> parsePairs(std::istream& in, const std::string& file,
                                  const std::string& dir) {
  std::vector<PairEntry> pairs;
  std::string line;
  for (int no = 1; std::getline(in, line); ++no) {
    if (line.find_first_not_of(" \t\r") == std::string::npos || line[0] == '#') continue;
    std::istringstream ls(line);
    PairEntry e;
    double norm = 1.0;
    if (!(ls >> e.source >> e.target) || !readPose(ls, e.T_target_source, &norm)) {
      throw std::runtime_error(file + ":" + std::to_string(no) +
                               ": expected 'source target tx ty tz qx qy qz qw'");
    }
    if (std::abs(norm - 1.0) > 1e-3) {
      throw std::runtime_error(file + ":" + std::to_string(no) + ": quaternion is not unit");
    }
    e.name = e.source + "->" + e.target;
    e.source = dir + "/" + e.source;
    e.target = dir + "/" + e.target;
    pairs.push_back(e);
  }
  if (pairs.empty()) throw std::runtime_error(file + ": no pairs");
  return pairs;
}

std::vector<StampedPose> readTum(const std::string& file) {
  std::ifstream in(file);
  if (!in) throw std::runtime_error(file + ": cannot open");
  return parseTum(in, file);
}

std::vector<StampedPose> parseTum(std::istream& in, const std::string& file) {
  std::vector<StampedPose> poses;
  std::string line;
  for (int no = 1; std::getline(in, line); ++no) {
    if (line.find_first_not_of(" \t\r") == std::string::npos || line[0] == '#') continue;
    std::istringstream ls(line);
    StampedPose p;
    double norm = 1.0;
    const std::string where = file + ":" + std::to_string(no) + ": ";
    if (!(ls >> p.stamp) || !std::isfinite(p.stamp) || !readPose(ls, p.pose, &norm)) {
      throw std::runtime_error(where + "expected 'stamp tx ty tz qx qy qz qw'");
    }
    if (std::abs(norm - 1.0) > 1e-3) throw std::runtime_error(where + "quaternion is not unit");
    if (!p.pose.matrix().allFinite()) throw std::runtime_error(where + "pose is not finite");
    if (!poses.empty() && !(p.stamp > poses.back().stamp)) {
      throw std::runtime_error(where + "stamps must increase");
    }
    poses.push_back(p);
  }
  if (poses.empty()) throw std::runtime_error(file + ": no poses");
  return poses;
}

Sequence readSequence(const std::string& dir) {
  namespace fs = std::filesystem;
  Sequence s;
  std::error_code ec;
  if (!fs::is_directory(dir, ec)) throw std::runtime_error(dir + ": not a folder");
  for (const auto& e : fs::directory_iterator(dir)) {
    const std::string ext = e.path().extension().string();
    if (e.is_regular_file() && (ext == ".pcd" || ext == ".ply")) s.clouds.push_back(e.path().string());
  }
  std::sort(s.clouds.begin(), s.clouds.end());
  s.truth = readTum(dir + "/poses.tum");
  if (s.clouds.size() != s.truth.size()) {
    throw std::runtime_error(dir + ": " + std::to_string(s.clouds.size()) + " clouds but " +
                             std::to_string(s.truth.size()) + " poses in poses.tum");
  }
  return s;
}

}  // namespace cube_scan_matcher::io
