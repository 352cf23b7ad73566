#include "cube_scan_matcher/core/plane_polish.h"

#include <algorithm>
#include <array>
#include <cmath>
#include <vector>

#include <Eigen/Eigenvalues>
#include <Eigen/Geometry>

#include "cube_scan_matcher/core/deskew.h"
#include "cube_scan_matcher/core/parallel.h"
#include "require_in_range.h"
#include "voxel_key.h"

namespace cube_scan_matcher {

void validate(const PolishSettings& s) {
  if (!s.enabled) return;
  requireInRange("polish.voxel_fraction", s.voxel_fraction, 1e-3, 2.0);
  requireInRange("polish.min_points", s.min_points, 3, 1000);
  requireInRange("polish.max_planarity", s.max_planarity, 1e-6, 1.0);
  requireInRange("polish.kernel", s.kernel, 1e-4, 1.0);
  requireInRange("polish.max_iterations", s.max_iterations, 1, 100);
  requireInRange("polish.tolerance_m", s.tolerance_m, 0.0, 0.1);
  requireInRange("polish.tolerance_rad", s.tolerance_rad, 0.0, 0.01);
  requireInRange("polish.max_overrelaxation", s.max_overrelaxation, 1.0, 4.0);
  requireInRange("polish.round_steps", s.round_steps, 0, 100);
  requireInRange("polish.collapse_fraction", s.collapse_fraction, 0.0, 2.0);
  requireInRange("polish.max_shift_m", s.max_shift_m, 1e-4, 10.0);
  requireInRange("polish.max_shift_rad", s.max_shift_rad, 1e-5, 1.0);
  requireInRange("polish.min_correspondences", s.min_correspondences, 6, 1000000);
  requireInRange("polish.weak_ratio", s.weak_ratio, 1e-9, 0.999);
  requireInRange("polish.degenerate_ratio", s.degenerate_ratio, 1e-12, 0.999);
  requireInRange("polish.translation_degenerate_ratio", s.translation_degenerate_ratio, 1e-12, 0.999);
  requireInRange("polish.min_spread", s.min_spread, 0.0, 1.0);
  requireInRange("polish.support_cosine", s.support_cosine, 0.0, 0.999);
  requireInRange("polish.degenerate_sigma_m", s.degenerate_sigma_m, 0.0, 1e3);
  requireInRange("polish.covariance_scale", s.covariance_scale, 1.0, 1e6);
  requireInRange("polish.covariance_cell_m", s.covariance_cell_m, 0.0, 100.0);
  requireInRange("polish.covariance_cell_scale", s.covariance_cell_scale, 0.0, 1e6);
  requireInRange("polish.covariance_jackknife_cap", s.covariance_jackknife_cap, 0.0, 1e6);
}

namespace {

using Matrix6 = Eigen::Matrix<double, 6, 6>;
using Vector6 = Eigen::Matrix<double, 6, 1>;

/// The least-squares problem linearised at (R, t): for each scan point p with q = R p + t and
/// each of its planes (n, m) (its own voxel's, or the 8 around it), residual r = n . (q - m),
/// Jacobian [n, (R p) x n] for the perturbation t' = t + dt, R' = exp(dtheta) R; Geman-McClure
/// weights. `count`: the scan points with at least one correspondence.
struct Linearisation {
  Matrix6 H = Matrix6::Zero();
  Vector6 g = Vector6::Zero();
  double weight = 0.0;     // sum of w
  double weighted_r2 = 0.0;  // sum of w r^2
  int count = 0;
};

/// One correspondence: its plane normal and weight (the Jacobian's translation part), its
/// term w r J of the gradient and its plane's mean (in the reference frame; not the scan
/// point's position, whose noise would sort points across a cube's face by their residual).
struct Row {
  Eigen::Vector3d n;
  double w;
  Vector6 J;  // the residual's Jacobian (times jscale)
  double wr;  // w r: the row's gradient term is wr J
  Eigen::Vector3f m;
};

/// Adds the correspondence of q = rp + t with `plane`, its robust weight times `beta`, and its
/// Jacobian times `jscale`; false (nothing added) when q is more than max_r from the plane.
inline bool addCorrespondence(Linearisation& L, const LocalPlane& plane, const Eigen::Vector3d& rp,
                              const Eigen::Vector3d& q, double beta, double jscale, double k2,
                              double max_r, std::vector<Row>* rows) {
  const double r = plane.normal.dot(q - plane.mean);
  if (std::abs(r) > max_r) return false;
  const double s = k2 / (k2 + r * r);
  const double w = beta * s * s;
  Vector6 J;
  J.head<3>() = plane.normal;
  J.tail<3>() = rp.cross(plane.normal);
  if (jscale != 1.0) J *= jscale;
  for (int a = 0; a < 6; ++a) {  // the upper triangle of H += w J J^T
    const double wa = w * J[a];
    for (int b = a; b < 6; ++b) L.H(a, b) += wa * J[b];
  }
  const Vector6 wrJ = (w * r) * J;
  if (rows) rows->push_back({plane.normal, w, J, w * r, plane.mean.cast<float>()});
  L.g += wrJ;
  L.weight += w;
  L.weighted_r2 += w * r * r;
  return true;
}

/// One plane per scan point: its own voxel's. With `near`, also collects the scan points that
/// found a plane (the only ones the later iterations need to look at: the pose moves by
/// millimetres); with `rows`, every correspondence.
/// With `scale`, each point's Jacobian is multiplied by scale[i] (the sweep polish).
Linearisation linearise(const PlaneMap& map, const PointArray& scan, const Eigen::Matrix3d& R,
                        const Eigen::Vector3d& t, double kernel, PointArray* near = nullptr,
                        std::vector<Row>* rows = nullptr, const std::vector<float>* scale = nullptr,
                        std::vector<std::size_t>* near_index = nullptr) {
  Linearisation L;
  const double k2 = kernel * kernel;
  const double max_r = map.voxel();
  for (std::size_t i = 0; i < scan.size(); ++i) {
    const Eigen::Vector3d rp = R * scan.point(i).cast<double>();
    const Eigen::Vector3d q = rp + t;
    const LocalPlane* plane = map.planeAt(q);
    if (!plane) continue;
    if (near) near->push_back(scan.x[i], scan.y[i], scan.z[i]);
    if (near_index) near_index->push_back(i);
    const double jscale = scale ? double((*scale)[i]) : 1.0;
    if (addCorrespondence(L, *plane, rp, q, 1.0, jscale, k2, max_r, rows)) ++L.count;
  }
  L.H.triangularView<Eigen::StrictlyLower>() = L.H.transpose();
  return L;
}

/// The 8 voxels whose centres surround a point: the lowest one (PlaneMap::planeOfVoxel
/// indices, packed) and their planes, nullptr where a voxel has none.
struct Corners {
  std::uint64_t base = ~std::uint64_t{0};
  std::array<const LocalPlane*, 8> planes{};
};

/// The lowest of the 8 voxel centres around q (PlaneMap::planeOfVoxel indices) in b, and per
/// axis the trilinear weights of the lower and the upper centre in g. `inv`: 1 / voxel edge.
inline void cornerBase(const Eigen::Vector3d& q, double inv, std::int64_t b[3], double g[3][2]) {
  // Voxel k's centre is at (k + 1/2) / inv: u = q inv - 1/2 has the lower centre at floor(u).
  for (int k = 0; k < 3; ++k) {
    const double u = q[k] * inv - 0.5;
    const double lower = std::floor(u);
    const double f = u - lower;
    g[k][0] = 1.0 - f, g[k][1] = f;
    b[k] = std::int64_t(std::clamp(lower, -double(1 << 20), double(1 << 20))) + (1 << 20);
  }
}

/// Sets c to the planes of the 8 voxels from b on, unless it already holds them.
inline void lookUpCorners(const PlaneMap& map, const std::int64_t b[3], Corners& c) {
  const std::uint64_t base = detail::packVoxel(b[0], b[1], b[2]);
  if (c.base == base) return;
  c.base = base;
  for (int k = 0; k < 8; ++k) {
    c.planes[std::size_t(k)] =
        map.planeOfVoxel(b[0] + (k & 1), b[1] + ((k >> 1) & 1), b[2] + ((k >> 2) & 1));
  }
}

/// Looks up every point's corners (and so fits the planes they need) on `threads` threads:
/// the lookups and the lazy plane fits are most of a pass over every scan point, and the
/// serial pass that follows then finds each point's corners in place. The result does not
/// depend on the threads: each point's corners are the same whoever looks them up.
void lookUpCornersInParallel(const PlaneMap& map, const PointArray& scan, const Eigen::Matrix3d& R,
                             const Eigen::Vector3d& t, std::vector<Corners>& corners,
                             int threads) {
  constexpr std::size_t kChunk = 1024;  // points per job
  const int jobs = int((scan.size() + kChunk - 1) / kChunk);
  const double inv = map.inverseVoxel();
  runOnThreads(jobs, threads, [&](int job, int) {
    const std::size_t end = std::min(scan.size(), (std::size_t(job) + 1) * kChunk);
    for (std::size_t i = std::size_t(job) * kChunk; i < end; ++i) {
      const Eigen::Vector3d rp = R * scan.point(i).cast<double>();
      const Eigen::Vector3d q = rp + t;
      std::int64_t b[3];
      double g[3][2];
      cornerBase(q, inv, b, g);
      lookUpCorners(map, b, corners[i]);
    }
  });
}

/// Trilinear correspondences: each scan point is paired with the planes of the 8 voxels whose
/// centres surround q, each weighted by q's trilinear weight for that centre (they sum to 1).
/// The weights vary continuously with the pose, so the objective has no steps where a point
/// crosses a voxel face: a polish started a centimetre apart ends on the same pose.
/// `corners[i]` caches point i's planes; they are looked up again only when q moves into
/// another set of 8 voxels. With `near`, collects the points that have a plane among their 8
/// (and their corners, in `near_corners`). With threads > 1 the corners are looked up on that
/// many threads first (lookUpCornersInParallel); the sums are the same, in the same order.
Linearisation lineariseTrilinear(const PlaneMap& map, const PointArray& scan,
                                 const Eigen::Matrix3d& R, const Eigen::Vector3d& t,
                                 double kernel, std::vector<Corners>& corners,
                                 PointArray* near = nullptr,
                                 std::vector<Corners>* near_corners = nullptr, int threads = 1) {
  Linearisation L;
  const double k2 = kernel * kernel;
  const double max_r = map.voxel();
  const double inv = map.inverseVoxel();
  corners.resize(scan.size());
  if (threads > 1) lookUpCornersInParallel(map, scan, R, t, corners, threads);
  for (std::size_t i = 0; i < scan.size(); ++i) {
    const Eigen::Vector3d rp = R * scan.point(i).cast<double>();
    const Eigen::Vector3d q = rp + t;
    std::int64_t b[3];
    double g[3][2];  // per axis: the weights of the lower and the upper centre
    cornerBase(q, inv, b, g);
    Corners& c = corners[i];
    lookUpCorners(map, b, c);
    bool any_plane = false, any = false;
    for (int k = 0; k < 8; ++k) {
      const LocalPlane* plane = c.planes[std::size_t(k)];
      if (!plane) continue;
      any_plane = true;
      const double beta = g[0][k & 1] * g[1][(k >> 1) & 1] * g[2][(k >> 2) & 1];
      if (beta > 0.0 && addCorrespondence(L, *plane, rp, q, beta, 1.0, k2, max_r, nullptr)) {
        any = true;
      }
    }
    if (any_plane && near) {
      near->push_back(scan.x[i], scan.y[i], scan.z[i]);
      near_corners->push_back(c);
    }
    if (any) ++L.count;
  }
  L.H.triangularView<Eigen::StrictlyLower>() = L.H.transpose();
  return L;
}

/// Eigen-decomposition of H in units where a rotation of 1 rad moves a point by `rho` metres.
struct Spectrum {
  Eigen::SelfAdjointEigenSolver<Matrix6> eig;
  Vector6 scale;  // x_scaled = x / scale (1 for translation, 1/rho for rotation)
  double max_eigenvalue = 0.0;
};

Spectrum spectrum(const Matrix6& H, double rho) {
  Spectrum s;
  s.scale << 1, 1, 1, 1.0 / rho, 1.0 / rho, 1.0 / rho;
  const Matrix6 Hs = s.scale.asDiagonal() * H * s.scale.asDiagonal();
  s.eig.compute(Hs);
  s.max_eigenvalue = std::max(s.eig.eigenvalues()(5), 0.0);
  return s;
}

/// The Gauss-Newton step H dx = -g restricted to the directions whose information is at least
/// weak_ratio of the strongest (the others are left where the cube stages put them).
Vector6 step(const Linearisation& L, const Spectrum& s, double weak_ratio) {
  const Vector6 gs = s.scale.asDiagonal() * L.g;
  Vector6 u = Vector6::Zero();
  for (int k = 0; k < 6; ++k) {
    const double lambda = s.eig.eigenvalues()(k);
    if (!(lambda >= weak_ratio * s.max_eigenvalue) || !(lambda > 0.0)) continue;
    const Vector6 v = s.eig.eigenvectors().col(k);
    u -= v * (v.dot(gs) / lambda);
  }
  return s.scale.asDiagonal() * u;
}

/// The clustered ("sandwich") covariance H^-1 B H^-1 with B = sum over cells c of g_c g_c^T,
/// g_c the sum of the terms w r J of the correspondences in cell c (cubes of edge `cell` [m]
/// in the reference frame): residuals that share a surface's model error (a trunk's tangent
/// plane met by points on another side of the trunk) count once per cell, not once per point.
/// H^-1 = S inv_s S (inv_s: the floored inverse of the scaled H, S = diag(scale); H unscaled).
/// With jackknife_cap > 1, each cell's term is the pose's change when the cell is left out,
/// (H - H_c)^-1 g_c (H_c = sum of w J J^T over the cell), instead of H^-1 g_c: a cell that
/// alone fixes a direction (the few small objects of an open square) weighs as much as its
/// leverage says. (H - (1 - 1/cap) H_c) replaces H - H_c, which is at least H / cap, so a cell
/// widens the term along a direction at most cap times in standard deviation.
Matrix6 clusteredCovariance(const std::vector<Row>& rows, double cell, const Vector6& scale,
                            const Matrix6& inv_s, const Matrix6& H, double jackknife_cap) {
  const float inv = float(1.0 / cell);
  detail::KeyIndex index(rows.size() / 8);
  const bool jackknife = jackknife_cap > 1.0;
  thread_local std::vector<Vector6> cells;
  thread_local std::vector<Matrix6> infos;
  cells.clear();
  infos.clear();
  for (const Row& row : rows) {
    const auto [c, fresh] =
        index.insert(detail::packVoxel(detail::voxelIndex(row.m.x(), inv),
                                       detail::voxelIndex(row.m.y(), inv),
                                       detail::voxelIndex(row.m.z(), inv)));
    if (fresh) {
      cells.push_back(Vector6::Zero());
      if (jackknife) infos.push_back(Matrix6::Zero());
    }
    cells[c] += row.wr * row.J;
    if (jackknife) infos[c].noalias() += row.w * row.J * row.J.transpose();
  }
  Matrix6 B = Matrix6::Zero();
  if (!jackknife) {
    for (const Vector6& c : cells) {
      const Vector6 g = scale.asDiagonal() * c;
      B.noalias() += g * g.transpose();
    }
    return scale.asDiagonal() * inv_s * B * inv_s * scale.asDiagonal();
  }
  const Matrix6 Hs = scale.asDiagonal() * H * scale.asDiagonal();
  const double keep = 1.0 - 1.0 / jackknife_cap;
  for (std::size_t c = 0; c < cells.size(); ++c) {
    const Vector6 g = scale.asDiagonal() * cells[c];
    const Matrix6 Hc = scale.asDiagonal() * infos[c] * scale.asDiagonal();
    const Eigen::LDLT<Matrix6> ldlt(Hs - keep * Hc);
    Vector6 d = ldlt.info() == Eigen::Success ? Vector6(ldlt.solve(g)) : Vector6(inv_s * g);
    if (!d.allFinite()) d = inv_s * g;
    B.noalias() += d * d.transpose();
  }
  return scale.asDiagonal() * B * scale.asDiagonal();
}

/// The cosine between two steps in units where 1 rad = rho m (0 when either is zero).
double cosineScaled(const Vector6& a, const Vector6& b, double rho) {
  Vector6 scale;
  scale << 1, 1, 1, rho, rho, rho;
  const Vector6 sa = scale.asDiagonal() * a, sb = scale.asDiagonal() * b;
  const double norms = sa.norm() * sb.norm();
  return norms > 0.0 ? sa.dot(sb) / norms : 0.0;
}

double radiusOfGyration(const PointArray& points) {
  double sum_r2 = 0.0;
  for (std::size_t i = 0; i < points.size(); ++i) sum_r2 += points.point(i).cast<double>().squaredNorm();
  return points.empty() ? 1.0 : std::max(1.0, std::sqrt(sum_r2 / double(points.size())));
}

double rotationAngle(const Eigen::Matrix3d& R) {
  return Eigen::AngleAxisd(R).angle();
}

/// Where the Gauss-Newton rounds of the polish end.
struct Iterated {
  Eigen::Matrix3d R;
  Eigen::Vector3d t;
  int iterations = 0;
  /// The radius of gyration about the scan's origin of the points near a plane at the start
  /// (far outliers have none): the lever arm that makes a rotation comparable with a
  /// translation. 1 m when no step was taken.
  double rho = 1.0;
};

/// The Gauss-Newton rounds from (R, t). Each round starts with a pass over every scan point
/// that collects those near a plane into `near`, then iterates on them alone (the pose moves
/// by millimetres). A round ends when it converges, or after round_steps steps (the set was
/// collected where the pose no longer is); the polish ends after a converged round that
/// started at a converged pose, so the final set is collected at the result and does not
/// depend on the start. Correspondences are trilinear (lineariseTrilinear), so the objective is
/// continuous in the pose.
Iterated iterate(const PlaneMap& map, const PointArray& scan, const Eigen::Isometry3d& start,
                 const PolishSettings& s, PointArray& near, int threads) {
  Iterated res{start.linear(), start.translation()};
  Eigen::Matrix3d& R = res.R;
  Eigen::Vector3d& t = res.t;
  int& it = res.iterations;
  double& rho = res.rho;
  // Reused from call to call: fresh corner lists of a few thousand entries would be faulted in
  // page by page at every registration (~10 us per page fault on a VM). The first round's
  // corners stay valid as a cache for the second round's collecting pass (the pose has moved
  // by centimetres at most).
  thread_local std::vector<Corners> all_corners, near_corners;
  all_corners.assign(scan.size(), Corners());
  double stretch = 1.0;  // over-relaxation of the last step
  Vector6 last_dx = Vector6::Zero();
  bool started_converged = false;  // this round collected its points at a converged pose
  while (it < s.max_iterations) {
    near.clear();
    near_corners.clear();
    bool converged = false;
    bool cut = false;  // the round ran its round_steps steps without converging
    for (int round_it = 0; it < s.max_iterations; ++round_it) {
      if (s.round_steps > 0 && round_it >= s.round_steps) {
        cut = true;
        break;
      }
      const bool collect = round_it == 0;  // a pass over every scan point, filling `near`
      const Linearisation L =
          collect ? lineariseTrilinear(map, scan, R, t, s.kernel, all_corners, &near, &near_corners,
                                       threads)
                  : lineariseTrilinear(map, near, R, t, s.kernel, near_corners);
      if (L.count < s.min_correspondences) break;
      if (it == 0) rho = radiusOfGyration(near);
      const Vector6 dx = step(L, spectrum(L.H, rho), s.weak_ratio);
      if (!dx.allFinite()) break;
      // A step along the last one's direction (on the same points) is stretched; a step that
      // turns (an overshoot comes back) resets the stretch.
      stretch = !collect && cosineScaled(dx, last_dx, rho) > 0.8
                    ? std::min(1.5 * stretch, s.max_overrelaxation)
                    : 1.0;
      last_dx = dx;
      t += stretch * dx.head<3>();
      const Eigen::Vector3d w = stretch * dx.tail<3>();
      if (w.norm() > 0.0) R = Eigen::AngleAxisd(w.norm(), w.normalized()).toRotationMatrix() * R;
      ++it;
      if (dx.head<3>().norm() < s.tolerance_m && dx.tail<3>().norm() < s.tolerance_rad) {
        converged = true;
        break;
      }
    }
    if ((!converged && !cut) || (converged && started_converged)) break;
    started_converged = converged;
  }
  return res;
}

/// The covariance sigma^2 H^-1 (sigma^2 from the weighted residuals, times covariance_scale),
/// weak directions included with their (large) variance, plus the clustered term; sets the
/// result's weak direction and ratio. Eigenvalues are floored so that the inverse stays finite.
void setCovariance(const Linearisation& L, const std::vector<Row>& rows, double rho,
                   const PolishSettings& s, PolishResult& res) {
  const Spectrum sp = spectrum(L.H, rho);
  const double sigma2 = L.weighted_r2 / (L.weight - 6.0);
  Matrix6 inv_s = Matrix6::Zero();
  const double floor = std::max(sp.max_eigenvalue * 1e-12, 1e-300);
  for (int k = 0; k < 6; ++k) {
    const Vector6 v = sp.eig.eigenvectors().col(k);
    inv_s.noalias() += v * v.transpose() / std::max(sp.eig.eigenvalues()(k), floor);
  }
  res.covariance = s.covariance_scale * sigma2 * sp.scale.asDiagonal() * inv_s *
                   sp.scale.asDiagonal();
  if (s.covariance_cell_m > 0.0 && s.covariance_cell_scale > 0.0) {
    res.covariance += s.covariance_cell_scale *
                      clusteredCovariance(rows, s.covariance_cell_m, sp.scale, inv_s, L.H,
                                          s.covariance_jackknife_cap);
  }
  res.weak_ratio = sp.max_eigenvalue > 0.0 ? sp.eig.eigenvalues()(0) / sp.max_eigenvalue : 0.0;
  res.weak_direction = sp.eig.eigenvectors().col(0);
}

/// Translation alone: the normals' information sum w n n^T along its eigenvectors, counted only
/// from the planes that lean towards each by support_cosine. In a tunnel the fitted normals'
/// small tilts (and a few fits across a corner) would otherwise give its axis 0.3-2 % of the
/// floor's information, a 1-2 cm sd and a wrong pose accepted 1-2 m along the axis. Sets the
/// translation's weak axis and ratio, floors the covariance along that axis, and the
/// degenerate flag.
void checkTranslation(const Linearisation& L, const std::vector<Row>& rows,
                      const PolishSettings& s, PolishResult& res) {
  const Eigen::SelfAdjointEigenSolver<Eigen::Matrix3d> et(L.H.topLeftCorner<3, 3>());
  Eigen::Vector3d t_info = Eigen::Vector3d::Zero();
  for (const Row& row : rows) {
    for (int k = 0; k < 3; ++k) {
      const double c = row.n.dot(et.eigenvectors().col(k));
      if (std::abs(c) >= s.support_cosine) t_info(k) += row.w * c * c;
    }
  }
  int t_weakest = 0;
  for (int k = 1; k < 3; ++k) {
    if (t_info(k) < t_info(t_weakest)) t_weakest = k;
  }
  const Eigen::Vector3d u = et.eigenvectors().col(t_weakest);
  res.translation_weak_axis = u;
  res.translation_weak_ratio = t_info.maxCoeff() > 0.0 ? t_info(t_weakest) / t_info.maxCoeff() : 0.0;
  // Along that axis the variance is at least what the supported information gives, and when
  // nothing fixes the pose along it (the cube stages leave it near the guess, whose error the
  // scan cannot tell) at least degenerate_sigma_m^2.
  const bool translation_degenerate = res.translation_weak_ratio < s.translation_degenerate_ratio;
  const double sigma2 = L.weighted_r2 / (L.weight - 6.0);
  const double t_floor = std::max(t_info.maxCoeff() * 1e-12, 1e-300);
  double min_var = s.covariance_scale * sigma2 / std::max(t_info(t_weakest), t_floor);
  if (translation_degenerate) min_var = std::max(min_var, s.degenerate_sigma_m * s.degenerate_sigma_m);
  const double var_u = u.dot(res.covariance.topLeftCorner<3, 3>() * u);
  if (min_var > var_u) res.covariance.topLeftCorner<3, 3>() += (min_var - var_u) * u * u.transpose();
  if (translation_degenerate && res.weak_ratio >= s.degenerate_ratio) {
    res.weak_direction << u, 0.0, 0.0, 0.0;  // the axis the scene does not fix
  }
  res.degenerate = res.weak_ratio < s.degenerate_ratio || translation_degenerate;
}

}  // namespace

PolishResult polishOnPlanes(const PlaneMap& map, const PointArray& scan, const Pose6& pose,
                            const PolishSettings& s, int threads) {
  PolishResult res;
  res.pose = pose;
  if (scan.empty() || map.voxels() == 0 || !pose.allFinite()) {
    res.reason = "no points or no planes";
    return res;
  }
  const Eigen::Isometry3d T0 = poseToIsometry(pose);
  thread_local PointArray near;  // reused: see iterate()
  const Iterated end = iterate(map, scan, T0, s, near, threads);
  res.iterations = end.iterations;

  // The covariance and the weak axes from each point's own voxel's plane (with the trilinear
  // pairs, a floor point near a wall would also meet the wall's plane: a residual of the
  // corner's geometry, not of the pose, which would widen the covariance).
  thread_local std::vector<Row> rows;
  rows.clear();
  const Linearisation L = linearise(map, near.empty() ? scan : near, end.R, end.t, s.kernel,
                                    nullptr, &rows);
  res.correspondences = L.count;
  if (L.count < s.min_correspondences || L.weight <= 6.0) {
    res.reason = "too few points near a reference plane";
    return res;
  }
  res.shift_m = (end.t - T0.translation()).norm();
  res.shift_rad = rotationAngle(end.R * T0.linear().transpose());
  if (!(res.shift_m <= s.max_shift_m) || !(res.shift_rad <= s.max_shift_rad)) {
    res.reason = "the polish left the cube result's basin";
    return res;
  }
  Eigen::Isometry3d T = Eigen::Isometry3d::Identity();
  T.linear() = end.R;
  T.translation() = end.t;
  res.pose = isometryToPose(T);
  res.applied = true;
  res.rms = std::sqrt(L.weighted_r2 / L.weight);
  setCovariance(L, rows, end.rho, s, res);
  checkTranslation(L, rows, s, res);
  return res;
}

SweepPolishResult polishSweepOnPlanes(const PlaneMap& map, const PointArray& scan,
                                      const std::vector<float>& tau, const SweepMotion& motion,
                                      const Twist& placed, const Pose6& pose,
                                      const PolishSettings& s, int max_iterations) {
  const double interval = motion.interval;
  SweepPolishResult res;
  res.pose = pose;
  if (scan.empty() || map.voxels() == 0 || !pose.allFinite() || tau.size() != scan.size() ||
      !(interval > 0.0)) {
    res.reason = "no points, no planes or no times";
    return res;
  }
  // A step moves the pose on the left, t' = t + dt, R' = exp(dtheta) R, as the polish does; the
  // points are re-placed with the motion it implies at every step, so the residuals are exact
  // and only the Jacobian is approximate: a change of the pose moves a point taken at tau by
  // about s = 1 + tau / interval of it (the sweep's points at the previous scan's time do not
  // move, its last line moves with the pose).
  std::vector<float> weight(tau.size());
  for (std::size_t i = 0; i < tau.size(); ++i) weight[i] = float(std::clamp(1.0 + tau[i] / interval, 0.0, 1.0));
  Eigen::Isometry3d T = poseToIsometry(pose);
  const Eigen::Isometry3d T0 = T;
  double rho = 1.0;
  PointArray placed_now, near;
  std::vector<std::size_t> near_index;
  std::vector<float> near_weight, near_tau;
  PointArray near_raw;
  for (int it = 0; it < max_iterations; ++it) {
    const Twist velocity = motion.velocity(T);
    Linearisation L;
    if (it == 0) {
      placed_now = scan;
      deskew(placed_now, tau, placed, velocity);
      near.clear();
      near_index.clear();
      L = linearise(map, placed_now, T.linear(), T.translation(), s.kernel, &near, nullptr, &weight, &near_index);
      near_weight.clear(), near_tau.clear(), near_raw.clear();
      for (std::size_t i : near_index) {
        near_weight.push_back(weight[i]);
        near_tau.push_back(tau[i]);
        near_raw.push_back(scan.x[i], scan.y[i], scan.z[i]);
      }
      rho = radiusOfGyration(near);
    } else {
      PointArray q = near_raw;
      deskew(q, near_tau, placed, velocity);
      L = linearise(map, q, T.linear(), T.translation(), s.kernel, nullptr, nullptr, &near_weight);
    }
    res.correspondences = L.count;
    if (L.count < s.min_correspondences) {
      res.reason = "too few points near a reference plane";
      return res;
    }
    const Vector6 dx = step(L, spectrum(L.H, rho), s.weak_ratio);
    if (!dx.allFinite()) break;
    T.translation() += dx.head<3>();
    const Eigen::Vector3d w = dx.tail<3>();
    if (w.norm() > 0.0) T.linear() = Eigen::AngleAxisd(w.norm(), w.normalized()).toRotationMatrix() * T.linear();
    res.iterations = it + 1;
    if (dx.head<3>().norm() < s.tolerance_m && w.norm() < s.tolerance_rad) break;
  }
  res.shift_m = (T.translation() - T0.translation()).norm();
  res.shift_rad = rotationAngle(T.linear() * T0.linear().transpose());
  res.pose = isometryToPose(T);
  res.applied = true;
  return res;
}

}  // namespace cube_scan_matcher
