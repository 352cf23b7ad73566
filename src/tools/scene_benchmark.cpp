// scene_benchmark: pairwise registration over many simulated worlds with exact truth.
// Per trial: a seeded world of a scene type, a start pose on its street, a motion (the paper's
// Table 1 motion of that scene type, or a random 1-5 m / +-45 deg motion), two sweeps of the
// simulated tilting scanner, and registrations from guesses = truth with uniform errors within
// the "big" (+-1 m, +-8 deg) and "small" (+-0.25 m, +-2 deg) bounds. Reports per scene type,
// motion and bounds: successes (Es < 0.10 m and Ea < 1 deg), median / p95 / max Es and Ea,
// median time, and the acceptance gate's verdict on every trial (false accepts: accepted but
// wrong; false rejects: rejected but right).
//   scene_benchmark --worlds 20 --trials 10 --csv scenes.csv
#include <algorithm>
#include <cstdio>
#include <iostream>
#include <map>
#include <random>
#include <string>
#include <tuple>
#include <vector>

#include "cube_scan_matcher/core/acceptance_gate.h"
#include "cube_scan_matcher/core/filters.h"
#include "cube_scan_matcher/core/metrics.h"
#include "cube_scan_matcher/core/registration.h"
#include "cube_scan_matcher/sim/motion.h"
#include "cube_scan_matcher/sim/tilting_scanner.h"
#include "arg_reader.h"
#include "csv_writer.h"
#include "settings_cli.h"

using namespace cube_scan_matcher;
using namespace cube_scan_matcher::tools;

namespace {

void usage(std::ostream& os) {
  os << "usage: scene_benchmark [options]\n"
        "  --scenes LIST         comma list of scene types: the paper's hall, urban, park,\n"
        "                        natural (\"paper\", the default), and square, slope, forest,\n"
        "                        tunnel, wall, crowd (\"robot\"); \"all\" for the ten\n"
        "  --artefacts           the sensor's artefacts: 2 % dropouts, mixed pixels at half\n"
        "                        the range edges, 30 no-return patches per world\n"
        "  --sweep-interval S    [s] time between the two sweeps: what moves in crowd\n"
        "                        (default 2)\n"
        "  --worlds N            worlds (scene seeds 1..N) per scene type (default 20)\n"
        "  --first-world F       scene seeds F..F+N-1 instead (default 1); a world's pairs do\n"
        "                        not depend on the others\n"
        "  --trials N            start poses per world and motion (default 10)\n"
        "  --motions LIST        table1 (the paper's Table 1 motion of the scene type),\n"
        "                        random (1-5 m, +-45 deg yaw) (default table1,random)\n"
        "  --initial-errors B    big (+-1 m, +-8 deg), small (+-0.25 m, +-2 deg) or both\n"
        "                        (default both)\n"
        "  --trial-seed N        seed of start poses, motions, noise and guesses (default 1;\n"
        "                        --seed is the GNMM's)\n"
        "  --csv FILE            one row per registration (default scenes.csv)\n"
        "  --check-success P     exit 2 unless every (scene, motion, bounds) group succeeds in\n"
        "                        >= P %% of its trials (default off)\n"
        "  --check-false-accepts N  exit 2 if more than N trials in all are accepted by the\n"
        "                        gate but wrong (default off)\n"
        "  --check-accepted N    exit 2 if fewer than N trials in all are accepted by the gate\n"
        "                        and right (default off): a gate that rejects everything fails\n"
        "  --repeat K            also register each pair from K starts in each bounds and\n"
        "                        report the repeatability: the median over pairs of each\n"
        "                        pair's median distance to its own median pose (default 1 = off)\n"
        "  --check-repeatability M D  exit 2 unless every group's repeatability is <= M [m]\n"
        "                        and D [deg] (needs --repeat >= 2; default off)\n"
     << algorithmOptionsHelp();
}

struct Bounds {
  std::string name;
  double t, a_deg;
};

struct Row {
  std::string scene, motion, bounds;
  int world = 0, trial = 0;
  double es = 0, ea = 0, time = 0;
  int J = 0, J_guess = 0, J_truth = 0;
  GateReason reason = GateReason::Accepted;
  /// Error [x y z m, rotation about x y z rad] (left: R_est R_true^-1) and the result's
  /// standard deviations in the same coordinates (0 when it has no covariance).
  Eigen::Matrix<double, 6, 1> error = Eigen::Matrix<double, 6, 1>::Zero();
  Eigen::Matrix<double, 6, 1> sigma = Eigen::Matrix<double, 6, 1>::Zero();
  bool degenerate = false;
  double weak_ratio = 0.0, t_weak_ratio = 0.0;
  int J_prepolish = 0;
  double shift_m = 0.0, shift_deg = 0.0;
  bool polished = false;
  double plane_rms = 0.0, plane_fraction = 0.0;
  int agreeing = 0, J_runner_up = 0, J_coarse = 0, attempts = 1, J_axis = 0;
  bool axis_moved = false, consensus = false;
  /// The largest |error| / sigma over the six axes (0 without a covariance).
  double maxZ() const {
    double z = 0.0;
    for (int k = 0; k < 6; ++k) {
      if (sigma(k) > 0.0) z = std::max(z, std::abs(error(k)) / sigma(k));
    }
    return z;
  }
  bool hasCovariance() const { return sigma.maxCoeff() > 0.0; }
  bool success() const { return PoseError{es, ea}.success(); }
  bool accepted() const { return reason == GateReason::Accepted; }
};

/// A start pose on the scene's street (x in [0, 100] m, |y| <= 1 m, heading within +-10 deg,
/// base 1 m above the ground) whose sensor is in free space in the first sweep's scene and the
/// sensor after `motion` in the second's (they differ when things move).
Eigen::Isometry3d startPose(const sim::Scene& scene, const sim::Scene& scene_b,
                            const Eigen::Isometry3d& motion, std::mt19937_64& rng) {
  std::uniform_real_distribution<double> ux(0.0, 100.0), uy(-1.0, 1.0), uh(-10.0, 10.0);
  for (int attempt = 0; attempt < 200; ++attempt) {
    const double x = ux(rng), y = uy(rng);
    Eigen::Isometry3d a = Eigen::Isometry3d::Identity();
    a.linear() = rotationFromRpy(0.0, 0.0, deg2rad(uh(rng)));
    a.translation() = Eigen::Vector3d(x, y, scene.groundHeight(x, y) + 1.0);
    const Eigen::Isometry3d b = a * motion;
    if (!scene.insideSolid(a.translation(), 0.3) && !scene_b.insideSolid(b.translation(), 0.3))
      return a;
  }
  throw std::runtime_error("no free start pose found for this world and motion");
}

double median(const std::vector<double>& v) { return quantile(v, 0.5); }

}  // namespace

int main(int argc, char** argv) {
  std::vector<std::string> scenes = {"hall", "urban", "park", "natural"};
  std::vector<std::string> motions = {"table1", "random"};
  std::vector<Bounds> bounds = {{"big", 1.0, 8.0}, {"small", 0.25, 2.0}};
  int worlds = 20, trials = 10, first_world = 1;
  std::uint64_t seed = 1;
  std::string csv_path = "scenes.csv";
  double check_success = -1, check_false_accepts = -1, check_accepted = -1;
  int repeat = 1;
  double check_rep_m = -1, check_rep_deg = -1;
  bool artefacts = false;
  double sweep_interval = 2.0;
  RegistrationSettings settings;
  RangeFilterSettings filter;
  try {
    auto bounds_of = [&](const std::string& v) {
      if (v == "big") bounds = {{"big", 1.0, 8.0}};
      else if (v == "small") bounds = {{"small", 0.25, 2.0}};
      else if (v == "both") bounds = {{"big", 1.0, 8.0}, {"small", 0.25, 2.0}};
      else throw std::invalid_argument("--initial-errors: expected big, small or both");
    };
    for (ArgReader r(argc, argv); r.more();) {
      if (r.help()) return usage(std::cout), 0;
      if (r.algorithm(settings, filter) || r.flag("--artefacts", artefacts) ||
          r.optionWith("--scenes",
                       [&](const std::string& v) { scenes = sim::expandSceneNames(splitList(v)); }) ||
          r.option("--sweep-interval", sweep_interval) || r.option("--worlds", worlds) ||
          r.option("--first-world", first_world) || r.option("--trials", trials) ||
          r.optionWith("--motions", [&](const std::string& v) { motions = splitList(v); }) ||
          r.optionWith("--initial-errors", bounds_of) || r.option("--trial-seed", seed) ||
          r.option("--csv", csv_path) || r.option("--check-success", check_success) ||
          r.option("--check-false-accepts", check_false_accepts) ||
          r.option("--check-accepted", check_accepted) || r.option("--repeat", repeat) ||
          r.optionWith("--check-repeatability", 2, [&](const std::vector<std::string>& v) {
            check_rep_m = io::parseNumber("--check-repeatability", v[0]);
            check_rep_deg = io::parseNumber("--check-repeatability", v[1]);
          }))
        continue;
      r.unknown();
    }
    if (!(sweep_interval >= 0.0)) throw std::invalid_argument("--sweep-interval must be >= 0");
    if (worlds < 1 || trials < 1 || first_world < 1) {
      throw std::invalid_argument("--worlds, --first-world and --trials must be >= 1");
    }
    if (repeat < 1) throw std::invalid_argument("--repeat must be >= 1");
    if (check_rep_m >= 0 && repeat < 2)
      throw std::invalid_argument("--check-repeatability needs --repeat >= 2");
    for (const std::string& m : motions) {
      if (m != "table1" && m != "random") throw std::invalid_argument("unknown motion: " + m);
    }
    validate(settings);
    validate(filter);

    CsvWriter csv(csv_path,
                  "scene,world,trial,motion,bounds,Es_m,Ea_deg,time_s,J,J_guess,J_truth,gate,"
                  "success,ex_m,ey_m,ez_m,erx_rad,ery_rad,erz_rad,sx_m,sy_m,sz_m,srx_rad,sry_rad,"
                  "srz_rad,degenerate,weak_ratio,polished,plane_rms_m,plane_fraction,"
                  "starts_agreeing,J_runner_up,J_coarse,t_weak_ratio,attempts,J_axis,axis_moved,"
                  "consensus,J_prepolish,polish_shift_m,polish_shift_deg");
    CubeRegistration reg(settings);
    const GateSettings gate_settings;
    const sim::ScannerModel model = artefacts ? sim::scannerWithArtefacts() : sim::ScannerModel{};
    std::vector<Row> rows;
    // Per (scene, motion, bounds): each repeated pair's repeatability.
    std::map<std::tuple<std::string, std::string, std::string>, std::vector<Repeatability>> reps;
    for (const std::string& scene_name : scenes) {
      const sim::SceneType type = sim::sceneTypeFromString(scene_name);
      for (int w = first_world; w < first_world + worlds; ++w) {
        sim::Scene world = sim::Scene::generate(type, std::uint64_t(w));
        std::mt19937_64 rng(seed * 1000003ULL + std::uint64_t(w) * 7919ULL + std::uint64_t(type));
        if (artefacts) {
          std::mt19937_64 patch_rng(std::uint64_t(w) * 104729ULL + std::uint64_t(type));
          sim::addNoReturnPatches(world, patch_rng, 30);
        }
        // The scenes of the two sweeps (equal unless something moves).
        const sim::Scene scene = world.at(0.0), scene_b = world.at(sweep_interval);
        for (const std::string& motion_name : motions) {
          for (int t = 0; t < trials; ++t) {
            const Eigen::Isometry3d motion =
                motion_name == "table1" ? sim::paperTable1Motion(type) : sim::randomPairMotion(rng);
            const Eigen::Isometry3d a = startPose(scene, scene_b, motion, rng), b = a * motion;
            // The reference is the first sweep, the scan the second: truth = T_a^-1 T_b.
            reg.setReference(filterPoints(sim::scanInBody(scene, model, a, rng), filter));
            const PointArray scan = filterPoints(sim::scanInBody(scene_b, model, b, rng), filter);
            const int j_truth = reg.score(scan, isometryToPose(motion));
            for (const Bounds& bd : bounds) {
              const Pose6 guess = isometryToPose(motion * sim::randomTransform(rng, bd.t, bd.a_deg));
              const RegistrationResult r = reg.align(scan, guess);
              const PoseError e = poseError(r.transform, motion);
              Row row{scene_name, motion_name, bd.name, w, t, e.es_m, e.ea_deg, r.time_s,
                      r.J, r.J_guess, j_truth,
                      r.ok() ? gate(r, guess, gate_settings) : GateReason::RegistrationFailed};
              row.error.head<3>() = r.transform.translation() - motion.translation();
              const Eigen::AngleAxisd d(r.transform.linear() * motion.linear().transpose());
              row.error.tail<3>() = d.angle() * d.axis();
              row.sigma = r.covariance.diagonal().cwiseMax(0.0).cwiseSqrt();
              row.degenerate = r.degenerate;
              row.weak_ratio = r.weak_ratio;
              row.t_weak_ratio = r.translation_weak_ratio;
              row.attempts = r.attempts;
              row.J_axis = r.J_axis;
              row.axis_moved = r.axis_moved;
              row.consensus = r.consensus;
              row.polished = r.polished;
              row.plane_rms = r.plane_rms;
              row.agreeing = r.starts_agreeing;
              row.J_runner_up = r.J_runner_up;
              row.J_coarse = r.J_coarse;
              row.J_prepolish = r.J_prepolish;
              row.shift_m = r.polish_shift_m;
              row.shift_deg = rad2deg(r.polish_shift_rad);
              row.plane_fraction =
                  r.polish_points ? double(r.plane_correspondences) / r.polish_points : 0.0;
              csv << row.scene << w << t << row.motion << row.bounds << row.es << row.ea
                  << row.time << row.J << row.J_guess << row.J_truth << toString(row.reason)
                  << int(row.success());
              for (int k = 0; k < 6; ++k) csv << row.error(k);
              for (int k = 0; k < 6; ++k) csv << row.sigma(k);
              csv << int(row.degenerate) << row.weak_ratio << int(row.polished) << row.plane_rms
                  << row.plane_fraction << row.agreeing << row.J_runner_up << row.J_coarse
                  << row.t_weak_ratio << row.attempts << row.J_axis << int(row.axis_moved)
                  << int(row.consensus) << row.J_prepolish << row.shift_m << row.shift_deg;
              csv.endRow();
              rows.push_back(row);
              if (repeat > 1) {
                std::vector<Eigen::Isometry3d> estimates{r.transform};
                for (int k = 1; k < repeat; ++k) {
                  const Pose6 g = isometryToPose(motion * sim::randomTransform(rng, bd.t, bd.a_deg));
                  estimates.push_back(reg.align(scan, g).transform);
                }
                reps[{scene_name, motion_name, bd.name}].push_back(repeatability(estimates));
              }
            }
          }
        }
        std::fprintf(stderr, "%s: world %d (%d of %d)\n", scene_name.c_str(), w,
                     w - first_world + 1, worlds);
      }
    }

    // Per (scene, motion, bounds) group.
    std::printf("%s\n", machineReport().c_str());
    std::printf("%-8s %-7s %-6s %9s %22s %22s %9s %5s %5s %5s %6s %14s %15s\n", "scene", "motion", "bounds",
                "success", "Es med|p95|max [m]", "Ea med|p95|max [deg]", "median s", "acc",
                "FA", "FR", ">3sd", "sd_t|sd_r", repeat > 1 ? "rep [m]|[deg]" : "");
    std::map<std::tuple<std::string, std::string, std::string>, std::vector<const Row*>> groups;
    for (const Row& r : rows) groups[{r.scene, r.motion, r.bounds}].push_back(&r);
    std::vector<std::string> failures;
    int false_accepts = 0, accepted_right = 0;
    for (const auto& [key, group] : groups) {
      std::vector<double> es, ea, time;
      std::vector<double> sd_t, sd_r;
      int ok = 0, acc = 0, fa = 0, fr = 0, with_cov = 0, beyond3 = 0;
      for (const Row* r : group) {
        if (r->accepted() && r->hasCovariance()) {
          ++with_cov;
          beyond3 += r->maxZ() > 3.0;
          sd_t.push_back(r->sigma.head<3>().norm());
          sd_r.push_back(rad2deg(r->sigma.tail<3>().norm()));
        }
        es.push_back(r->es), ea.push_back(r->ea), time.push_back(r->time);
        ok += r->success();
        acc += r->accepted();
        fa += r->accepted() && !r->success();
        fr += !r->accepted() && r->success();
      }
      false_accepts += fa;
      accepted_right += acc - fa;
      const double pct = 100.0 * ok / double(group.size());
      // Repeatability: the median over the group's pairs.
      std::vector<double> rep_m, rep_deg;
      for (const Repeatability& q : reps[key]) rep_m.push_back(q.median_m), rep_deg.push_back(q.median_deg);
      char rep_text[48] = "";
      if (!rep_m.empty()) std::snprintf(rep_text, sizeof rep_text, "%7.4f|%7.4f", median(rep_m), median(rep_deg));
      std::printf("%-8s %-7s %-6s %4d/%-4zu %6.3f|%6.3f|%7.3f %6.2f|%6.2f|%7.2f %9.3f %5d %5d %5d "
                  "%5.1f%% %6.4f|%6.3f %15s\n",
                  std::get<0>(key).c_str(), std::get<1>(key).c_str(), std::get<2>(key).c_str(), ok,
                  group.size(), median(es), quantile(es, 0.95),
                  *std::max_element(es.begin(), es.end()), median(ea), quantile(ea, 0.95),
                  *std::max_element(ea.begin(), ea.end()), median(time), acc, fa, fr,
                  with_cov ? 100.0 * beyond3 / with_cov : 0.0, sd_t.empty() ? 0.0 : median(sd_t),
                  sd_r.empty() ? 0.0 : median(sd_r), rep_text);
      if (check_rep_m >= 0 && !rep_m.empty() &&
          (median(rep_m) > check_rep_m || median(rep_deg) > check_rep_deg)) {
        char b[200];
        std::snprintf(b, sizeof b, "%s %s %s: repeatability %.4f m / %.4f deg > %.4f m / %.4f deg",
                      std::get<0>(key).c_str(), std::get<1>(key).c_str(), std::get<2>(key).c_str(),
                      median(rep_m), median(rep_deg), check_rep_m, check_rep_deg);
        failures.push_back(b);
      }
      if (check_success >= 0 && pct < check_success) {
        char b[160];
        std::snprintf(b, sizeof b, "%s %s %s: %.1f %% successes < %.1f %%", std::get<0>(key).c_str(),
                      std::get<1>(key).c_str(), std::get<2>(key).c_str(), pct, check_success);
        failures.push_back(b);
      }
    }
    std::printf("success: Es < 0.10 m and Ea < 1 deg; acc: accepted by the gate (GateSettings "
                "defaults); FA: accepted but wrong; FR: rejected but right; >3sd: accepted results with an axis's error beyond 3 predicted "
                "standard deviations; sd_t|sd_r: median predicted sd [m]|[deg] (norm over axes); "
                "rep: median over the pairs of each one's median distance to its own median pose "
                "from --repeat starts; CSV: %s\n",
                csv_path.c_str());
    if (check_false_accepts >= 0 && false_accepts > check_false_accepts) {
      failures.push_back(std::to_string(false_accepts) + " false accepts > " +
                         std::to_string(int(check_false_accepts)));
    }
    if (check_accepted >= 0 && accepted_right < check_accepted) {
      failures.push_back(std::to_string(accepted_right) + " accepted right results < " +
                         std::to_string(int(check_accepted)));
    }
    for (const std::string& f : failures) std::fprintf(stderr, "CHECK FAILED %s\n", f.c_str());
    if (!failures.empty()) return 2;
  } catch (const std::exception& e) {
    std::fprintf(stderr, "scene_benchmark: %s\n", e.what());
    return 1;
  }
  return 0;
}
