// sequence_benchmark: runs the online matcher (OnlineMatcher, the nodelet's core) over a whole
// sequence and reports drift, beside PCL peers chained the same way in the same run.
//   sequence_benchmark --scene urban --length 500 --odometry big       (simulated, exact truth)
//   sequence_benchmark --dir ../shared/data/balm_os0_hall_seq_a --odometry big   (real + poses.tum)
// Metrics: relative pose error per 10/50/100 m (% and deg/m), ATE after a rigid alignment,
// drift while standing still, accepted / rejected scans, median time per scan.
#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <functional>
#include <iostream>
#include <limits>
#include <memory>
#include <optional>
#include <random>
#include <string>
#include <vector>

#include "cube_scan_matcher/core/chain_covariance.h"
#include "cube_scan_matcher/core/metrics.h"
#include "cube_scan_matcher/core/odometry_anchor.h"
#include "cube_scan_matcher/core/online_matcher.h"
#include "cube_scan_matcher/core/trajectory_metrics.h"
#include "cube_scan_matcher/io/cloud_io.h"
#include "cube_scan_matcher/sim/motion.h"
#include "cube_scan_matcher/sim/sequence_motion.h"
#include "cube_scan_matcher/sim/tilting_scanner.h"
#include "open3d_peers.h"
#include "peer_methods.h"
#include "arg_reader.h"
#include "csv_writer.h"
#include "settings_cli.h"

using namespace cube_scan_matcher;
using namespace cube_scan_matcher::tools;

namespace {

void usage(std::ostream& os) {
  os << "usage: sequence_benchmark (--scene NAME | --dir DIR) [options]\n"
        "  --scene NAME          simulated run: hall, urban, park, natural, square, slope,\n"
        "                        forest, tunnel, wall or crowd (sim/scene.h)\n"
        "  --length M            simulated path length [m] (default 500)\n"
        "  --world-seed N        world, trajectory and noise seed (default 1; --seed is the\n"
        "                        GNMM's)\n"
        "  --dir DIR             real sequence: DIR/*.pcd|*.ply in name order + DIR/poses.tum\n"
        "  --odometry MODE       none, small, big, drift, dgps: odometry = truth with the\n"
        "                        simulator's errors (motion.h); cv: no odometry, constant\n"
        "                        velocity from each method's own estimate; identity: no\n"
        "                        odometry, no motion (default big)\n"
        "  --period S            simulated time between sweeps [s] (default 1.5)\n"
        "  --step M              simulated travel per sweep while driving [m] (default 1.5)\n"
        "  --methods LIST        comma list of cubes (package defaults: keyframes and a\n"
        "                        submap), cubes-s2s (every scan a keyframe, no submap: scan\n"
        "                        to scan), cubes-submap (--submap keyframes merged),\n"
        "                        gicp, ndt, icp (PCL on --voxel copies, scan to scan),\n"
        "                        o3d-p2pl, o3d-gicp (Open3D point-to-plane ICP and GICP on\n"
        "                        the same copies, when built with libopen3d-dev)\n"
        "                        (default cubes,cubes-s2s,gicp,ndt)\n"
        "  --submap K            keyframes merged in cubes-submap (default 3)\n"
        "  --keyframe-distance M, --keyframe-angle DEG   keyframe thresholds of the cube methods\n"
        "  --no-motion-candidate 0|1  without odometry, also search from no motion (default 1)\n"
        "  --no-motion-dense-points N  with odometry, a rejected result at no motion searched\n"
        "                        again on the dense points (OnlineMatcherSettings; default 4,\n"
        "                        0 = off)\n"
        "  --no-odometry-grid M:DEG  without odometry, the planar grid's half widths around\n"
        "                        the last pose: x and y [m], yaw [deg] (OnlineMatcherSettings::\n"
        "                        no_odometry_grid; default 2:45, 0:0 = off: the prediction and\n"
        "                        the no-motion candidate in widened bounds)\n"
        "  --no-odometry-dense-points N  without odometry, the coarse and refine stages' dense\n"
        "                        points (default 4)\n"
        "  --reject-degenerate B, --require-polish B, --max-sigma M  the gate's criteria\n"
        "                        (GateSettings; B = 0 or 1, M [m], 0 = off)\n"

        "  --voxel L             peers' voxel leaf [m] (default 0.2)\n"
        "  --csv FILE            per-scan trajectories (default sequence.csv)\n"
        "  --chain-sigmas LIST   comma list of chain covariance settings (chain_covariance.h)\n"
        "                        M:DEG:PCT:SCALE: floors of an accepted increment [m, deg], the\n"
        "                        scale error's sd [%], the factor on the registration's sd;\n"
        "                        default the package's. Each is checked against the truth at\n"
        "                        the cube methods' keyframes\n"
        "  --anchor-sigma-m M, --anchor-sigma-deg D   the odometry's absolute sd assumed by the\n"
        "                        anchored rows (odometry_anchor.h; default 0.5 m, 2 deg). With\n"
        "                        odometry, each cube method also gets a row NAME-anchored (its\n"
        "                        chain tied to the odometry) and the table a row \"odometry\"\n"
        "  --consistency FILE    one line per cube method and chain setting appended: shares\n"
        "                        of keyframe errors within 1 and beyond 3 predicted sd per\n"
        "                        axis, and the NEES (default: none)\n"
        "  --summary FILE        one line per method appended (default: none)\n"
        "  --label TEXT          run label in the CSVs (default: scene or folder name)\n"
        "  --check-pct P, --check-deg-m D, --check-still-m S, --check-rejected N,\n"
        "  --check-accepted-wrong W\n"
        "                        exit 2 unless every cube method's relative error over the\n"
        "                        longest of 100/50/10 m segments the run has is <= P % and\n"
        "                        <= D deg/m, its standing-still drift <= S m, its rejected\n"
        "                        scans <= N and its accepted results beyond 0.10 m / 1 deg of\n"
        "                        the truth <= W (for CI)\n"
     << algorithmOptionsHelp();
}

double yawDeg(const Eigen::Isometry3d& T) { return rad2deg(isometryToPose(T)[5]); }

/// One method's chain over the sequence.
struct Method {
  std::string name;
  Trajectory poses;
  std::vector<double> times;
  /// Cube methods: each scan's work and its split of the time (online_matcher.h OnlineWork).
  std::vector<OnlineWork> work;
  /// Cube methods, per scan: the gate's verdict; the registration's result (scan -> newest
  /// keyframe) and the index of that keyframe's scan (-1: nothing registered), to tell right
  /// results from wrong ones against the truth whatever the gate said.
  std::vector<GateReason> verdict;
  std::vector<Eigen::Isometry3d> result;
  std::vector<int> result_keyframe;
  int accepted = 0, rejected = 0;
  /// Cube methods: per scan, whether it became a keyframe, and its pose's covariance along the
  /// chain (chain_covariance.h) for each of the benchmark's chain settings.
  std::vector<bool> keyframe;
  std::vector<std::vector<Matrix6d>> covariances;
  /// Cube methods with odometry: the chain tied to the odometry (odometry_anchor.h).
  Trajectory anchored;
  /// A row computed from the others (an anchored chain, the odometry): reported, not checked.
  bool derived = false;
  /// Processes scan k; `odom` is the odometry (T_odom_base) when the mode has one.
  std::function<void(Method&, const PointArray&, double, const std::optional<Eigen::Isometry3d>&)> step;
};

/// T with its rotation projected onto SO(3) (nearest rotation, by SVD): a diverged peer
/// can return a matrix that is not rigid, and a chain must not compound it.
Eigen::Isometry3d rigidPart(const Eigen::Isometry3d& T) {
  Eigen::JacobiSVD<Eigen::Matrix3d> svd(T.linear(), Eigen::ComputeFullU | Eigen::ComputeFullV);
  Eigen::Matrix3d R = svd.matrixU() * svd.matrixV().transpose();
  if (R.determinant() < 0) {
    Eigen::Matrix3d U = svd.matrixU();
    U.col(2) *= -1.0;
    R = U * svd.matrixV().transpose();
  }
  Eigen::Isometry3d out = Eigen::Isometry3d::Identity();
  out.linear() = R;
  out.translation() = T.translation();
  return out;
}

/// The previous estimate's motion, as a guess for the next increment (constant velocity).
Eigen::Isometry3d lastMotion(const Trajectory& poses) {
  if (poses.size() < 2) return Eigen::Isometry3d::Identity();
  return poses[poses.size() - 2].inverse() * poses.back();
}

Method cubeMethod(const std::string& name, const OnlineMatcherSettings& settings,
                  const RangeFilterSettings& filter, bool constant_velocity,
                  const std::vector<ChainCovarianceSettings>& chain_settings,
                  const OdometryAnchorSettings& anchor_settings) {
  Method m;
  m.name = name;
  OnlineMatcherSettings s = settings;
  s.constant_velocity = constant_velocity;
  auto matcher = std::make_shared<OnlineMatcher>(s);
  auto chains = std::make_shared<std::vector<ChainCovariance>>();
  for (const ChainCovarianceSettings& c : chain_settings) chains->emplace_back(c);
  m.covariances.resize(chain_settings.size());
  auto anchor = std::make_shared<OdometryAnchor>(anchor_settings);
  auto newest_keyframe = std::make_shared<int>(-1);  // the scan the reference is in the frame of
  m.step = [matcher, chains, anchor, filter, newest_keyframe](
               Method& self, const PointArray& points, double stamp,
               const std::optional<Eigen::Isometry3d>& odom) {
    const auto t0 = std::chrono::steady_clock::now();
    const OnlineStep st = matcher->process(filterPoints(points, filter), stamp, odom);
    self.times.push_back(std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count());
    self.keyframe.push_back(st.reference_updated);
    self.work.push_back(st.work);
    self.verdict.push_back(st.reason);
    self.result.push_back(st.registered ? st.result.transform : Eigen::Isometry3d::Identity());
    self.result_keyframe.push_back(st.registered ? *newest_keyframe : -1);
    if (st.reference_updated) *newest_keyframe = int(self.poses.size());
    for (std::size_t i = 0; i < chains->size(); ++i) {
      const StepCovariance c = (*chains)[i].add(st);
      self.covariances[i].push_back(c.pose);
      if (i == 0 && odom) self.anchored.push_back(anchor->add(st.pose, c.motion, odom));
    }
    if (st.registered) (st.accepted ? self.accepted : self.rejected)++;
    if (st.registered && !st.accepted) {
      std::fprintf(stderr, "%s scan %zu: %s\n", self.name.c_str(), self.poses.size(), st.message.c_str());
    }
    self.poses.push_back(st.pose);
  };
  return m;
}

using PeerFn = PeerResult (*)(const Cloud::ConstPtr&, const Cloud::ConstPtr&, const Eigen::Isometry3d&);

/// A PCL peer chained scan to scan: the guess is the odometry increment, the last motion
/// (cv) or identity. PCL gives no acceptance test of its own: a result is used when it is finite
/// and within the cube method's correction gate (max_correction_*) of the guess.
Method peerMethod(const std::string& name, PeerFn fn, double voxel, bool constant_velocity,
                  const GateSettings& gate) {
  Method m;
  m.name = name;
  struct State {
    Cloud::Ptr previous;
    std::optional<Eigen::Isometry3d> previous_odom;
  };
  auto state = std::make_shared<State>();
  m.step = [state, fn, voxel, constant_velocity, gate](Method& self, const PointArray& points, double,
                                                 const std::optional<Eigen::Isometry3d>& odom) {
    const auto t0 = std::chrono::steady_clock::now();
    Cloud::Ptr cloud = voxelCopy(toPcl(points), float(voxel));
    Eigen::Isometry3d pose = odom ? *odom : Eigen::Isometry3d::Identity();
    if (state->previous) {
      Eigen::Isometry3d guess = Eigen::Isometry3d::Identity();
      if (odom && state->previous_odom) guess = state->previous_odom->inverse() * *odom;
      else if (constant_velocity) guess = lastMotion(self.poses);
      const PeerResult r = fn(cloud, state->previous, guess);
      const Eigen::Isometry3d correction = guess.inverse() * r.estimate;
      const bool rigid = r.estimate.matrix().allFinite() &&
                         (r.estimate.linear().transpose() * r.estimate.linear() -
                          Eigen::Matrix3d::Identity()).norm() < 1e-4;
      if (rigid && correction.translation().norm() <= gate.max_correction_m &&
          Eigen::AngleAxisd(correction.linear()).angle() <= gate.max_correction_rad) {
        pose = self.poses.back() * r.estimate;
        ++self.accepted;
      } else {  // diverged (not finite, not rigid) or beyond the cubes' correction gate:
                // the chain goes on with the guess
        pose = self.poses.back() * guess;
        ++self.rejected;
      }
    }
    self.times.push_back(std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count());
    state->previous = cloud;
    state->previous_odom = odom;
    self.poses.push_back(rigidPart(pose));
  };
  return m;
}

/// A registration result within these of the truth is right [m], [deg].
constexpr double kRightM = 0.10, kRightDeg = 1.0;

/// How far scan k's registration result (scan -> its newest keyframe) is from the truth's
/// increment, [m] and [deg]; nullopt when the scan was not registered.
std::optional<std::pair<double, double>> resultError(const Method& m, const Trajectory& truth,
                                                     std::size_t k) {
  if (k >= m.result_keyframe.size() || m.result_keyframe[k] < 0) return std::nullopt;
  const Eigen::Isometry3d true_increment =
      truth[std::size_t(m.result_keyframe[k])].inverse() * truth[k];
  const Eigen::Isometry3d e = true_increment.inverse() * m.result[k];
  return std::make_pair(e.translation().norm(), rad2deg(Eigen::AngleAxisd(e.linear()).angle()));
}

/// The gate's verdicts against the truth: registered scans accepted or rejected, right or
/// wrong (kRightM, kRightDeg), and the rejections by reason.
struct Verdicts {
  int accepted = 0, accepted_wrong = 0, rejected = 0, rejected_right = 0;
  std::vector<std::pair<std::string, std::pair<int, int>>> reasons;  // reason: rejected, of them right
};

Verdicts countVerdicts(const Method& m, const Trajectory& truth) {
  Verdicts v;
  for (std::size_t k = 0; k < m.verdict.size(); ++k) {
    const auto err = resultError(m, truth, k);
    if (!err) continue;
    const bool right = err->first <= kRightM && err->second <= kRightDeg;
    if (m.verdict[k] == GateReason::Accepted) {
      ++v.accepted;
      v.accepted_wrong += !right;
      continue;
    }
    ++v.rejected;
    v.rejected_right += right;
    const std::string reason = toString(m.verdict[k]);
    auto it = std::find_if(v.reasons.begin(), v.reasons.end(),
                           [&](const auto& r) { return r.first == reason; });
    if (it == v.reasons.end()) it = v.reasons.insert(v.reasons.end(), {reason, {0, 0}});
    ++it->second.first;
    it->second.second += right;
  }
  return v;
}

void reportVerdicts(const Method& m, const Verdicts& v) {
  std::printf("%s verdicts against the truth (right: within %.2f m / %.0f deg of it): %d "
              "accepted, %d of them wrong; %d rejected, %d of them right",
              m.name.c_str(), kRightM, kRightDeg, v.accepted, v.accepted_wrong, v.rejected,
              v.rejected_right);
  for (const auto& [reason, counts] : v.reasons) {
    std::printf("%s %s %d (%d right)", &reason == &v.reasons.front().first ? ";" : ",",
                reason.c_str(), counts.first, counts.second);
  }
  std::printf("\n");
}

/// A cube method's work per scan (online_matcher.h OnlineWork): the counts' means and
/// maxima, and each stage's median and p95 time over the scans where it ran.
void reportWork(const Method& m) {
  std::vector<double> aligns, searches, rounds, register_s, candidate_s, deskew_s, reference_s,
      coarse_s, refine_s, polish_s, total_s;
  for (const OnlineWork& w : m.work) {
    total_s.push_back(w.total_s);
    if (w.aligns > 0) {
      coarse_s.push_back(w.coarse_s);
      refine_s.push_back(w.refine_s);
      polish_s.push_back(w.polish_s);
    }
    aligns.push_back(w.aligns);
    searches.push_back(w.searches);
    rounds.push_back(w.deskew_rounds);
    if (w.aligns > 0) register_s.push_back(w.register_s);
    if (w.candidate_s > 0.0) candidate_s.push_back(w.candidate_s);
    if (w.deskew_rounds > 0) deskew_s.push_back(w.deskew_s);
    if (w.reference_built) reference_s.push_back(w.reference_s);
  }
  auto mean = [](const std::vector<double>& v) {
    double sum = 0.0;
    for (double x : v) sum += x;
    return v.empty() ? 0.0 : sum / double(v.size());
  };
  auto max = [](const std::vector<double>& v) {
    return v.empty() ? 0.0 : *std::max_element(v.begin(), v.end());
  };
  std::printf("%s work per scan: align() calls mean %.2f (max %.0f), search attempts mean %.2f "
              "(max %.0f), de-skew rounds mean %.2f (max %.0f)\n",
              m.name.c_str(), mean(aligns), max(aligns), mean(searches), max(searches),
              mean(rounds), max(rounds));
  auto stage = [](const char* name, const std::vector<double>& v) {
    if (v.empty()) {
      std::printf("  %-22s never\n", name);
    } else {
      std::printf("  %-22s %4zu scans, median %.3f s, p95 %.3f s\n", name, v.size(),
                  quantile(v, 0.5), quantile(v, 0.95));
    }
  };
  stage("registration", register_s);
  stage("no-motion searches", candidate_s);
  stage("de-skew rounds", deskew_s);
  stage("keyframe submap", reference_s);
  std::printf("  in the align() calls:\n");
  stage("  coarse search", coarse_s);
  stage("  refine", refine_s);
  stage("  polish", polish_s);
  stage("whole step", total_s);
}

/// Each cube method's chain covariance against the truth at its keyframes (the chain's
/// nodes; the first scan, exact by definition, left out), for each chain setting.
void reportConsistency(const std::vector<Method>& table, const Trajectory& truth,
                       const std::vector<ChainCovarianceSettings>& chain_settings,
                       const std::string& label, const std::string& odometry_mode,
                       std::uint64_t seed, const std::string& path) {
  std::optional<CsvWriter> csv;
  if (!path.empty()) {
    csv.emplace(path,
                "label,odometry,world_seed,method,sigma_m,sigma_deg,drift_pct,registration_scale,"
                "keyframes,within1_x,"
                "within1_y,within1_z,within1_roll,within1_pitch,within1_yaw,beyond3_x,beyond3_y,"
                "beyond3_z,beyond3_roll,beyond3_pitch,beyond3_yaw,nees_mean,nees_median",
                CsvWriter::Mode::Append);
  }
  std::printf("chain covariance at keyframes: %% within 1 sd | %% beyond 3 sd, x y z roll pitch yaw\n");
  for (const Method& m : table) {
    if (m.covariances.empty()) continue;
    std::vector<bool> use = m.keyframe;
    if (!use.empty()) use[0] = false;
    for (std::size_t i = 0; i < chain_settings.size(); ++i) {
      const CovarianceConsistency c = covarianceConsistency(truth, m.poses, m.covariances[i], use);
      std::printf("%-14s %.3g m %.3g deg %.3g %% x%.2g: %d keyframes, within 1 sd",
                  m.name.c_str(), chain_settings[i].sigma_m, rad2deg(chain_settings[i].sigma_rad),
                  100.0 * chain_settings[i].drift_fraction, chain_settings[i].registration_scale,
                  c.poses);
      for (int a = 0; a < 6; ++a) std::printf(" %.0f", 100.0 * c.within1(a));
      std::printf(", beyond 3 sd");
      for (int a = 0; a < 6; ++a) std::printf(" %.1f", 100.0 * c.beyond3(a));
      std::printf(", NEES mean %.2f median %.2f (6 if consistent)\n", c.nees_mean, c.nees_median);
      if (!csv) continue;
      *csv << label << odometry_mode << seed << m.name << chain_settings[i].sigma_m
           << rad2deg(chain_settings[i].sigma_rad) << 100.0 * chain_settings[i].drift_fraction
           << chain_settings[i].registration_scale << c.poses;
      for (int a = 0; a < 6; ++a) *csv << c.within1(a);
      for (int a = 0; a < 6; ++a) *csv << c.beyond3(a);
      *csv << c.nees_mean << c.nees_median;
      csv->endRow();
    }
  }
}

}  // namespace

int main(int argc, char** argv) {
  std::string scene_name, dir, odometry_mode = "big", csv_path = "sequence.csv", summary_path, label;
  double length = 500.0, period = 1.5, voxel = 0.2;
  sim::SequenceSettings motion;
  std::uint64_t seed = 1;
  int submap = 3;
  double check_pct = -1, check_deg_m = -1, check_still_m = -1, check_rejected = -1,
         check_accepted_wrong = -1;
  std::vector<std::string> methods = {"cubes", "cubes-s2s", "gicp", "ndt"};
  OnlineMatcherSettings matcher_settings;
  RangeFilterSettings filter;
  std::vector<ChainCovarianceSettings> chain_settings{ChainCovarianceSettings{}};
  std::string consistency_path;
  OdometryAnchorSettings anchor_settings;
  try {
    auto& gate = matcher_settings.gate;
    for (ArgReader r(argc, argv); r.more();) {
      if (r.help()) return usage(std::cout), 0;
      if (r.algorithm(matcher_settings.registration, filter) || r.option("--scene", scene_name) ||
          r.option("--dir", dir) || r.option("--length", length) ||
          r.option("--world-seed", seed) || r.option("--odometry", odometry_mode) ||
          r.option("--period", period) || r.option("--step", motion.step) ||
          r.optionWith("--methods", [&](const std::string& v) { methods = splitList(v); }) ||
          r.option("--submap", submap) ||
          r.option("--keyframe-distance", matcher_settings.keyframes.distance) ||
          r.optionWith("--keyframe-angle",
                       [&](const std::string& v) {
                         matcher_settings.keyframes.angle =
                             deg2rad(io::parseNumber("--keyframe-angle", v));
                       }) ||
          r.option("--voxel", voxel) ||
          r.option("--no-motion-candidate", matcher_settings.no_motion_candidate) ||
          r.option("--no-motion-dense-points", matcher_settings.no_motion_dense_points) ||
          r.option("--no-odometry-dense-points", matcher_settings.no_odometry_dense_points) ||
          r.optionWith("--no-odometry-grid",
                       [&](const std::string& v) {
                         const auto [m, deg] = splitPair("--no-odometry-grid", v, "M:DEG");
                         PlanarGridSettings& g = matcher_settings.no_odometry_grid;
                         g.half_width_m = io::parseNumber("--no-odometry-grid", m);
                         g.half_yaw = deg2rad(io::parseNumber("--no-odometry-grid", deg));
                       }) ||
          r.option("--reject-degenerate", gate.reject_degenerate) ||
          r.option("--require-polish", gate.require_polish) ||
          r.option("--max-sigma", gate.max_sigma_m) || r.option("--csv", csv_path) ||
          r.option("--summary", summary_path) || r.option("--label", label) ||
          r.optionWith("--chain-sigmas",
                       [&](const std::string& v) {
                         chain_settings.clear();
                         for (const std::string& item : splitList(v)) {
                           std::vector<double> v;
                           std::size_t from = 0;
                           for (std::size_t to; (to = item.find(':', from)) != std::string::npos;
                                from = to + 1) {
                             v.push_back(io::parseNumber("--chain-sigmas", item.substr(from, to - from)));
                           }
                           v.push_back(io::parseNumber("--chain-sigmas", item.substr(from)));
                           if (v.size() != 4) {
                             throw std::invalid_argument("--chain-sigmas: '" + item +
                                                         "' is not M:DEG:PCT:SCALE");
                           }
                           ChainCovarianceSettings c;
                           c.sigma_m = v[0];
                           c.sigma_rad = deg2rad(v[1]);
                           c.drift_fraction = v[2] / 100.0;
                           c.registration_scale = v[3];
                           validate(c);
                           chain_settings.push_back(c);
                         }
                       }) ||
          r.option("--consistency", consistency_path) ||
          r.option("--anchor-sigma-m", anchor_settings.odometry_sigma_m) ||
          r.optionWith("--anchor-sigma-deg",
                       [&](const std::string& v) {
                         anchor_settings.odometry_sigma_rad =
                             deg2rad(io::parseNumber("--anchor-sigma-deg", v));
                       }) ||
          r.option("--check-pct", check_pct) || r.option("--check-deg-m", check_deg_m) ||
          r.option("--check-still-m", check_still_m) ||
          r.option("--check-rejected", check_rejected) ||
          r.option("--check-accepted-wrong", check_accepted_wrong))
        continue;
      r.unknown();
    }
    if (scene_name.empty() == dir.empty()) throw std::invalid_argument("give one of --scene or --dir");
    if (!(length > 0.0) || !(period > 0.0) || !(voxel > 0.0) || !(motion.step > 0.0)) {
      throw std::invalid_argument("--length, --period, --step and --voxel must be > 0");
    }
    const bool cv = odometry_mode == "cv", identity = odometry_mode == "identity";
    const bool has_odometry = !cv && !identity;
    const sim::OdometryError error_model =
        has_odometry ? sim::odometryErrorFromString(odometry_mode) : sim::OdometryError::None;
    validate(matcher_settings);
    validate(filter);

    std::vector<Method> table;
    for (const std::string& m : methods) {
      OnlineMatcherSettings s = matcher_settings;
      if (m == "cubes") table.push_back(cubeMethod(m, s, filter, !identity, chain_settings, anchor_settings));
      else if (m == "cubes-s2s") {
        s.keyframes.distance = 0.0, s.keyframes.angle = 0.0, s.keyframes.interval = 0.0;
        s.keyframes.submap_size = 1;
        table.push_back(cubeMethod(m, s, filter, !identity, chain_settings, anchor_settings));
      } else if (m == "cubes-submap") {
        s.keyframes.submap_size = submap;
        table.push_back(cubeMethod(m + std::to_string(submap), s, filter, !identity, chain_settings,
                                    anchor_settings));
      } else if (m == "gicp") table.push_back(peerMethod(m, runGicp, voxel, cv, matcher_settings.gate));
      else if (m == "ndt") table.push_back(peerMethod(m, runNdt, voxel, cv, matcher_settings.gate));
      else if (m == "icp") table.push_back(peerMethod(m, runIcp, voxel, cv, matcher_settings.gate));
      else if (m == "o3d-p2pl" || m == "o3d-gicp") {
        if (!open3dAvailable()) throw std::invalid_argument(m + ": this build has no Open3D");
        table.push_back(peerMethod(m, m == "o3d-p2pl" ? runOpen3dPointToPlane : runOpen3dGicp,
                                   voxel, cv, matcher_settings.gate));
      }
      else throw std::invalid_argument("unknown method: " + m);
    }

    // The scans: simulated on the fly, or read from the folder.
    std::optional<sim::Scene> scene;
    std::unique_ptr<sim::SequenceMotion> robot;
    io::Sequence sequence;
    std::size_t count = 0;
    if (!scene_name.empty()) {
      scene = sim::Scene::generate(sim::sceneTypeFromString(scene_name), seed);
      robot = std::make_unique<sim::SequenceMotion>(*scene, motion, seed + 1);
      if (label.empty()) label = scene_name;
    } else {
      sequence = io::readSequence(dir);
      count = sequence.clouds.size();
      if (label.empty()) label = dir.substr(dir.find_last_of('/') + 1);
    }
    sim::OdometrySimulator odometry(error_model, seed + 2);
    std::mt19937_64 rng(seed);
    const sim::ScannerModel model;

    Trajectory truth, odometry_poses;
    std::vector<double> distance;
    double travelled = 0.0;
    for (std::size_t k = 0;; ++k) {
      PointArray points;
      Eigen::Isometry3d pose;
      double stamp;
      if (robot) {
        if (travelled >= length) break;
        if (k > 0) robot->advance();
        pose = robot->pose();
        stamp = double(k) * period;
        points = sim::scanInBody(scene->movers.empty() ? *scene : scene->at(stamp), model, pose, rng);
      } else {
        if (k == count) break;
        // Truth relative to the first pose: the estimate starts at the truth's first pose.
        pose = sequence.truth[0].pose.inverse() * sequence.truth[k].pose;
        stamp = sequence.truth[k].stamp;
        points = io::readCloudFile(sequence.clouds[k]);
      }
      if (!truth.empty()) travelled += (pose.translation() - truth.back().translation()).norm();
      truth.push_back(pose);
      std::optional<Eigen::Isometry3d> odom;
      if (has_odometry) odom = odometry.next(pose);
      if (odom) odometry_poses.push_back(*odom);
      for (Method& m : table) m.step(m, points, stamp, odom);
      if (k % 25 == 0) std::fprintf(stderr, "scan %zu, %.0f m\n", k, travelled);
    }
    // The odometry alone and each cube chain tied to it, as rows of their own.
    if (has_odometry) {
      const std::size_t methods_run = table.size();
      for (std::size_t i = 0; i < methods_run; ++i) {
        if (table[i].anchored.size() != truth.size()) continue;
        Method a;
        a.name = table[i].name + "-anchored";
        a.poses = table[i].anchored;
        a.times = table[i].times;
        a.work = table[i].work;
        a.accepted = table[i].accepted, a.rejected = table[i].rejected;
        a.derived = true;
        table.push_back(std::move(a));
      }
      Method o;
      o.name = "odometry";
      o.poses = odometry_poses;
      o.times.assign(truth.size(), 0.0);
      o.derived = true;
      table.push_back(std::move(o));
    }

    constexpr int kCubeColumns = 15;  // aligns .. result_err_deg: blank for the peers
    CsvWriter csv(csv_path,
                  "label,odometry,method,scan,time_s,truth_x,truth_y,truth_z,truth_yaw_deg,x,y,z,"
                  "yaw_deg,aligns,searches,evaluations,deskew_rounds,reference_built,register_s,"
                  "candidate_s,deskew_s,reference_s,coarse_s,refine_s,polish_s,verdict,"
                  "result_err_m,result_err_deg");
    for (const Method& m : table) {
      for (std::size_t k = 0; k < truth.size(); ++k) {
        const Eigen::Vector3d t = truth[k].translation(), e = m.poses[k].translation();
        csv << label << odometry_mode << m.name << k << m.times[k] << t.x() << t.y() << t.z()
            << yawDeg(truth[k]) << e.x() << e.y() << e.z() << yawDeg(m.poses[k]);
        if (k < m.work.size()) {  // a cube method: its work (the peers report time only)
          const OnlineWork& w = m.work[k];
          csv << w.aligns << w.searches << w.evaluations << w.deskew_rounds
              << int(w.reference_built) << w.register_s << w.candidate_s << w.deskew_s
              << w.reference_s << w.coarse_s << w.refine_s << w.polish_s;
          csv << (k < m.verdict.size() ? toString(m.verdict[k]) : std::string());
          if (const auto err = resultError(m, truth, k)) {
            csv << err->first << err->second;
          } else {
            csv << "" << "";
          }
        } else {
          for (int i = 0; i < kCubeColumns; ++i) csv << "";
        }
        csv.endRow();
      }
    }
    std::optional<CsvWriter> summary;
    if (!summary_path.empty()) {
      summary.emplace(summary_path,
                      "label,odometry,method,scans,length_m,accepted,rejected,rpe10_pct,"
                      "rpe10_deg_m,rpe50_pct,rpe50_deg_m,rpe100_pct,rpe100_deg_m,ate_m,"
                      "still_scans,still_m,still_deg,median_time_s,max_error_m,p95_time_s,"
                      "accepted_wrong,rejected_right",
                      CsvWriter::Mode::Append);
    }
    const StationaryDrift still_truth = stationaryDrift(truth, truth);
    std::printf("%s\n", machineReport().c_str());
    std::printf("%s, odometry %s: %zu scans, %.1f m, %d standing-still runs (%d scans)\n",
                label.c_str(), odometry_mode.c_str(), truth.size(), travelled,
                still_truth.segments, still_truth.scans);
    std::printf("%-16s %6s %6s %14s %14s %14s %8s %8s %14s %9s %9s\n", "method", "acc", "rej",
                "RPE10 %|deg/m", "RPE50 %|deg/m", "RPE100 %|deg/m", "ATE m", "max m",
                "still m|deg", "median s", "p95 s");
    std::vector<std::string> failures;
    for (const Method& m : table) {
      RelativeError r[3];
      const double lengths[3] = {10.0, 50.0, 100.0};
      for (int i = 0; i < 3; ++i) r[i] = relativePoseError(truth, m.poses, lengths[i]);
      const double ate = absoluteTrajectoryError(truth, m.poses);
      // The largest position error as published, without any alignment: what the anchored
      // rows bound. Meaningful only for a chain started at the true first pose (map = world,
      // as with simulated odometry); otherwise NaN, printed "-" and left blank.
      double max_error = std::numeric_limits<double>::quiet_NaN();
      if (!truth.empty() &&
          (m.poses[0].translation() - truth[0].translation()).norm() < 1e-3 &&
          Eigen::AngleAxisd(m.poses[0].linear().transpose() * truth[0].linear()).angle() < 1e-4) {
        max_error = 0.0;
        for (std::size_t k = 0; k < truth.size(); ++k) {
          max_error =
              std::max(max_error, (m.poses[k].translation() - truth[k].translation()).norm());
        }
      }
      char max_cell[32] = "-";
      if (std::isfinite(max_error)) std::snprintf(max_cell, sizeof max_cell, "%.3f", max_error);
      const StationaryDrift sd = stationaryDrift(truth, m.poses);
      const double t_med = quantile(m.times, 0.5), t_p95 = quantile(m.times, 0.95);
      auto cell = [](const RelativeError& e) {
        char b[32];
        if (e.segments == 0) std::snprintf(b, sizeof b, "-");
        else std::snprintf(b, sizeof b, "%.2f|%.4f", e.translation_pct, e.rotation_deg_per_m);
        return std::string(b);
      };
      std::printf("%-16s %6d %6d %14s %14s %14s %8.3f %8s %8.3f|%.2f %9.3f %9.3f\n", m.name.c_str(),
                  m.accepted, m.rejected, cell(r[0]).c_str(), cell(r[1]).c_str(), cell(r[2]).c_str(),
                  ate, max_cell, sd.translation, sd.rotation_deg, t_med, t_p95);
      if (summary) {
        *summary << label << odometry_mode << m.name << truth.size() << travelled << m.accepted
                 << m.rejected;
        for (const RelativeError& e : r) {
          if (e.segments == 0) *summary << "" << "";
          else *summary << e.translation_pct << e.rotation_deg_per_m;
        }
        *summary << ate << sd.scans << sd.translation << sd.rotation_deg << t_med;
        if (std::isfinite(max_error)) *summary << max_error;
        else *summary << "";
        *summary << t_p95;
        if (!m.derived && !m.verdict.empty()) {
          const Verdicts v = countVerdicts(m, truth);
          *summary << v.accepted_wrong << v.rejected_right;
        } else {
          *summary << "" << "";
        }
        summary->endRow();
      }
      if (m.name.rfind("cubes", 0) == 0 && !m.derived) {
        const RelativeError* longest = nullptr;
        for (const RelativeError& e : r) {
          if (e.segments > 0) longest = &e;
        }
        char b[160];
        if (!longest && (check_pct >= 0 || check_deg_m >= 0)) {
          // A drift bound that nothing could be checked against fails rather than passes.
          std::snprintf(b, sizeof b, "%s: no 10 m segment to check the drift bounds on",
                        m.name.c_str());
          failures.push_back(b);
        }
        if (longest && check_pct >= 0 && longest->translation_pct > check_pct) {
          std::snprintf(b, sizeof b, "%s: %.2f %% over %.0f m > %.2f %%", m.name.c_str(),
                        longest->translation_pct, longest->length, check_pct);
          failures.push_back(b);
        }
        if (longest && check_deg_m >= 0 && longest->rotation_deg_per_m > check_deg_m) {
          std::snprintf(b, sizeof b, "%s: %.4f deg/m over %.0f m > %.4f", m.name.c_str(),
                        longest->rotation_deg_per_m, longest->length, check_deg_m);
          failures.push_back(b);
        }
        if (check_still_m >= 0 && sd.translation > check_still_m) {
          std::snprintf(b, sizeof b, "%s: standing-still drift %.3f m > %.3f m", m.name.c_str(),
                        sd.translation, check_still_m);
          failures.push_back(b);
        }
        if (check_rejected >= 0 && m.rejected > check_rejected) {
          std::snprintf(b, sizeof b, "%s: %d scans rejected > %.0f", m.name.c_str(), m.rejected,
                        check_rejected);
          failures.push_back(b);
        }
        const int accepted_wrong = countVerdicts(m, truth).accepted_wrong;
        if (check_accepted_wrong >= 0 && accepted_wrong > check_accepted_wrong) {
          std::snprintf(b, sizeof b, "%s: %d accepted results wrong > %.0f", m.name.c_str(),
                        accepted_wrong, check_accepted_wrong);
          failures.push_back(b);
        }
      }
    }
    for (const Method& m : table) {
      if (!m.derived && !m.work.empty()) reportWork(m);
      if (!m.derived && !m.verdict.empty()) reportVerdicts(m, countVerdicts(m, truth));
    }
    reportConsistency(table, truth, chain_settings, label, odometry_mode, seed, consistency_path);
    for (const std::string& f : failures) std::fprintf(stderr, "CHECK FAILED %s\n", f.c_str());
    if (!failures.empty()) return 2;
  } catch (const std::exception& e) {
    std::fprintf(stderr, "sequence_benchmark: %s\n", e.what());
    return 1;
  }
  return 0;
}
