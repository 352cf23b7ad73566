// simulate_and_register [--scene NAME] [--sweeps N] [--odometry-error small|big] [--seed N]
// The built-in demo: a simulated tilting scanner (paper section 3.1) drives through a
// procedural scene; each sweep is registered to the previous one from an odometry guess with
// random errors, and the per-sweep errors against the exact truth are printed (eqs. 7-8).
#include <algorithm>
#include <cstdio>
#include <iostream>
#include <random>
#include <string>
#include <vector>

#include "cube_scan_matcher/core/metrics.h"
#include "cube_scan_matcher/core/registration.h"
#include "cube_scan_matcher/sim/motion.h"
#include "cube_scan_matcher/sim/tilting_scanner.h"
#include "arg_reader.h"
#include "settings_cli.h"

using namespace cube_scan_matcher;

int main(int argc, char** argv) {
  std::string scene_name = "urban";
  int sweeps = 6;
  std::string odometry_error = "small";
  std::uint64_t seed = 1;
  RegistrationSettings settings = RegistrationSettings{};
  RangeFilterSettings filter;
  try {
    for (tools::ArgReader r(argc, argv); r.more();) {
      if (r.help()) {
        std::cout << "usage: simulate_and_register [options]\n"
                     "  --scene NAME          hall, urban, park, natural, square, slope, forest, tunnel,\n"
                     "                        wall or crowd (default urban; the crowd stands still)\n"
                     "  --sweeps N            sweeps to simulate (default 6)\n"
                     "  --odometry-error B    none, small (+-0.25 m, +-2 deg), big (+-1 m, +-8 deg)\n"
                     "                        uniform errors on each odometry increment, or drift\n"
                     "                        (default small)\n"
                     "  --scene-seed N        seed of the world and the noise (default 1)\n"
                  << tools::algorithmOptionsHelp();
        return 0;
      }
      if (r.algorithm(settings, filter) || r.option("--scene", scene_name) ||
          r.option("--sweeps", sweeps) || r.option("--scene-seed", seed) ||
          r.option("--odometry-error", odometry_error))
        continue;
      r.unknown();
    }
    if (sweeps < 2) throw std::invalid_argument("--sweeps must be >= 2");
    const sim::Scene scene = sim::Scene::generate(sim::sceneTypeFromString(scene_name), seed);
    const sim::ScannerModel model;
    sim::RobotMotion robot(scene, sim::MotionSettings{}, seed + 1);
    sim::OdometrySimulator odometry(sim::odometryErrorFromString(odometry_error), seed + 2);
    std::mt19937_64 rng(seed);
    Eigen::Isometry3d mount = Eigen::Isometry3d::Identity();
    mount.linear() = sim::sensorToBodyRotation();

    // Registration in the sensor frame: the scan of sweep k to that of sweep k-1.
    CubeRegistration reg(settings);
    Eigen::Isometry3d prev_sensor = robot.pose() * mount;
    Eigen::Isometry3d prev_odom = odometry.next(robot.pose()) * mount;
    reg.setReference(filterPoints(sim::scan(scene, model, prev_sensor, rng), filter));
    std::printf("scene %s, %d sweeps of %d x %d beams, odometry errors: %s\n", scene_name.c_str(),
                sweeps, model.phiCount(), model.psiCount(), odometry_error.c_str());
    std::printf("%5s %8s %10s %10s %10s %10s %8s %8s %8s\n", "sweep", "points", "Es guess",
                "Es [m]", "Ea [deg]", "time [s]", "J/l", "J", "J truth");
    std::vector<double> es, ea;
    int ok = 0;
    for (int k = 1; k < sweeps; ++k) {
      robot.advance();
      const Eigen::Isometry3d sensor = robot.pose() * mount;
      const Eigen::Isometry3d odom = odometry.next(robot.pose()) * mount;
      const PointArray pts = filterPoints(sim::scan(scene, model, sensor, rng), filter);
      const Eigen::Isometry3d truth = prev_sensor.inverse() * sensor;
      const Pose6 guess = isometryToPose(prev_odom.inverse() * odom);
      const RegistrationResult r = reg.align(pts, guess);
      const PoseError e = poseError(r.transform, truth);
      const PoseError eg = poseError(poseToIsometry(guess), truth);
      es.push_back(e.es_m);
      ea.push_back(e.ea_deg);
      ok += e.success();
      const int j_truth = reg.score(pts, isometryToPose(truth));
      std::printf("%5d %8zu %10.3f %10.3f %10.3f %10.4f %8.2f %8d %8d\n", k, pts.size(), eg.es_m,
                  e.es_m, e.ea_deg, r.time_s, r.overlap(), r.J, j_truth);
      reg.setReference(pts);
      prev_sensor = sensor;
      prev_odom = odom;
    }
    auto med = [](std::vector<double> v) {
      std::sort(v.begin(), v.end());
      return v[v.size() / 2];
    };
    std::printf("summary: median Es %.3f m (max %.3f), median Ea %.3f deg (max %.3f), "
                "success (Es < 0.10 m, Ea < 1 deg) %d/%zu\n",
                med(es), *std::max_element(es.begin(), es.end()), med(ea),
                *std::max_element(ea.begin(), ea.end()), ok, es.size());
  } catch (const std::exception& e) {
    std::cerr << "simulate_and_register: " << e.what() << "\n";
    return 1;
  }
  return 0;
}
