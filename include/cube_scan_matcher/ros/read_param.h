// Reading one ROS parameter with a range check: shared by every node and nodelet of the
// package, without the matcher's settings.
#pragma once

#include <algorithm>
#include <sstream>
#include <stdexcept>
#include <string>
#include <vector>

#include <ros/node_handle.h>

namespace cube_scan_matcher {

/// A parameter out of range or of the wrong type; what() names it.
class ParamError : public std::invalid_argument {
 public:
  using std::invalid_argument::invalid_argument;
};

/// Reads ~name (default `value`) and checks lo <= value <= hi; throws ParamError naming the
/// parameter, its value, the range and `unit`. Shared by every node of the package.
template <typename T>
T readParam(const ros::NodeHandle& pnh, const std::string& name, T value, T lo, T hi,
            const std::string& unit = "") {
  if (pnh.hasParam(name) && !pnh.getParam(name, value)) {
    throw ParamError("parameter ~" + name + " has the wrong type (expected a number)");
  }
  if (!(value >= lo && value <= hi)) {  // also false for NaN
    std::ostringstream os;
    os << "parameter ~" << name << " = " << value << " is out of range [" << lo << ", " << hi
       << "]" << (unit.empty() ? "" : " " + unit);
    throw ParamError(os.str());
  }
  return value;
}

/// Levenshtein distance between two names (insertions, deletions, substitutions).
inline std::size_t editDistance(const std::string& a, const std::string& b) {
  std::vector<std::size_t> row(b.size() + 1);
  for (std::size_t j = 0; j <= b.size(); ++j) row[j] = j;
  for (std::size_t i = 1; i <= a.size(); ++i) {
    std::size_t diagonal = row[0];
    row[0] = i;
    for (std::size_t j = 1; j <= b.size(); ++j) {
      const std::size_t up = row[j];
      row[j] = std::min({row[j] + 1, row[j - 1] + 1, diagonal + (a[i - 1] == b[j - 1] ? 0 : 1)});
      diagonal = up;
    }
  }
  return row[b.size()];
}

/// One warning text per name in `present` that is not in `known`: a misspelt parameter would
/// otherwise be ignored without a word. The closest known name is suggested when it is within
/// a quarter of the name's length (at least 2 edits).
inline std::vector<std::string> unknownParamWarnings(const std::vector<std::string>& present,
                                                     const std::vector<std::string>& known) {
  std::vector<std::string> warnings;
  for (const std::string& name : present) {
    if (std::find(known.begin(), known.end(), name) != known.end()) continue;
    std::string closest;
    std::size_t best = std::max<std::size_t>(2, name.size() / 4) + 1;
    for (const std::string& k : known) {
      const std::size_t d = editDistance(name, k);
      if (d < best) best = d, closest = k;
    }
    warnings.push_back("~" + name + " is not a parameter of this nodelet and is ignored" +
                       (closest.empty() ? std::string(" (docs/parameters.md lists them)")
                                        : " (did you mean ~" + closest + "?)"));
  }
  return warnings;
}

/// The top-level names set on the parameter server under `pnh`'s namespace ("~a/b" gives "a").
inline std::vector<std::string> privateParamNames(const ros::NodeHandle& pnh) {
  std::vector<std::string> all, names;
  if (!pnh.getParamNames(all)) return names;
  const std::string prefix = pnh.getNamespace() + "/";
  for (const std::string& n : all) {
    if (n.compare(0, prefix.size(), prefix) != 0) continue;
    const std::string name = n.substr(prefix.size(), n.find('/', prefix.size()) - prefix.size());
    if (!name.empty() && std::find(names.begin(), names.end(), name) == names.end()) {
      names.push_back(name);
    }
  }
  return names;
}

/// unknownParamWarnings for the names set under `pnh`, joined with "; " ("" = none): what a
/// nodelet logs at start and keeps in its diagnostics.
inline std::string unknownParamReport(const ros::NodeHandle& pnh,
                                      const std::vector<std::string>& known) {
  std::string report;
  for (const std::string& w : unknownParamWarnings(privateParamNames(pnh), known)) {
    report += (report.empty() ? "" : "; ") + w;
  }
  return report;
}

}  // namespace cube_scan_matcher
