// register_clouds REFERENCE SCAN [--guess x y z roll pitch yaw] [options]
// Registers SCAN to REFERENCE with the cube method and prints the pose scan -> reference.
#include <cstdio>
#include <iostream>
#include <string>
#include <vector>

#include "cube_scan_matcher/core/filters.h"
#include "cube_scan_matcher/core/registration.h"
#include "cube_scan_matcher/io/cloud_io.h"
#include "arg_reader.h"
#include "settings_cli.h"

using namespace cube_scan_matcher;

namespace {
void usage(std::ostream& os) {
  os << "usage: register_clouds REFERENCE SCAN [--guess x y z roll pitch yaw] [options]\n"
        "Registers SCAN (newer, .pcd/.ply) to REFERENCE by coincidence of coarse binary cubes\n"
        "optimised with GNMM; prints the pose that maps SCAN points into REFERENCE's frame.\n\n"
        "  --guess x y z r p y   initial estimate: metres and degrees (roll, pitch, yaw as in\n"
        "                        paper eq. 2: R = Rz(yaw) Ry(pitch) Rx(roll); default 0)\n"
     << tools::algorithmOptionsHelp() << "  -h, --help            this text\n";
}
}  // namespace

int main(int argc, char** argv) {
  RegistrationSettings settings = RegistrationSettings{};
  RangeFilterSettings filter;
  Pose6 guess = Pose6::Zero();
  std::vector<std::string> files;
  try {
    for (tools::ArgReader r(argc, argv); r.more();) {
      if (r.help()) {
        usage(std::cout);
        return 0;
      }
      if (r.algorithm(settings, filter) ||
          r.optionWith("--guess", 6, [&](const std::vector<std::string>& v) {
            for (int k = 0; k < 6; ++k) {
              const double x = io::parseNumber("--guess", v[std::size_t(k)]);
              guess[k] = k < 3 ? x : deg2rad(x);
            }
          }))
        continue;
      files.push_back(r.positional());
    }
    if (files.size() != 2) {
      usage(std::cerr);
      std::cerr << "register_clouds: expected REFERENCE and SCAN, got " << files.size()
                << " file(s)\n";
      return 2;
    }
    validate(filter);
    CubeRegistration reg(settings);
    FilterStats ref_stats, scan_stats;
    const PointArray ref =
        filterPoints(io::readCloudFile(files[0]), filter, &ref_stats);
    const PointArray scan =
        filterPoints(io::readCloudFile(files[1]), filter, &scan_stats);
    if (ref.empty()) throw std::runtime_error(files[0] + ": no valid point after filtering");
    if (scan.empty()) throw std::runtime_error(files[1] + ": no valid point after filtering");
    reg.setReference(ref);
    const RegistrationResult r = reg.align(scan, guess);
    if (!r.ok()) throw std::runtime_error("registration failed: " + r.message);
    const Pose6& p = r.pose;
    std::printf("pose x y z [m] roll pitch yaw [deg]: %.4f %.4f %.4f %.4f %.4f %.4f\n", p[0], p[1],
                p[2], rad2deg(p[3]), rad2deg(p[4]), rad2deg(p[5]));
    std::printf("matrix (scan -> reference):\n");
    const Eigen::Matrix4d m = r.transform.matrix();
    for (int row = 0; row < 4; ++row) {
      std::printf("  %10.6f %10.6f %10.6f %10.6f\n", m(row, 0), m(row, 1), m(row, 2), m(row, 3));
    }
    std::printf("J %d (at guess %d) of l %zu, overlap %.3f\n", r.J, r.J_guess, r.reference_cubes,
                r.overlap());
    std::printf("points: reference %zu of %zu, scan %zu of %zu, evaluated %zu\n", ref.size(),
                ref_stats.input, scan.size(), scan_stats.input, r.points_used);
    std::printf("evaluations %d, iterations %d, restarts %d, time %.4f s\n", r.evaluations,
                r.iterations, r.restarts, r.time_s);
  } catch (const std::exception& e) {
    std::cerr << "register_clouds: " << e.what() << "\n";
    return 1;
  }
  return 0;
}
