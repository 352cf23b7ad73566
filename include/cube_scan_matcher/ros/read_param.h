// Reading one ROS parameter with a range check: shared by every node and nodelet of the
// package, without the matcher's settings.
#pragma once

#include <sstream>
#include <stdexcept>
#include <string>

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

}  // namespace cube_scan_matcher
