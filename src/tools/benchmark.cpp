// benchmark DATASET_DIR [options]
// The paper's protocol (section 3.3) on a folder of real pairs: for each pair and each of N
// seeded trials, the initial guess is the reference pose plus uniform errors within the chosen
// bounds; the cube method and the PCL peers run in this process on the same guesses.
#include <algorithm>
#include <cmath>
#include <chrono>
#include <cstdio>
#include <functional>
#include <memory>
#include <iostream>
#include <map>
#include <random>
#include <sstream>
#include <string>
#include <vector>

#include "cube_scan_matcher/core/filters.h"
#include "cube_scan_matcher/core/metrics.h"
#include "cube_scan_matcher/core/pose_covariance.h"
#include "cube_scan_matcher/core/registration.h"
#include "cube_scan_matcher/io/cloud_io.h"
#include "cube_scan_matcher/io/dataset.h"
#include "open3d_peers.h"
#include "peer_methods.h"
#include "arg_reader.h"
#include "csv_writer.h"
#include "settings_cli.h"

using namespace cube_scan_matcher;
using namespace cube_scan_matcher::io;
using namespace cube_scan_matcher::tools;

namespace {

const std::vector<std::string> kAllMethods = {"cubes",   "cubes-paper", "icp-raw",   "icp-voxel",
                                              "ndt-raw", "ndt-voxel",   "gicp-voxel"};
/// Named explicitly only: the defaults without the polish (its effect, in the same run).
const std::vector<std::string> kExtraMethods = {"cubes-nopolish"};
/// Open3D peers: named explicitly (not in 'all', whose figures BENCHMARK.md keeps comparable).
const std::vector<std::string> kOpen3dMethods = {"o3d-p2pl-voxel", "o3d-gicp-voxel"};

void usage(std::ostream& os) {
  os << "usage: benchmark DATASET_DIR [options]\n"
        "Runs the paper's protocol on DATASET_DIR/pairs.txt (format: shared/data/README.md).\n\n"
        "  --trials N            seeded trials per pair and bounds (default 25)\n"
        "  --initial-errors B    big (+-1 m, +-8 deg), small (+-0.25 m, +-2 deg) or both\n"
        "                        (default big)\n"
        "  --methods LIST        comma list of: cubes (package defaults), cubes-paper (the\n"
        "                        paper's fixed mode), icp-raw, icp-voxel, ndt-raw, ndt-voxel,\n"
        "                        gicp-voxel; or 'all' (default all); also o3d-p2pl-voxel,\n"
        "                        o3d-gicp-voxel (Open3D point-to-plane ICP and GICP, when\n"
        "                        built with libopen3d-dev); cubes-nopolish (the defaults before\n"
        "                        the point-to-plane polish: no polish, 5 refine levels,\n"
        "                        whatever the cube options given)\n"
        "  --edges LIST          cube edges E [m] for the cube methods (default 0.5)\n"
        "  --voxel L             voxel leaf of the *-voxel peer copies [m] (default 0.2)\n"
        "  --trial-seed N        seed of the initial-guess errors (default 1)\n"
        "  --csv FILE            per-trial rows with the estimate at full precision\n"
        "                        (default benchmark.csv)\n"
        "  --check-repeatability M D  exit 3 unless every cube method's repeatability (the\n"
        "                        median distance of the trials' estimates to their median\n"
        "                        pose) is <= M [m] and D [deg] on every pair (default off)\n"
        "  --require-success K   exit 3 unless every cube method succeeds (Es < 0.10 m and\n"
        "                        Ea < 1 deg) in at least K trials of every pair (default off)\n"
        "Options of the 'cubes' method (cubes-paper ignores all but --edges/--seed/--max-cubes):\n"
     << algorithmOptionsHelp() << "  -h, --help            this text\n";
}

double median(std::vector<double> v) {
  if (v.empty()) return 0.0;
  std::sort(v.begin(), v.end());
  const std::size_t m = v.size() / 2;
  return v.size() % 2 ? v[m] : 0.5 * (v[m - 1] + v[m]);
}

struct Row {
  std::string pair, bounds, method;
  int trial;
  double es, ea, time;
  long evaluations;
  long j, j_ref;
  double time_coarse = 0.0, time_refine = 0.0, time_polish = 0.0;  // cube methods: stage times [s]
  int polish_iterations = 0;   // cube methods: the polish's Gauss-Newton steps,
  double weak_ratio = 0.0;     // its weakest direction's relative information,
  double sigma_m = 0.0;        // and the largest translation sd of its covariance [m]
  Eigen::Isometry3d estimate = Eigen::Isometry3d::Identity();  // the method's T_target_source
};

/// The cells tx,ty,tz,qx,qy,qz,qw with every digit: results compare bit for bit.
void writePose(CsvWriter& csv, const Eigen::Isometry3d& T) {
  const Eigen::Quaterniond q(T.linear());
  csv << Exact{T.translation().x()} << Exact{T.translation().y()} << Exact{T.translation().z()}
      << Exact{q.x()} << Exact{q.y()} << Exact{q.z()} << Exact{q.w()};
}

struct Bounds {
  std::string name;
  double t_m, a_deg;
};

}  // namespace

int main(int argc, char** argv) {
  RegistrationSettings cube_settings = RegistrationSettings{};
  RangeFilterSettings filter;
  std::string dir, csv_path = "benchmark.csv";
  int trials = 25, require = -1;
  double check_rep_m = -1, check_rep_deg = -1;  // --check-repeatability (-1: off)
  unsigned trial_seed = 1;
  double voxel = 0.2;
  std::vector<std::string> methods = kAllMethods;
  std::vector<double> edges;
  std::vector<Bounds> bounds = {{"big", 1.0, 8.0}};
  try {
    auto bounds_of = [&](const std::string& b) {
      if (b == "big") bounds = {{"big", 1.0, 8.0}};
      else if (b == "small") bounds = {{"small", 0.25, 2.0}};
      else if (b == "both") bounds = {{"big", 1.0, 8.0}, {"small", 0.25, 2.0}};
      else throw std::invalid_argument("--initial-errors: expected big, small or both");
    };
    auto methods_of = [&](const std::string& m) {
      methods = m == "all" ? kAllMethods : splitList(m);
      for (const auto& name : methods) {
        const bool o3d =
            std::find(kOpen3dMethods.begin(), kOpen3dMethods.end(), name) != kOpen3dMethods.end();
        if (o3d && !open3dAvailable())
          throw std::invalid_argument("--methods " + name + ": this build has no Open3D");
        const bool extra =
            std::find(kExtraMethods.begin(), kExtraMethods.end(), name) != kExtraMethods.end();
        if (!o3d && !extra &&
            std::find(kAllMethods.begin(), kAllMethods.end(), name) == kAllMethods.end())
          throw std::invalid_argument("--methods: unknown method '" + name + "'");
      }
    };
    auto edges_of = [&](const std::string& list) {
      edges.clear();
      for (const auto& e : splitList(list)) edges.push_back(parseNumber("--edges", e));
    };
    for (ArgReader r(argc, argv); r.more();) {
      if (r.help()) {
        usage(std::cout);
        return 0;
      }
      if (r.algorithm(cube_settings, filter) || r.option("--trials", trials) ||
          r.optionWith("--initial-errors", bounds_of) || r.optionWith("--methods", methods_of) ||
          r.optionWith("--edges", edges_of) || r.option("--voxel", voxel) ||
          r.option("--trial-seed", trial_seed) || r.option("--csv", csv_path) ||
          r.option("--require-success", require) ||
          r.optionWith("--check-repeatability", 2, [&](const std::vector<std::string>& v) {
            check_rep_m = parseNumber("--check-repeatability", v[0]);
            check_rep_deg = parseNumber("--check-repeatability", v[1]);
          }))
        continue;
      if (!dir.empty()) throw std::invalid_argument("more than one DATASET_DIR given");
      dir = r.positional();
    }
    if (dir.empty()) {
      usage(std::cerr);
      return 2;
    }
    if (trials < 1) throw std::invalid_argument("--trials must be >= 1");
    if (!(voxel > 0.0)) throw std::invalid_argument("--voxel must be > 0");
    if (edges.empty()) edges.push_back(cube_settings.grid.cube_edge);
    validate(filter);

    // The method table: name -> runner(pair data, guess) filling a Row.
    struct Data {
      Cloud::Ptr src, tgt, src_vox, tgt_vox;
      PointArray src_pts, tgt_pts;
      Eigen::Isometry3d ref;
    };
    using Runner = std::function<void(const Data&, const Eigen::Isometry3d&, Row&,
                                      Eigen::Isometry3d&)>;
    std::vector<std::pair<std::string, Runner>> table;
    auto addCube = [&](const std::string& label, RegistrationSettings s) {
      validate(s);
      // One matcher per method for the whole run, as the nodelet keeps one: its per-thread
      // working memory is reused, while the grids are rebuilt (and timed) at every trial.
      auto reg = std::make_shared<CubeRegistration>(s);
      table.emplace_back(label, [reg](const Data& d, const Eigen::Isometry3d& guess, Row& row,
                                      Eigen::Isometry3d& est) {
        const auto t0 = std::chrono::steady_clock::now();
        reg->setReference(d.tgt_pts);  // timed: the grid is part of the method's cost
        const RegistrationResult r = reg->align(d.src_pts, isometryToPose(guess));
        row.time = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
        est = r.transform;
        row.evaluations = r.evaluations;
        row.time_coarse = r.time_coarse_s;
        row.time_refine = r.time_refine_s;
        row.time_polish = r.time_polish_s;
        row.polish_iterations = r.polish_iterations;
        row.weak_ratio = r.weak_ratio;
        row.sigma_m = largestTranslationSigma(r.covariance);
        row.j = r.J;
        row.j_ref = reg->score(d.src_pts, isometryToPose(d.ref));  // untimed, for comparison
      });
    };
    for (const auto& m : methods) {
      for (double e : edges) {
        std::ostringstream label;
        label << m << "(E=" << e << ")";
        if (m == "cubes") {
          RegistrationSettings s = cube_settings;
          s.grid.cube_edge = e;
          addCube(label.str(), s);
        } else if (m == "cubes-nopolish") {
          RegistrationSettings s;  // the defaults before the polish, not the command line's cube options
          s.refine.compass.levels = 5;
          s.grid.cube_edge = e;
          s.polish.enabled = false;
          addCube(label.str(), s);
        } else if (m == "cubes-paper") {
          RegistrationSettings s = RegistrationSettings::paper(e);
          s.gnmm.seed = cube_settings.gnmm.seed;
          s.grid.max_cubes = cube_settings.grid.max_cubes;
          addCube(label.str(), s);
        }
      }
      auto peer = [&](const std::string& name,
                      PeerResult (*fn)(const Cloud::ConstPtr&, const Cloud::ConstPtr&,
                                       const Eigen::Isometry3d&),
                      bool vox) {
        table.emplace_back(name, [fn, vox](const Data& d, const Eigen::Isometry3d& guess,
                                           Row& row, Eigen::Isometry3d& est) {
          const PeerResult r = vox ? fn(d.src_vox, d.tgt_vox, guess) : fn(d.src, d.tgt, guess);
          est = r.estimate;
          row.time = r.time_s;
          row.evaluations = r.iterations;
        });
      };
      if (m == "icp-raw") peer(m, runIcp, false);
      if (m == "icp-voxel") peer(m, runIcp, true);
      if (m == "ndt-raw") peer(m, runNdt, false);
      if (m == "ndt-voxel") peer(m, runNdt, true);
      if (m == "gicp-voxel") peer(m, runGicp, true);
      if (m == "o3d-p2pl-voxel") peer(m, runOpen3dPointToPlane, true);
      if (m == "o3d-gicp-voxel") peer(m, runOpen3dGicp, true);
    }

    const std::vector<PairEntry> pairs = readPairs(dir);
    CsvWriter csv(csv_path,
                  "pair,bounds,method,trial,Es_m,Ea_deg,time_s,evaluations,J,J_ref,time_coarse_s,"
                  "time_refine_s,time_polish_s,polish_iterations,weak_ratio,sigma_m,tx,ty,tz,qx,"
                  "qy,qz,qw");
    std::vector<Row> rows;
    const std::size_t total = pairs.size() * bounds.size() * std::size_t(trials) * table.size();
    std::size_t done = 0;
    const auto bench_start = std::chrono::steady_clock::now();
    for (std::size_t p = 0; p < pairs.size(); ++p) {
      Data d;
      const PointArray src_all = readCloudFile(pairs[p].source);
      const PointArray tgt_all = readCloudFile(pairs[p].target);
      d.src = toPcl(src_all);
      d.tgt = toPcl(tgt_all);
      d.src_vox = voxelCopy(d.src, float(voxel));
      d.tgt_vox = voxelCopy(d.tgt, float(voxel));
      d.src_pts = filterPoints(src_all, filter);
      d.tgt_pts = filterPoints(tgt_all, filter);
      d.ref = pairs[p].T_target_source;
      std::fprintf(stderr, "pair %s: %zu -> %zu points (voxel copies %zu, %zu)\n",
                   pairs[p].name.c_str(), d.src->size(), d.tgt->size(), d.src_vox->size(),
                   d.tgt_vox->size());
      const Pose6 ref_pose = isometryToPose(d.ref);
      for (const Bounds& b : bounds) {
        std::mt19937_64 rng(trial_seed * 1000003ULL + p * 7919ULL + (b.name == "big" ? 0 : 1));
        std::uniform_real_distribution<double> u(-1.0, 1.0);
        for (int t = 0; t < trials; ++t) {
          Pose6 g = ref_pose;
          for (int k = 0; k < 3; ++k) g[k] += b.t_m * u(rng);
          for (int k = 3; k < 6; ++k) g[k] += deg2rad(b.a_deg) * u(rng);
          const Eigen::Isometry3d guess = poseToIsometry(g);
          for (const auto& [name, run] : table) {
            Row row{pairs[p].name, b.name, name, t, 0, 0, 0, 0, -1, -1};
            Eigen::Isometry3d est;
            run(d, guess, row, est);
            row.estimate = est;
            const PoseError err = poseError(est, d.ref);
            row.es = err.es_m;
            row.ea = err.ea_deg;
            rows.push_back(row);
            csv << row.pair << row.bounds << row.method << row.trial << row.es << row.ea
                << row.time << row.evaluations << row.j << row.j_ref << row.time_coarse
                << row.time_refine << row.time_polish << row.polish_iterations << row.weak_ratio
                << row.sigma_m;
            writePose(csv, row.estimate);
            csv.endRow();
            ++done;
            const double el = std::chrono::duration<double>(std::chrono::steady_clock::now() -
                                                            bench_start).count();
            std::fprintf(stderr, "\r[%zu/%zu] %.0f s elapsed, ~%.0f s left   ", done, total, el,
                         el / double(done) * double(total - done));
          }
        }
      }
      std::fprintf(stderr, "\n");
    }

    // Summary: median Es, Ea, time, successes; time ratio to the first cube method.
    std::printf("%s\n", machineReport().c_str());
    std::printf("\n%-44s %-6s %-22s %9s %9s %10s %8s %10s %16s\n", "pair", "bounds", "method",
                "med Es[m]", "med Ea[°]", "med t[s]", "success", "t/t_cube", "rep [m]|[°]");
    bool checks_ok = true;
    for (const auto& pair : pairs) {
      for (const Bounds& b : bounds) {
        double cube_time = 0.0;
        for (const auto& [name, run] : table) {
          std::vector<double> es, ea, tm;
          std::vector<Eigen::Isometry3d> estimates;
          int ok = 0;
          for (const Row& r : rows) {
            if (r.pair != pair.name || r.bounds != b.name || r.method != name) continue;
            es.push_back(r.es);
            ea.push_back(r.ea);
            tm.push_back(r.time);
            estimates.push_back(r.estimate);
            ok += PoseError{r.es, r.ea}.success();
          }
          const double mt = median(tm);
          const bool is_cube = name.rfind("cubes", 0) == 0;
          if (is_cube && cube_time == 0.0) cube_time = mt;
          if (is_cube && require >= 0 && ok < require) checks_ok = false;
          const Repeatability rep = repeatability(estimates);
          if (is_cube && check_rep_m >= 0 &&
              (rep.median_m > check_rep_m || rep.median_deg > check_rep_deg)) {
            std::fprintf(stderr, "benchmark: %s %s: repeatability %.5f m / %.5f deg > %g m / %g "
                         "deg\n", pair.name.c_str(), name.c_str(), rep.median_m, rep.median_deg,
                         check_rep_m, check_rep_deg);
            checks_ok = false;
          }
          std::printf("%-44s %-6s %-22s %9.4f %9.3f %10.4f %5d/%-2d %10.1f %7.4f|%7.4f\n",
                      pair.name.c_str(), b.name.c_str(), name.c_str(), median(es), median(ea), mt,
                      ok, int(es.size()), cube_time > 0 ? mt / cube_time : 0.0, rep.median_m,
                      rep.median_deg);
        }
      }
    }
    std::printf("success: Es < 0.10 m and Ea < 1 deg; t/t_cube: median time over the first cube "
                "method's; rep: median over trials of the distance to the method's median pose "
                "(repeatability); CSV: %s\n", csv_path.c_str());
    if (!checks_ok) {
      std::fprintf(stderr, "benchmark: a cube method missed --require-success %d of %d trials "
                   "or --check-repeatability\n", require, trials);
      return 3;
    }
  } catch (const std::exception& e) {
    std::cerr << "benchmark: " << e.what() << "\n";
    return 1;
  }
  return 0;
}
