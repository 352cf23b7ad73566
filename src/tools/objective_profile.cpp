// objective_profile: J along the driving direction between two sweeps of the simulated tilting
// scanner taken `--step` m apart, on all scan points and on the densely sampled ones
// (dense_sampling.h). Shows J's false maximum at "no motion" (docs/experiments.md, "The
// no-motion maximum and dense_points"). With --turn, the second sweep is taken at the same place
// after turning on the spot, and J is laid along the yaw instead.
//   objective_profile --scene hall --seed 1 --step 1.5
//   objective_profile --scene park --turn 30
#include <cstdio>
#include <iostream>
#include <random>
#include <string>
#include <vector>

#include "cube_scan_matcher/core/dense_sampling.h"
#include "cube_scan_matcher/core/registration.h"
#include "cube_scan_matcher/io/dataset.h"
#include "cube_scan_matcher/sim/tilting_scanner.h"
#include "arg_reader.h"
#include "settings_cli.h"

using namespace cube_scan_matcher;

int main(int argc, char** argv) {
  std::string scene_name = "hall";
  std::uint64_t seed = 1;
  double step = 1.5;
  double turn_deg = 0.0;
  int dense = 4;
  std::vector<double> starts = {10, 30, 50, 70, 90};
  try {
    for (tools::ArgReader r(argc, argv); r.more();) {
      if (r.help()) {
        std::cout << "usage: objective_profile [--scene NAME] [--seed N] [--step M] [--x LIST]\n"
                     "                         [--dense-points N] [--turn DEG]\n"
                     "  J (E = 0.5 m, default collapse) of the second sweep laid at x = -0.5..1.5\n"
                     "  times the step (the truth at 1, 'no motion' at 0), along the street from\n"
                     "  each start x in LIST (default 10,30,50,70,90), on all points and on the\n"
                     "  points of E-cubes holding >= N points (default 4). --turn DEG: the second\n"
                     "  sweep taken at the same place after a turn of DEG on the spot, J laid at\n"
                     "  yaw = -0.5..1.5 times DEG\n";
        return 0;
      }
      if (r.option("--scene", scene_name) || r.option("--seed", seed) ||
          r.option("--step", step) || r.option("--turn", turn_deg) || r.option("--dense-points", dense) ||
          r.optionWith("--x", [&](const std::string& v) {
            starts.clear();
            for (const std::string& x : tools::splitList(v)) starts.push_back(io::parseNumber("--x", x));
          }))
        continue;
      r.unknown();
    }
    const sim::Scene scene = sim::Scene::generate(sim::sceneTypeFromString(scene_name), seed);
    const sim::ScannerModel model;
    std::mt19937_64 rng(seed + 4);
    const bool turn = turn_deg != 0.0;
    if (turn) {
      std::printf("%s seed %llu, turn %.1f deg on the spot; J at yaw = -0.5..1.5 x turn (0.25 x turn apart)\n",
                  scene_name.c_str(), static_cast<unsigned long long>(seed), turn_deg);
    } else {
      std::printf("%s seed %llu, step %.2f m; J at x = -0.5..1.5 x step (0.25 x step apart)\n",
                  scene_name.c_str(), static_cast<unsigned long long>(seed), step);
    }
    for (double x0 : starts) {
      Eigen::Isometry3d a = Eigen::Isometry3d::Identity(), b = Eigen::Isometry3d::Identity();
      a.translation() = Eigen::Vector3d(x0, 0.0, scene.groundHeight(x0, 0.0) + 1.0);
      const double x1 = turn ? x0 : x0 + step;
      b.translation() = Eigen::Vector3d(x1, 0.0, scene.groundHeight(x1, 0.0) + 1.0);
      if (turn) b.linear() = Eigen::AngleAxisd(deg2rad(turn_deg), Eigen::Vector3d::UnitZ()).matrix();
      CubeRegistration reg(RegistrationSettings{});
      reg.setReference(sim::scanInBody(scene, model, a, rng));
      const PointArray scan = sim::scanInBody(scene, model, b, rng);
      const PointArray dense_scan =
          dense > 1 ? keepDenselySampled(scan, reg.settings().grid.cube_edge, dense) : scan;
      const Pose6 truth = isometryToPose(a.inverse() * b);
      for (const auto* points : {&scan, &dense_scan}) {
        std::printf("x0 %5.1f %-6s", x0, points == &scan ? "all" : "dense");
        for (double f = -0.5; f <= 1.51; f += 0.25) {
          Pose6 p = truth;
          if (turn) {
            p[5] = f * deg2rad(turn_deg);
          } else {
            p[0] = f * step;
          }
          std::printf(" %6d%s", reg.score(*points, p), f == 0.0 ? "o" : f == 1.0 ? "*" : " ");
        }
        std::printf("\n");
      }
    }
    std::printf("o: no motion, *: the truth\n");
  } catch (const std::exception& e) {
    std::fprintf(stderr, "objective_profile: %s\n", e.what());
    return 1;
  }
  return 0;
}
