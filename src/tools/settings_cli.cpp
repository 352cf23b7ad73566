#include "settings_cli.h"

#include <cstdlib>
#include <fstream>
#include <sstream>
#include <stdexcept>

#include "cube_scan_matcher/core/simd_path.h"


namespace cube_scan_matcher::tools {

std::string algorithmOptionsHelp() {
  const RegistrationSettings d = RegistrationSettings{};
  const RangeFilterSettings f;
  auto num = [](double v) {
    std::string s = std::to_string(v);
    s.erase(s.find_last_not_of('0') + 1);
    if (s.back() == '.') s.pop_back();
    return s;
  };
  return std::string() +
         "  --edge E              cube edge E [m] (default " + num(d.grid.cube_edge) + "; paper 0.3-0.5)\n"
         "  --vertices N          GNMM population size (default " + std::to_string(d.gnmm.vertices) + ", >= 7)\n"
         "  --iterations N        GNMM iterations (default " + std::to_string(d.gnmm.max_iterations) + ")\n"
         "  --bounds T A          restart half-widths: T [m] for x,y,z and A [deg] for roll,pitch,yaw\n"
         "                        (default " + num(d.gnmm.bounds[0]) + " m, " + num(rad2deg(d.gnmm.bounds[3])) + " deg)\n"
         "  --starts K            independent GNMM searches from the guess, best J wins\n"
         "                        (default " + std::to_string(d.search.starts) + "; paper 1)\n"
         "  --retries N           search again from new seeds while the polished result is\n"
         "                        degenerate or unconfirmed, up to N times (default " + std::to_string(d.search.retries) + ")\n"
         "  --ambiguous R K       a result with a translation weak ratio below R that at most K\n"
         "                        starts agree with counts only when a retry lands on it again\n"
         "                        (default " + num(d.search.ambiguous_weak_ratio) + " " + std::to_string(d.search.ambiguous_max_agreeing) + "; 0 = off)\n"
         "  --axis-probe M G      probe J along the weakest translation axis up to +-M [m] after\n"
         "                        the polish; a J gain above G (fraction) moves the result there\n"
         "                        (default " + num(d.search.axis_probe_m) + " m, " + num(d.search.axis_probe_gain) + "; 0 m = off)\n"
         "  --threads T           threads for the starts, the refine candidates, the polish's\n"
         "                        plane lookups and the grid builds (default " + std::to_string(d.search.threads) + ")\n"
         "  --simd P              vector path of the per-point loop: auto, avx512, avx2 or\n"
         "                        portable (default auto = the fastest this CPU runs, or the\n"
         "                        CSM_SIMD environment variable); results are the same on all\n"
         "                        paths\n"
         "  --collapse F          keep one scan point per voxel of F*E before the search,\n"
         "                        0 = all points as in the paper (default " + num(d.collapse_fraction) + ")\n"
         "  --refine F            compass-search stage on cubes of F*E from the coarse result,\n"
         "                        0 = off as in the paper (default " + num(d.refine.enabled ? d.refine.edge_fraction : 0.0) + ")\n"
         "  --refine-coarse-weight W  the refine objective adds W x J on the E grid\n"
         "                        (default " + num(d.refine.coarse_weight) + "; 0 = fine grids only)\n"
         "  --refine-candidates K refine the K best distinct coarse results, keep the best\n"
         "                        (default " + std::to_string(d.refine.candidates) + ")\n"
         "  --dense-points N      the coarse search uses only scan points whose E-cube holds\n"
         "                        >= N scan points; 0 = all (default " + num(d.dense_points) + ")\n"
         "  --polish V            point-to-plane polish on planes fitted in voxels of V*E (3x3x3\n"
         "                        blocks), 0 = off (default " + num(d.polish.enabled ? d.polish.voxel_fraction : 0.0) + ")\n"
         "  --polish-kernel K     Geman-McClure scale of the polish [m] (default " + num(d.polish.kernel) + ")\n"
         "  --polish-planarity P  a plane's smallest / middle eigenvalue at most P (default " + num(d.polish.max_planarity) + ")\n"
         "  --polish-min-points N reference points a plane needs (default " + std::to_string(d.polish.min_points) + ")\n"
         "  --polish-min-spread F a plane's points spread >= F voxels along their second axis\n"
         "                        (default " + num(d.polish.min_spread) + ")\n"
         "  --support-cosine C    a plane informs a translation axis when its normal's cosine\n"
         "                        to it is >= C (default " + num(d.polish.support_cosine) + ")\n"
         "  --translation-degenerate R  degenerate when the weakest translation's supported\n"
         "                        information is < R x the strongest's (default " + num(d.polish.translation_degenerate_ratio) + ")\n"
         "  --polish-collapse F   the polish evaluates one scan point per voxel of F*E, 0 = all\n"
         "                        (default " + num(d.polish.collapse_fraction) + ")\n"
         "  --polish-weak R       the polish does not move along directions with less than R x\n"
         "                        the strongest information (default " + num(d.polish.weak_ratio) + ")\n"
         "  --polish-iterations N Gauss-Newton steps of the polish (default " + std::to_string(d.polish.max_iterations) + ")\n"
         "  --polish-overrelax F  a polish step along the last one's direction is stretched\n"
         "                        up to F times, 1 = plain Gauss-Newton (default " + num(d.polish.max_overrelaxation) + ")\n"
         "  --polish-round-steps N  steps per round of the polish before its points are\n"
         "                        collected again; 0 = only when a round converges (default " + std::to_string(d.polish.round_steps) + ")\n"
         "  --polish-max-shift M D  the polish is not applied when it moves the pose more than\n"
         "                        M m or D deg (default " + num(d.polish.max_shift_m) + " " + num(rad2deg(d.polish.max_shift_rad)) + ")\n"
         "  --covariance-scale C  the polish's covariance is C x sigma^2 H^-1 (default " + num(d.polish.covariance_scale) + ")\n"
         "  --covariance-cell M   plus the clustered covariance over cubes of M m, 0 = off\n"
         "                        (default " + num(d.polish.covariance_cell_m) + ")\n"
         "  --covariance-cell-scale K  times K (default " + num(d.polish.covariance_cell_scale) + ")\n"
         "  --covariance-jackknife C  each cube's clustered term left out (jackknife), widened\n"
         "                        at most C times in sd; <= 1 = off (default " + num(d.polish.covariance_jackknife_cap) + ")\n"
         "  --coarse-max-points N the coarse search evaluates at most N collapsed points, 0 = all\n"
         "                        (default " + num(d.coarse_max_points) + ")\n"
         "  --screen S F          the coarse search's GNMM iterations but the last F evaluate\n"
         "                        every S-th coarse point, the last F all; S = 1 = off\n"
         "                        (default " + std::to_string(d.screen_stride) + " " +
         std::to_string(d.screen_final_iterations) + ")\n"
         "  --refine-collapse F   the refine stage evaluates one point per voxel of F*E\n"
         "                        (default " + num(d.refine.collapse_fraction) + ")\n"
         "  --refine-grids K      refine on the sum of J over K fine grids shifted by 1/K cube\n"
         "                        (anti-aliasing; default " + std::to_string(d.refine.grids) + ")\n"
         "  --refine-levels N     compass-search step sizes in the refine stage, each half the one\n"
         "                        before (default " + std::to_string(d.refine.compass.levels) + ")\n"
         "  --refine-step T A     first compass steps T [m], A [deg] (default " + num(d.refine.compass.initial_step[0]) + " m, " + num(rad2deg(d.refine.compass.initial_step[3])) + " deg)\n"
         "  --seed N              RNG seed (default " + std::to_string(d.gnmm.seed) + ")\n"
         "  --max-cubes N         memory cap on the grid [cubes = bits] (default 2^31)\n"
         "  --max-byte-cubes N    grids of up to N cubes are evaluated on byte-per-cube working\n"
         "                        copies (faster), larger ones on bit copies; 0 = bits (default\n"
         "                        " + std::to_string(d.grid.max_byte_cubes) + ")\n"
         "  --min-range R         drop points closer than R [m] to the origin (default " + num(f.min_range) + ")\n"
         "  --max-range R         drop points farther than R [m] (default none)\n"
         "  --paper               the paper's fixed mode: 15 vertices, 500 iterations, all points,\n"
         "                        restarts around the initial estimate (resets the options before it)\n";
}

std::string machineReport() {
  std::string model = "unknown";
  std::ifstream in("/proc/cpuinfo");
  for (std::string line; std::getline(in, line);) {
    // x86: "model name : ..."; aarch64 kernels print no model name, only "CPU part".
    if (line.rfind("model name", 0) == 0 && line.find(':') != std::string::npos) {
      model = line.substr(line.find(':') + 2);
      break;
    }
  }
  return "CPU: " + model + "; SIMD path: " + simdReport();
}

bool parseAlgorithmOption(const std::vector<std::string>& args, std::size_t& i,
                          RegistrationSettings& s, RangeFilterSettings& f) {
  const std::string& a = args[i];
  auto word = [&](int k) -> const std::string& {
    if (i + k >= args.size()) throw std::invalid_argument(a + ": missing value");
    return args[i + k];
  };
  auto value = [&](int k) { return io::parseNumber(a, word(k)); };
  std::size_t used = 1;
  if (a == "--edge") {
    s.grid.cube_edge = value(1), used = 2;
  } else if (a == "--vertices") {
    s.gnmm.vertices = int(value(1)), used = 2;
  } else if (a == "--iterations") {
    s.gnmm.max_iterations = int(value(1)), used = 2;
  } else if (a == "--bounds") {
    const double t = value(1), ang = deg2rad(value(2));
    s.gnmm.bounds << t, t, t, ang, ang, ang;
    used = 3;
  } else if (a == "--refine") {
    s.refine.enabled = value(1) > 0.0;
    if (s.refine.enabled) s.refine.edge_fraction = value(1);
    used = 2;
  } else if (a == "--polish") {
    s.polish.enabled = value(1) > 0.0;
    if (s.polish.enabled) s.polish.voxel_fraction = value(1);
    used = 2;
  } else if (a == "--polish-kernel") {
    s.polish.kernel = value(1), used = 2;
  } else if (a == "--polish-planarity") {
    s.polish.max_planarity = value(1), used = 2;
  } else if (a == "--polish-min-points") {
    s.polish.min_points = int(value(1)), used = 2;
  } else if (a == "--polish-min-spread") {
    s.polish.min_spread = value(1), used = 2;
  } else if (a == "--support-cosine") {
    s.polish.support_cosine = value(1), used = 2;
  } else if (a == "--translation-degenerate") {
    s.polish.translation_degenerate_ratio = value(1), used = 2;
  } else if (a == "--polish-collapse") {
    s.polish.collapse_fraction = value(1), used = 2;
  } else if (a == "--polish-weak") {
    s.polish.weak_ratio = value(1), used = 2;
  } else if (a == "--polish-iterations") {
    s.polish.max_iterations = int(value(1)), used = 2;
  } else if (a == "--polish-overrelax") {
    s.polish.max_overrelaxation = value(1), used = 2;
  } else if (a == "--polish-max-shift") {
    s.polish.max_shift_m = value(1), s.polish.max_shift_rad = deg2rad(value(2)), used = 3;
  } else if (a == "--polish-round-steps") {
    s.polish.round_steps = int(value(1)), used = 2;
  } else if (a == "--covariance-scale") {
    s.polish.covariance_scale = value(1), used = 2;
  } else if (a == "--covariance-cell") {
    s.polish.covariance_cell_m = value(1), used = 2;
  } else if (a == "--covariance-cell-scale") {
    s.polish.covariance_cell_scale = value(1), used = 2;
  } else if (a == "--covariance-jackknife") {
    s.polish.covariance_jackknife_cap = value(1), used = 2;
  } else if (a == "--refine-coarse-weight") {
    s.refine.coarse_weight = value(1), used = 2;
  } else if (a == "--refine-candidates") {
    s.refine.candidates = int(value(1)), used = 2;
  } else if (a == "--coarse-max-points") {
    s.coarse_max_points = int(value(1)), used = 2;
  } else if (a == "--screen") {
    s.screen_stride = int(value(1)), s.screen_final_iterations = int(value(2)), used = 3;
  } else if (a == "--refine-collapse") {
    s.refine.collapse_fraction = value(1), used = 2;
  } else if (a == "--refine-grids") {
    s.refine.grids = int(value(1)), used = 2;
  } else if (a == "--refine-levels") {
    s.refine.compass.levels = int(value(1)), used = 2;
  } else if (a == "--refine-step") {
    const double t = value(1), ang = deg2rad(value(2));
    s.refine.compass.initial_step << t, t, t, ang, ang, ang;
    used = 3;
  } else if (a == "--starts") {
    s.search.starts = int(value(1)), used = 2;
  } else if (a == "--retries") {
    s.search.retries = int(value(1)), used = 2;
  } else if (a == "--ambiguous") {
    s.search.ambiguous_weak_ratio = value(1), s.search.ambiguous_max_agreeing = int(value(2)), used = 3;
  } else if (a == "--axis-probe") {
    s.search.axis_probe_m = value(1), s.search.axis_probe_gain = value(2), used = 3;
  } else if (a == "--simd") {
    setSimdPath(parseSimdPath(word(1)));
    used = 2;
  } else if (a == "--threads") {
    s.search.threads = int(value(1)), used = 2;
  } else if (a == "--dense-points") {
    s.dense_points = int(value(1)), used = 2;
  } else if (a == "--collapse") {
    s.collapse_fraction = value(1), used = 2;
  } else if (a == "--seed") {
    s.gnmm.seed = std::uint64_t(value(1)), used = 2;
  } else if (a == "--max-byte-cubes") {
    s.grid.max_byte_cubes = std::uint64_t(value(1)), used = 2;
  } else if (a == "--max-cubes") {
    s.grid.max_cubes = std::uint64_t(value(1)), used = 2;
  } else if (a == "--min-range") {
    f.min_range = value(1), used = 2;
  } else if (a == "--max-range") {
    f.max_range = value(1), used = 2;
  } else if (a == "--paper") {
    s = RegistrationSettings::paper(s.grid.cube_edge);
  } else {
    return false;
  }
  i += used;
  return true;
}

std::vector<std::string> splitList(const std::string& s) {
  std::vector<std::string> out;
  std::stringstream ss(s);
  for (std::string item; std::getline(ss, item, ',');) {
    if (!item.empty()) out.push_back(item);
  }
  return out;
}

std::pair<std::string, std::string> splitPair(const std::string& option, const std::string& value,
                                              const std::string& form) {
  const std::size_t colon = value.find(':');
  if (colon == std::string::npos) {
    throw std::invalid_argument(option + ": '" + value + "' is not " + form);
  }
  return {value.substr(0, colon), value.substr(colon + 1)};
}

}  // namespace cube_scan_matcher::tools
