// point_scaling [--scene urban] [--points 10000,...,300000] [--trials 10] [options]
// How the cube method's time grows with the sweep's size: for each target point count, the
// simulated tilting scanner's angular steps are scaled (both by the same factor) until a sweep
// holds about that many points; a pair of such sweeps (2 m and 8 deg of yaw apart, exact truth)
// is registered from guesses within +-1 m / +-8 deg. Prints, per size, the points given and
// evaluated (after the collapse), the median time [ms] (grids included, as in `benchmark`),
// the time per 1,000 points given, and the successes (Es < 0.10 m, Ea < 1 deg).
#include <chrono>
#include <cmath>
#include <cstdio>
#include <iostream>
#include <optional>
#include <random>
#include <string>
#include <vector>

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

/// A scanner whose sweep holds about `target` points where the default model's sweep holds
/// `default_points`: the default phi and psi steps divided by sqrt(target / default_points).
sim::ScannerModel scaledScanner(std::size_t default_points, std::size_t target) {
  sim::ScannerModel model;
  const double f = std::sqrt(double(target) / double(default_points));
  model.phi_step_deg /= f;
  model.psi_step_deg /= f;
  return model;
}

}  // namespace

int main(int argc, char** argv) {
  std::string scene_name = "urban";
  std::vector<std::size_t> sizes = {10000, 20000, 50000, 100000, 200000, 300000};
  int trials = 10;
  std::uint64_t seed = 1;
  std::string csv_path;
  int require_success = 0;
  RegistrationSettings settings = RegistrationSettings{};
  RangeFilterSettings filter;
  try {
    for (ArgReader r(argc, argv); r.more();) {
      if (r.help()) {
        std::cout << "usage: point_scaling [options]\n"
                     "  --scene NAME          world type (default urban; see scene_benchmark)\n"
                     "  --points N,N,...      target points per sweep (default\n"
                     "                        10000,20000,50000,100000,200000,300000)\n"
                     "  --trials T            registrations per size, guesses within +-1 m /\n"
                     "                        +-8 deg (default 10)\n"
                     "  --scene-seed N        seed of the world, the noise and the guesses (default 1)\n"
                     "  --csv FILE            one row per size\n"
                     "  --require-success K   exit 1 when a size has fewer than K successes\n"
                  << algorithmOptionsHelp();
        return 0;
      }
      if (r.algorithm(settings, filter) || r.option("--scene", scene_name) ||
          r.optionWith("--points",
                       [&](const std::string& v) {
                         sizes.clear();
                         for (const std::string& s : splitList(v)) {
                           const double n = io::parseNumber("--points", s);
                           if (!(n >= 1000 && n <= 5e6))
                             throw std::invalid_argument("--points: each in [1000, 5e6]");
                           sizes.push_back(std::size_t(n));
                         }
                       }) ||
          r.option("--trials", trials) || r.option("--scene-seed", seed) ||
          r.option("--require-success", require_success) || r.option("--csv", csv_path))
        continue;
      r.unknown();
    }
    if (trials < 1) throw std::invalid_argument("--trials must be >= 1");
    validate(settings);
    const sim::Scene scene = sim::Scene::generate(sim::sceneTypeFromString(scene_name), seed);
    // Sensors 1 m above the street's ground, 2 m and 8 deg of yaw apart.
    Eigen::Isometry3d a = Eigen::Isometry3d::Identity();
    a.translation() = Eigen::Vector3d(30.0, 0.0, scene.groundHeight(30.0, 0.0) + 1.0);
    Eigen::Isometry3d motion = Eigen::Isometry3d::Identity();
    motion.linear() = rotationFromRpy(0.0, 0.0, deg2rad(8.0));
    motion.translation() = Eigen::Vector3d(2.0, 0.3, 0.0);
    const Eigen::Isometry3d b = a * motion;
    // The default sweep's size, counted once: every target scales from it.
    std::mt19937_64 count_rng(1);
    const std::size_t default_points = sim::scanInBody(scene, sim::ScannerModel{}, a, count_rng).size();
    if (default_points == 0) throw std::runtime_error("the default sweep of this scene has no points");

    std::printf("%s\n", machineReport().c_str());
    std::printf("scene %s (seed %llu), %d trials per size, guesses within +-1 m / +-8 deg\n",
                scene_name.c_str(), static_cast<unsigned long long>(seed), trials);
    std::printf("%10s %10s %10s %12s %16s %9s\n", "target", "points", "used", "median ms",
                "ms per 1k points", "success");
    std::optional<CsvWriter> csv;
    if (!csv_path.empty())
      csv.emplace(csv_path,
                  "target,points,points_used,median_time_s,time_per_kpoint_s,successes,trials");
    CubeRegistration reg(settings);
    int short_sizes = 0;
    for (std::size_t target : sizes) {
      const sim::ScannerModel model = scaledScanner(default_points, target);
      std::mt19937_64 rng(seed * 7919 + target);
      const PointArray ref = filterPoints(sim::scanInBody(scene, model, a, rng), filter);
      const PointArray scan = filterPoints(sim::scanInBody(scene, model, b, rng), filter);
      std::vector<double> times;
      int ok = 0;
      std::size_t used = 0;
      for (int t = 0; t < trials; ++t) {
        const Eigen::Isometry3d guess = motion * sim::randomTransform(rng, 1.0, 8.0);
        const auto t0 = std::chrono::steady_clock::now();
        reg.setReference(ref);  // timed, as in `benchmark`
        const RegistrationResult r = reg.align(scan, isometryToPose(guess));
        times.push_back(std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count());
        ok += poseError(r.transform, motion).success();
        used = r.points_used;
      }
      const double med = quantile(times, 0.5);
      const double per_k = med / (double(scan.size()) / 1000.0);
      std::printf("%10zu %10zu %10zu %12.1f %16.3f %6d/%-2d\n", target, scan.size(), used,
                  med * 1e3, per_k * 1e3, ok, trials);
      std::fflush(stdout);
      short_sizes += ok < require_success;
      if (csv) {
        *csv << target << scan.size() << used << med << per_k << ok << trials;
        csv->endRow();
      }
    }
    if (short_sizes > 0) {
      std::fprintf(stderr, "point_scaling: %d sizes with fewer than %d successes\n", short_sizes,
                   require_success);
      return 1;
    }
  } catch (const std::exception& e) {
    std::fprintf(stderr, "point_scaling: %s\n", e.what());
    return 1;
  }
  return 0;
}
