// The 6-vector the optimizers search over, and the objective they maximise. For poses it is
// [x, y, z, roll, pitch, yaw] in metres and radians (pose.h), but the optimizers know nothing
// about poses.
#pragma once

#include <functional>

#include <Eigen/Core>

namespace cube_scan_matcher {

using Vector6d = Eigen::Matrix<double, 6, 1>;

/// A function to maximise over R^6.
using Objective6 = std::function<double(const Vector6d&)>;

}  // namespace cube_scan_matcher
