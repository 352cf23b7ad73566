#include "cube_scan_matcher/core/planar_grid.h"

#include <algorithm>
#include <cmath>
#include <stdexcept>
#include <vector>

#include "cube_scan_matcher/core/parallel.h"
#include "require_in_range.h"

namespace cube_scan_matcher {

namespace {

/// Grid points per side: -n..n.
int halfCount(double half, double step) { return half > 0.0 ? int(std::floor(half / step + 1e-9)) : 0; }

}  // namespace

std::int64_t PlanarGridSettings::poses() const {
  const std::int64_t nxy = 2 * std::int64_t(halfCount(half_width_m, step_m)) + 1;
  const std::int64_t nyaw = 2 * std::int64_t(halfCount(half_yaw, step_yaw)) + 1;
  return nxy * nxy * nyaw;
}

void validate(const PlanarGridSettings& s) {
  requireInRange("planar grid half_width_m", s.half_width_m, 0.0, 20.0);
  requireInRange("planar grid step_m", s.step_m, 0.05, 5.0);
  requireInRange("planar grid half_yaw [rad]", s.half_yaw, 0.0, double(EIGEN_PI));
  requireInRange("planar grid step_yaw [rad]", s.step_yaw, deg2rad(0.1), deg2rad(45.0));
  if (s.poses() > 1000000) {
    throw std::invalid_argument("planar grid: " + std::to_string(s.poses()) +
                                " poses, more than 1e6 (widen the steps or narrow the extents)");
  }
}

PlanarGridResult planarGridMaxima(const std::vector<CoincidenceObjective*>& objectives,
                                  const PlanarGridSettings& s, const Pose6& centre, int count,
                                  int threads) {
  PlanarGridResult res;
  if (!s.enabled() || count <= 0) return res;
  threads = std::max(1, std::min(threads, int(objectives.size())));
  const int nxy = halfCount(s.half_width_m, s.step_m), nyaw = halfCount(s.half_yaw, s.step_yaw);
  const int sx = 2 * nxy + 1, sk = 2 * nyaw + 1;
  // J[(k * sx + i) * sx + j]: yaw index k, x index i, y index j; one yaw slice per job.
  std::vector<int> J(std::size_t(sk) * std::size_t(sx) * std::size_t(sx), 0);
  auto poseAt = [&](int k, int i, int j) {
    Pose6 p = centre;
    p[0] += (i - nxy) * s.step_m;
    p[1] += (j - nxy) * s.step_m;
    p[5] += (k - nyaw) * s.step_yaw;
    return p;
  };
  auto index = [&](int k, int i, int j) { return (std::size_t(k) * sx + std::size_t(i)) * sx + std::size_t(j); };
  runOnThreads(sk, threads, [&](int k, int t) {
    CoincidenceObjective& f = *objectives[std::size_t(t)];
    const PointArray* scan = f.scan();
    if (!scan || scan->empty()) return;  // J = 0 everywhere, as evaluate() gives
    // The poses of a yaw slice differ in translation only: the scan is rotated once (u = A p)
    // and each pose's cube indices are those of u + b (cube_grid.h: the indices evaluate()
    // computes, bit for bit).
    const CubeGrid& grid = f.grid();
    const std::size_t n = scan->size();
    thread_local std::vector<float> ux, uy, uz;
    ux.resize(n), uy.resize(n), uz.resize(n);
    const auto affineAt = [&](int i, int j) {
      const Eigen::Isometry3d pose = poseToIsometry(poseAt(k, i, j));
      return grid.affine(pose.linear().cast<float>(), pose.translation().cast<float>());
    };
    rotatePoints(affineAt(0, 0).a, scan->x.data(), scan->y.data(), scan->z.data(), n, ux.data(),
                 uy.data(), uz.data());
    std::int32_t idx[CoincidenceObjective::kBlock];
    for (int i = 0; i < sx; ++i) {
      for (int j = 0; j < sx; ++j) {
        const GridAffine g = affineAt(i, j);
        f.startCount();
        for (std::size_t begin = 0; begin < n; begin += CoincidenceObjective::kBlock) {
          const std::size_t m = std::min(CoincidenceObjective::kBlock, n - begin);
          cubeIndicesFromRotated(1.0f, g.b, grid.dimsF(), ux.data() + begin, uy.data() + begin,
                                 uz.data() + begin, m, f.outsideIndex(), idx);
          f.countBlock(idx, m);
        }
        J[index(k, i, j)] = f.finishCount();
      }
    }
  });
  res.evaluations = int(J.size());
  // Local maxima over the 26-neighbourhood (ties: the earlier grid index wins).
  auto isPeak = [&](int k, int i, int j) {
    const std::size_t c = index(k, i, j);
    if (J[c] <= 0) return false;
    for (int kk = std::max(k - 1, 0); kk <= std::min(k + 1, sk - 1); ++kk) {
      for (int ii = std::max(i - 1, 0); ii <= std::min(i + 1, sx - 1); ++ii) {
        for (int jj = std::max(j - 1, 0); jj <= std::min(j + 1, sx - 1); ++jj) {
          const std::size_t n = index(kk, ii, jj);
          if (n != c && (J[n] > J[c] || (J[n] == J[c] && n < c))) return false;
        }
      }
    }
    return true;
  };
  std::vector<std::size_t> peaks;
  for (int k = 0; k < sk; ++k) {
    for (int i = 0; i < sx; ++i) {
      for (int j = 0; j < sx; ++j) {
        if (isPeak(k, i, j)) peaks.push_back(index(k, i, j));
      }
    }
  }
  std::stable_sort(peaks.begin(), peaks.end(), [&](std::size_t a, std::size_t b) { return J[a] > J[b]; });
  if (peaks.size() > std::size_t(count)) peaks.resize(std::size_t(count));
  for (const std::size_t c : peaks) {
    const int k = int(c / (std::size_t(sx) * sx)), i = int((c / sx) % sx), j = int(c % sx);
    res.maxima.push_back(poseAt(k, i, j));
    res.maxima_J.push_back(J[c]);
  }
  return res;
}

}  // namespace cube_scan_matcher
