// sweep_motion_benchmark: registration of sweeps taken while the robot drives.
// Per trial: a seeded world, a zigzag path at a given speed and yaw rate (sim::DrivenPath, the
// yaw rate flipping every sweep), and a run of sweeps taken back to back (each sweep lasts
// `duration` [s], so a sweep's interval is its duration; the tilt goes up, then down). Each
// line of a sweep is cast from the true pose at its own time; the matcher gets the sweep as an
// assembler and tf would give it: every point placed with the simulated odometry at its time
// (constant velocity between the odometry's poses at the sweeps' reference times, the last
// line's), in base_link at the sweep's reference time, with per-point times. Modes:
//   static  each sweep taken from one pose, its reference pose (stop and go: the baseline)
//   ideal   the moving sweep placed with the true motion (a perfect de-skew: the bound)
//   rigid   the moving sweep, registered as it comes (today's matcher)
//   deskew  ... re-placed with the registered motion and registered again (the matcher's
//           DeskewSettings defaults)
//   deskewN ... the same with N = 0..9 re-registrations (deskew0: re-placed only)
// The error of each registered increment (sweep k-1 -> k, truth = the poses at the reference
// times) is reported per speed, yaw rate, duration, odometry model and mode; the first
// increment of a run is reported apart. A run starts standing still (its first sweep taken from
// one pose, odometry exact while standing) unless --start moving: a first sweep taken while
// driving is bent by the odometry's error, no earlier scan can correct it, and de-skewing the
// later sweeps against it carries its bend on (measured: BENCHMARK.md, "Sweeps taken while
// driving").
//   sweep_motion_benchmark --worlds 3 --csv sweep_motion.csv
#include <algorithm>
#include <chrono>
#include <cstdio>
#include <iostream>
#include <map>
#include <optional>
#include <random>
#include <string>
#include <tuple>
#include <vector>

#include "cube_scan_matcher/core/metrics.h"
#include "cube_scan_matcher/core/online_matcher.h"
#include "cube_scan_matcher/sim/motion.h"
#include "cube_scan_matcher/sim/tilting_scanner.h"
#include "arg_reader.h"
#include "csv_writer.h"
#include "settings_cli.h"

using namespace cube_scan_matcher;
using namespace cube_scan_matcher::tools;

namespace {

void usage(std::ostream& os) {
  os << "usage: sweep_motion_benchmark [options]\n"
        "  --scenes LIST       scene types (default paper: hall,urban,park,natural; robot; all)\n"
        "  --worlds N          worlds per scene type (default 3)\n"
        "  --sweeps N          sweeps per run, >= 3 (default 5: 4 increments, the first apart)\n"
        "  --motions LIST      speed:yaw-rate pairs [m/s]:[deg/s] (default 0.5:10,1:20,2:30)\n"
        "  --durations LIST    sweep durations [s] (default 1,2,4)\n"
        "  --odometry LIST     odometry error models: none, small, big, drift (default big,drift)\n"
        "  --modes LIST        static, ideal, rigid, deskew, deskew0..deskew9 (default\n"
        "                      static,rigid,deskew0,deskew)\n"
        "  --start rest|moving  the first sweep taken standing still (default), or already\n"
        "                      driving (its sweep bent by the odometry's error, which no\n"
        "                      earlier scan can correct)\n"
        "  --trial-seed N      seed of start poses and noise (default 1)\n"
        "  --csv FILE          one row per registered increment (default sweep_motion.csv)\n"
        "  --check MODE:V:W:ES:EA  exit 2 unless MODE's median Es <= ES [m] and Ea <= EA [deg]\n"
        "                      over the steady increments of the runs at speed <= V [m/s] and\n"
        "                      yaw rate <= W [deg/s] (repeatable)\n"
        "  --max-accepted-wrong MODE:N  exit 2 when more than N of MODE's increments (the\n"
        "                      first ones included) whose registration is off by\n"
        "                      0.10 m or 1 deg were accepted\n"
        "  --min-success MODE:F  exit 2 when fewer than the fraction F of MODE's increments\n"
        "                      (the first ones included) succeeded\n"
        "  --bent-sweep R:F    reject a sweep after rejected scans whose plane RMS is above\n"
        "                      R x, or fraction of points on planes below F x, the recent\n"
        "                      accepted ones' (DeskewSettings max_rms_ratio and\n"
        "                      min_plane_fraction_ratio; default 1.6:0.9, 0 = off)\n"
     << algorithmOptionsHelp();
}

struct Motion {
  double speed, yaw_rate_deg;
};

struct Check {
  std::string mode;
  double speed, yaw_rate, es, ea;
};

/// One registered increment.
struct Row {
  std::string scene, odometry, mode;
  Motion motion;
  double duration;
  int world, trial, k;
  bool accepted;
  double es, ea, time;
  // The error of the registration itself: the pose relative to the last accepted scan's (or
  // the first scan's) against the truth of the same. It differs from es/ea after a rejection,
  // whose pose is the prediction.
  double es_reg, ea_reg;
  std::string reason;
  bool success() const { return es < 0.10 && ea < 1.0; }
  /// An accepted increment is wrong when its registration is: after a rejected sweep the
  /// increment also carries that sweep's pose (the prediction), which nobody accepted.
  bool acceptedWrong() const { return accepted && !(es_reg < 0.10 && ea_reg < 1.0); }
};

/// The sweeps of one run: moving (in base_link at the reference time, placed by odometry, with
/// times) and static, with the truth and odometry at each reference time.
struct Run {
  std::vector<PointArray> moving, ideal, still;
  std::vector<std::vector<float>> times;
  std::vector<Eigen::Isometry3d> truth, odom;
};

Run simulate(const sim::Scene& scene, const sim::ScannerModel& model, const sim::DrivenPath& path,
             sim::OdometryError odometry_error, int sweeps, double duration, bool from_rest,
             std::uint64_t seed, std::mt19937_64& rng) {
  Eigen::Isometry3d mount = Eigen::Isometry3d::Identity();
  mount.linear() = sim::sensorToBodyRotation();
  sim::OdometrySimulator odometry(odometry_error, seed);
  Run run;
  // Knot 0 (t = 0) starts the odometry at the truth; sweep k spans [(k-1) d, k d].
  std::vector<Eigen::Isometry3d> truth{path.at(0.0)}, odom{odometry.next(truth[0])};
  if (from_rest) {
    // The first sweep standing still at the start (odometry = truth there), then driving.
    run.moving.push_back(sim::scanInBody(scene, model, truth[0], rng));
    run.ideal.push_back(run.moving.back());
    run.times.push_back(std::vector<float>(run.moving.back().size(), 0.0f));
    run.still.push_back(run.moving.back());
    run.truth.push_back(truth[0]);
    run.odom.push_back(odom[0]);
  }
  for (int k = 1; int(run.moving.size()) < sweeps; ++k) {
    const double t_ref = k * duration;
    truth.push_back(path.at(t_ref));
    odom.push_back(odometry.next(truth.back()));
    const sim::TimedSweep sweep = sim::scanDuringMotion(
        scene, model, [&](double t) { return path.at(t) * mount; }, t_ref, duration, k % 2 == 1, rng);
    // Placed as tf would place it: T_odom_base(t) at constant velocity between the knots.
    // Ideal: placed with the true motion (what a perfect de-skew gives).
    run.moving.push_back(sim::placeSweep(sweep, mount, odom[k - 1].inverse() * odom[k], duration));
    run.ideal.push_back(sim::placeSweep(sweep, mount, truth[k - 1].inverse() * truth[k], duration));
    run.times.push_back(sweep.time);
    run.still.push_back(sim::scanInBody(scene, model, truth.back(), rng));
    run.truth.push_back(truth.back());
    run.odom.push_back(odom.back());
  }
  return run;
}

double median(const std::vector<double>& v) { return quantile(v, 0.5); }

}  // namespace

int main(int argc, char** argv) {
  std::vector<std::string> scenes = sim::expandSceneNames({"paper"});
  std::vector<Motion> motions = {{0.5, 10.0}, {1.0, 20.0}, {2.0, 30.0}};
  std::vector<double> durations = {1.0, 2.0, 4.0};
  std::vector<std::string> odometry_models = {"big", "drift"};
  std::vector<std::string> modes = {"static", "rigid", "deskew0", "deskew"};
  std::vector<Check> checks;
  std::string wrong_cap_mode;  // --max-accepted-wrong MODE:N (empty: no limit)
  int wrong_cap = 0;
  std::string success_floor_mode;  // --min-success MODE:F (empty: no floor)
  double success_floor = 0.0;
  int worlds = 3, sweeps = 5;
  bool from_rest = true;
  std::uint64_t seed = 1;
  std::string csv_path = "sweep_motion.csv";
  OnlineMatcherSettings settings;
  RangeFilterSettings filter;
  try {
    auto motions_of = [&](const std::string& v) {
      motions.clear();
      for (const std::string& m : splitList(v)) {
        const auto [speed, yaw_rate] = splitPair("--motions", m, "speed:yaw-rate");
        motions.push_back({io::parseNumber("--motions", speed), io::parseNumber("--motions", yaw_rate)});
      }
    };
    auto durations_of = [&](const std::string& v) {
      durations.clear();
      for (const std::string& d : splitList(v)) durations.push_back(io::parseNumber("--durations", d));
    };
    auto start_of = [&](const std::string& v) {
      if (v != "rest" && v != "moving") throw std::invalid_argument("--start: rest or moving");
      from_rest = v == "rest";
    };
    auto check_of = [&](const std::string& v) {
      std::vector<std::string> f;
      std::size_t from = 0, to;
      while ((to = v.find(':', from)) != std::string::npos) f.push_back(v.substr(from, to - from)), from = to + 1;
      f.push_back(v.substr(from));
      if (f.size() != 5) throw std::invalid_argument("--check: expected MODE:V:W:ES:EA, got " + v);
      checks.push_back({f[0], io::parseNumber("--check", f[1]), io::parseNumber("--check", f[2]),
                        io::parseNumber("--check", f[3]), io::parseNumber("--check", f[4])});
    };
    auto wrong_cap_of = [&](const std::string& v) {
      std::string n;
      std::tie(wrong_cap_mode, n) = splitPair("--max-accepted-wrong", v, "MODE:N");
      wrong_cap = ArgReader::convert<int>("--max-accepted-wrong", n);
      if (wrong_cap < 0) throw std::invalid_argument("--max-accepted-wrong: N must be >= 0");
    };
    auto success_floor_of = [&](const std::string& v) {
      std::string f;
      std::tie(success_floor_mode, f) = splitPair("--min-success", v, "MODE:F");
      success_floor = io::parseNumber("--min-success", f);
      if (!(success_floor >= 0.0 && success_floor <= 1.0))
        throw std::invalid_argument("--min-success: F must be in [0, 1]");
    };
    auto bent_of = [&](const std::string& v) {
      const auto [rms, fraction] = splitPair("--bent-sweep", v, "R:F");
      settings.deskew.max_rms_ratio = io::parseNumber("--bent-sweep", rms);
      settings.deskew.min_plane_fraction_ratio = io::parseNumber("--bent-sweep", fraction);
    };
    for (ArgReader r(argc, argv); r.more();) {
      if (r.help()) return usage(std::cout), 0;
      if (r.algorithm(settings.registration, filter) ||
          r.optionWith("--scenes",
                       [&](const std::string& v) { scenes = sim::expandSceneNames(splitList(v)); }) ||
          r.option("--worlds", worlds) || r.option("--sweeps", sweeps) ||
          r.optionWith("--motions", motions_of) || r.optionWith("--durations", durations_of) ||
          r.optionWith("--odometry", [&](const std::string& v) { odometry_models = splitList(v); }) ||
          r.optionWith("--modes", [&](const std::string& v) { modes = splitList(v); }) ||
          r.optionWith("--start", start_of) || r.option("--trial-seed", seed) ||
          r.option("--csv", csv_path) || r.optionWith("--check", check_of) ||
          r.optionWith("--max-accepted-wrong", wrong_cap_of) ||
          r.optionWith("--min-success", success_floor_of) ||
          r.optionWith("--bent-sweep", bent_of))
        continue;
      r.unknown();
    }
    if (worlds < 1) throw std::invalid_argument("--worlds must be >= 1");
    if (!wrong_cap_mode.empty() &&
        std::find(modes.begin(), modes.end(), wrong_cap_mode) == modes.end())
      throw std::invalid_argument("--max-accepted-wrong: mode " + wrong_cap_mode + " is not run");
    if (!success_floor_mode.empty() &&
        std::find(modes.begin(), modes.end(), success_floor_mode) == modes.end())
      throw std::invalid_argument("--min-success: mode " + success_floor_mode + " is not run");
    if (sweeps < 3) throw std::invalid_argument("--sweeps must be >= 3");
    for (const Motion& m : motions) {
      if (!(m.speed >= 0.0 && m.speed <= 5.0) || !(std::abs(m.yaw_rate_deg) <= 90.0))
        throw std::invalid_argument("--motions: speed in [0, 5] m/s and yaw rate within +-90 deg/s");
    }
    for (double d : durations) {
      if (!(d > 0.0 && d <= 10.0)) throw std::invalid_argument("--durations: each in (0, 10] s");
    }
    for (const std::string& m : modes) {
      const bool deskew_n = m.size() == 7 && m.rfind("deskew", 0) == 0 && m[6] >= '0' && m[6] <= '9';
      if (m != "static" && m != "ideal" && m != "rigid" && m != "deskew" && !deskew_n)
        throw std::invalid_argument("unknown mode: " + m + " (static, rigid, deskew, deskew0..deskew9)");
    }
    for (const Check& c : checks) {
      if (std::find(modes.begin(), modes.end(), c.mode) == modes.end())
        throw std::invalid_argument("--check: mode " + c.mode + " is not run (--modes)");
    }
    std::vector<sim::OdometryError> odometry_errors;
    for (const std::string& o : odometry_models) odometry_errors.push_back(sim::odometryErrorFromString(o));
    validate(settings);
    validate(filter);

    CsvWriter csv(csv_path,
                  "scene,world,trial,speed_mps,yaw_rate_dps,duration_s,odometry,mode,k,accepted,"
                  "success,Es_m,Ea_deg,time_s,Es_reg_m,Ea_reg_deg,reason,after_rejection,J,l,"
                  "points_used,plane_rms_m,plane_correspondences,translation_weak_ratio,"
                  "starts_agreeing,correction_m,correction_deg,aligns,searches,deskew_rounds,"
                  "register_s,deskew_s,reference_s,coarse_s,refine_s,polish_s");
    const sim::ScannerModel model;
    std::vector<Row> rows;
    int trial = 0;
    for (const std::string& scene_name : scenes) {
      const sim::SceneType type = sim::sceneTypeFromString(scene_name);
      for (int w = 1; w <= worlds; ++w) {
        const sim::Scene scene = sim::Scene::generate(type, std::uint64_t(w)).at(0.0);
        for (const Motion& motion : motions) {
          for (double duration : durations) {
            for (std::size_t o = 0; o < odometry_errors.size(); ++o, ++trial) {
              std::mt19937_64 rng(seed * 1000003ULL + std::uint64_t(trial) * 7919ULL);
              // A start whose whole path stays in free space.
              const sim::DrivenPathSettings ps{motion.speed, motion.yaw_rate_deg, duration, 1.0};
              std::uniform_real_distribution<double> ux(0.0, 110.0 - motion.speed * duration * sweeps),
                  uy(-1.0, 1.0);
              std::optional<sim::DrivenPath> path;
              for (int attempt = 0; attempt < 200 && !path; ++attempt) {
                sim::DrivenPath p(scene, ps, ux(rng), uy(rng), 0.0);
                bool free = true;
                for (double t = 0.0; t <= duration * sweeps && free; t += 0.25) {
                  free = !scene.insideSolid(p.at(t).translation(), 0.3);
                }
                if (free) path.emplace(p);
              }
              if (!path) throw std::runtime_error(scene_name + " world " + std::to_string(w) + ": no free path");
              const Run run = simulate(scene, model, *path, odometry_errors[o], sweeps, duration,
                                       from_rest, seed + std::uint64_t(trial), rng);
              for (const std::string& mode : modes) {
                OnlineMatcherSettings s = settings;
                s.deskew.enabled = mode.rfind("deskew", 0) == 0;
                if (mode.size() > 6) s.deskew.iterations = mode[6] - '0';
                OnlineMatcher matcher(s);
                std::vector<Eigen::Isometry3d> poses;
                int last_accepted = 0;  // the first scan's pose is the chain's origin
                for (int k = 0; k < sweeps; ++k) {
                  const bool rigid_input = mode == "static" || mode == "ideal" || (from_rest && k == 0);
                  PointTimes times;  // placed by the odometry, as an assembler in odom gives it
                  const PointArray pts =
                      mode == "static"  ? filterPoints(run.still[k], filter)
                      : mode == "ideal" ? filterPoints(run.ideal[k], filter)
                                        : filterPoints(run.moving[k], run.times[k], filter, times.tau);
                  const auto start = std::chrono::steady_clock::now();
                  const OnlineStep step =
                      matcher.process(pts, k * duration, run.odom[k], rigid_input ? nullptr : &times);
                  const double seconds =
                      std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
                  poses.push_back(step.pose);
                  if (k == 0) continue;
                  const PoseError e = poseError(poses[k - 1].inverse() * poses[k],
                                                run.truth[k - 1].inverse() * run.truth[k]);
                  const int j = last_accepted;
                  const PoseError r = poseError(poses[j].inverse() * poses[k],
                                                run.truth[j].inverse() * run.truth[k]);
                  if (step.accepted) last_accepted = k;
                  Row row{scene_name, odometry_models[o], mode, motion, duration, w, trial, k,
                          step.accepted, e.es_m, e.ea_deg, seconds, r.es_m, r.ea_deg,
                          toString(step.reason)};
                  csv << row.scene << w << trial << motion.speed << motion.yaw_rate_deg
                      << duration << row.odometry << mode << k << int(row.accepted)
                      << int(row.success()) << row.es << row.ea << row.time << row.es_reg
                      << row.ea_reg << row.reason;
                  // The registration's own figures: what a gate could see.
                  const RegistrationResult& res = step.result;
                  csv << int(j != k - 1) << res.J << res.reference_cubes << res.points_used
                      << res.plane_rms << res.plane_correspondences << res.translation_weak_ratio
                      << res.starts_agreeing << step.correction.head<3>().norm()
                      << rad2deg(Eigen::AngleAxisd(poseToIsometry(step.correction).linear()).angle());
                  // Where the step's time went (OnlineWork): the rigid registration, the de-skew
                  // rounds (sweep polish and registrations), the keyframe's grids; and inside
                  // every align() call, its stages.
                  const OnlineWork& w = step.work;
                  csv << w.aligns << w.searches << w.deskew_rounds << w.register_s << w.deskew_s
                      << w.reference_s << w.coarse_s << w.refine_s << w.polish_s;
                  csv.endRow();
                  rows.push_back(row);
                }
              }
            }
          }
        }
        std::fprintf(stderr, "%s: world %d of %d\n", scene_name.c_str(), w, worlds);
      }
    }

    std::printf("%s\n", machineReport().c_str());
    std::printf("%-5s %-4s %-4s %-6s %-8s %9s %9s %20s %20s %8s %9s\n", "v", "w", "T", "odom",
                "mode", "success", "accepted", "Es med|p95 [m]", "Ea med|p95 [deg]", "med s",
                "first ok");
    // Per (speed, yaw rate, duration, odometry, mode): the steady increments (k >= 2), and the
    // first increments' successes apart.
    using Key = std::tuple<double, double, double, std::string, std::string>;
    std::map<Key, std::vector<const Row*>> steady, first;
    for (const Row& r : rows) {
      (r.k == 1 ? first : steady)[{r.motion.speed, r.motion.yaw_rate_deg, r.duration, r.odometry, r.mode}].push_back(&r);
    }
    std::vector<std::string> failures;
    std::map<std::string, std::vector<double>> check_es, check_ea;
    for (const auto& [key, group] : steady) {
      std::vector<double> es, ea, time;
      int ok = 0, acc = 0;
      for (const Row* r : group) {
        es.push_back(r->es), ea.push_back(r->ea), time.push_back(r->time);
        ok += r->success(), acc += r->accepted;
      }
      int first_ok = 0;
      for (const Row* r : first[key]) first_ok += r->success();
      std::printf("%-5.2g %-4.3g %-4.3g %-6s %-8s %4d/%-4zu %4d/%-4zu %9.4f|%9.4f %9.4f|%9.4f %8.3f %4d/%-4zu\n",
                  std::get<0>(key), std::get<1>(key), std::get<2>(key), std::get<3>(key).c_str(),
                  std::get<4>(key).c_str(), ok, group.size(), acc, group.size(), median(es),
                  quantile(es, 0.95), median(ea), quantile(ea, 0.95), median(time), first_ok,
                  first[key].size());
      for (std::size_t c = 0; c < checks.size(); ++c) {
        const Check& ch = checks[c];
        if (ch.mode != std::get<4>(key) || std::get<0>(key) > ch.speed || std::abs(std::get<1>(key)) > ch.yaw_rate) continue;
        check_es[std::to_string(c)].insert(check_es[std::to_string(c)].end(), es.begin(), es.end());
        check_ea[std::to_string(c)].insert(check_ea[std::to_string(c)].end(), ea.begin(), ea.end());
      }
    }
    std::printf("v [m/s], w [deg/s] yaw rate, T [s] sweep duration (= interval); steady: increments "
                "2..%d of each run; first ok: successes of increment 1 (its reference is the first "
                "sweep: taken standing still, or bent if --start moving); med s: median time of "
                "the matcher's whole step (de-skew rounds included); success: Es < 0.10 m and Ea "
                "< 1 deg; CSV: %s\n",
                sweeps - 1, csv_path.c_str());
    for (std::size_t c = 0; c < checks.size(); ++c) {
      const Check& ch = checks[c];
      const auto& es = check_es[std::to_string(c)];
      const auto& ea = check_ea[std::to_string(c)];
      if (es.empty()) {
        failures.push_back("--check " + ch.mode + ": no run at or below the speed and yaw rate");
        continue;
      }
      std::printf("check %s up to %.2g m/s and %.3g deg/s: median Es %.4f m (<= %.4f), Ea %.4f deg (<= %.4f)\n",
                  ch.mode.c_str(), ch.speed, ch.yaw_rate, median(es), ch.es, median(ea), ch.ea);
      if (median(es) > ch.es || median(ea) > ch.ea) failures.push_back("--check " + ch.mode + " missed");
    }
    std::map<std::string, std::pair<int, int>> wrong;  // mode: accepted wrong, increments
    std::map<std::string, int> succeeded;                // mode: increments with success
    for (const Row& r : rows) {
      wrong[r.mode].first += r.acceptedWrong();
      ++wrong[r.mode].second;
      succeeded[r.mode] += r.success();
    }
    for (const auto& [mode, count] : wrong) {
      std::printf("%s: %d of %d increments accepted wrong (the registration off by 0.10 m or 1 deg), "
                  "%d succeeded\n",
                  mode.c_str(), count.first, count.second, succeeded[mode]);
    }
    if (!success_floor_mode.empty() &&
        succeeded[success_floor_mode] < success_floor * wrong[success_floor_mode].second) {
      failures.push_back("--min-success " + success_floor_mode + ": " +
                         std::to_string(succeeded[success_floor_mode]) + " of " +
                         std::to_string(wrong[success_floor_mode].second) + " succeeded");
    }
    if (!wrong_cap_mode.empty() && wrong[wrong_cap_mode].first > wrong_cap) {
      failures.push_back("--max-accepted-wrong " + wrong_cap_mode + ": " +
                         std::to_string(wrong[wrong_cap_mode].first) + " > " +
                         std::to_string(wrong_cap));
    }
    for (const std::string& f : failures) std::fprintf(stderr, "CHECK FAILED %s\n", f.c_str());
    if (!failures.empty()) return 2;
  } catch (const std::exception& e) {
    std::fprintf(stderr, "sweep_motion_benchmark: %s\n", e.what());
    return 1;
  }
  return 0;
}
