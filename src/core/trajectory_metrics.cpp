#include "cube_scan_matcher/core/trajectory_metrics.h"

#include <algorithm>
#include <cmath>
#include <stdexcept>

#include <Eigen/Cholesky>

#include "cube_scan_matcher/core/pose.h"

namespace cube_scan_matcher {
namespace {

void requireSameLength(const Trajectory& truth, const Trajectory& estimate) {
  if (truth.size() != estimate.size()) {
    throw std::invalid_argument("the truth has " + std::to_string(truth.size()) +
                                " poses, the estimate " + std::to_string(estimate.size()));
  }
}

double angleOf(const Eigen::Isometry3d& T) { return Eigen::AngleAxisd(T.linear()).angle(); }

}  // namespace

std::vector<double> pathLengths(const Trajectory& truth) {
  std::vector<double> d(truth.size(), 0.0);
  for (std::size_t i = 1; i < truth.size(); ++i) {
    d[i] = d[i - 1] + (truth[i].translation() - truth[i - 1].translation()).norm();
  }
  return d;
}

RelativeError relativePoseError(const Trajectory& truth, const Trajectory& estimate, double length) {
  requireSameLength(truth, estimate);
  const std::vector<double> d = pathLengths(truth);
  RelativeError r;
  r.length = length;
  std::size_t j = 0;
  for (std::size_t i = 0; i < truth.size(); ++i) {
    j = std::max(j, i);
    while (j < truth.size() && d[j] - d[i] < length) ++j;
    if (j == truth.size()) break;
    const double travelled = d[j] - d[i];
    const Eigen::Isometry3d E =
        (truth[i].inverse() * truth[j]).inverse() * (estimate[i].inverse() * estimate[j]);
    r.translation_pct += 100.0 * E.translation().norm() / travelled;
    r.rotation_deg_per_m += rad2deg(angleOf(E)) / travelled;
    ++r.segments;
  }
  if (r.segments > 0) {
    r.translation_pct /= r.segments;
    r.rotation_deg_per_m /= r.segments;
  }
  return r;
}

double absoluteTrajectoryError(const Trajectory& truth, const Trajectory& estimate) {
  requireSameLength(truth, estimate);
  if (truth.empty()) return 0.0;
  Eigen::Matrix3Xd a(3, truth.size()), b(3, truth.size());  // estimate -> truth
  for (std::size_t i = 0; i < truth.size(); ++i) {
    a.col(Eigen::Index(i)) = estimate[i].translation();
    b.col(Eigen::Index(i)) = truth[i].translation();
  }
  const Eigen::Matrix4d T = Eigen::umeyama(a, b, false);
  const Eigen::Matrix3Xd aligned = (T.topLeftCorner<3, 3>() * a).colwise() + T.topRightCorner<3, 1>();
  return std::sqrt((aligned - b).colwise().squaredNorm().mean());
}

StationaryDrift stationaryDrift(const Trajectory& truth, const Trajectory& estimate,
                                double still_m, double still_deg) {
  requireSameLength(truth, estimate);
  StationaryDrift s;
  std::size_t i = 0;
  while (i < truth.size()) {
    std::size_t j = i + 1;
    auto still = [&](std::size_t k) {
      const Eigen::Isometry3d m = truth[i].inverse() * truth[k];
      return m.translation().norm() <= still_m && rad2deg(angleOf(m)) <= still_deg;
    };
    while (j < truth.size() && still(j)) ++j;
    if (j - i >= 2) {
      ++s.segments;
      s.scans += int(j - i);
      for (std::size_t k = i + 1; k < j; ++k) {
        const Eigen::Isometry3d m = estimate[i].inverse() * estimate[k];
        s.translation = std::max(s.translation, m.translation().norm());
        s.rotation_deg = std::max(s.rotation_deg, rad2deg(angleOf(m)));
      }
    }
    i = j;
  }
  return s;
}

CovarianceConsistency covarianceConsistency(const Trajectory& truth, const Trajectory& estimate,
                                            const std::vector<Eigen::Matrix<double, 6, 6>>& covariances,
                                            const std::vector<bool>& use) {
  if (truth.size() != estimate.size() || covariances.size() != truth.size() ||
      (!use.empty() && use.size() != truth.size())) {
    throw std::invalid_argument("covarianceConsistency: truth, estimate, covariances and use differ in size");
  }
  CovarianceConsistency out;
  std::vector<double> nees;
  for (std::size_t k = 0; k < truth.size(); ++k) {
    if (!use.empty() && !use[k]) continue;
    const Eigen::Matrix<double, 6, 6>& C = covariances[k];
    const Eigen::LLT<Eigen::Matrix<double, 6, 6>> llt(C);
    if (llt.info() != Eigen::Success) continue;
    Eigen::Matrix<double, 6, 1> e;
    e.head<3>() = estimate[k].translation() - truth[k].translation();
    const Eigen::AngleAxisd d(estimate[k].linear() * truth[k].linear().transpose());
    e.tail<3>() = d.axis() * d.angle();
    for (int i = 0; i < 6; ++i) {
      const double z = std::abs(e(i)) / std::sqrt(C(i, i));
      out.within1(i) += z <= 1.0;
      out.beyond3(i) += z > 3.0;
    }
    nees.push_back(e.dot(llt.solve(e)));
  }
  out.poses = int(nees.size());
  if (out.poses == 0) return out;
  out.within1 /= double(out.poses);
  out.beyond3 /= double(out.poses);
  double sum = 0.0;
  for (double v : nees) sum += v;
  out.nees_mean = sum / double(out.poses);
  std::nth_element(nees.begin(), nees.begin() + std::ptrdiff_t(nees.size() / 2), nees.end());
  out.nees_median = nees[nees.size() / 2];
  return out;
}

}  // namespace cube_scan_matcher
