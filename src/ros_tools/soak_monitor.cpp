// soak_monitor: watches a long run of the scan matcher (scripts/soak.sh replays a recorded
// demo bag in a loop) and reports what a soak should show: the manager still alive, its
// resident memory over time, latency, drops, and every registration against the simulator's
// ground truth, including whether each gate rejection was right (the rejected result really
// was off) or wrong (the result was right and the gate threw it away).
//   rosrun cube_scan_matcher soak_monitor _duration:=600 _pid:=1234 [_matcher_ns:=scan_matcher]
//     [_max_accepted_wrong:=0] [_min_accepted_share:=0.9]
// Exit code 0 when the process lived to the end, memory stayed flat (the maximum over the
// second half within 10 % of the first half's), scans were registered, at most
// max_accepted_wrong accepted increments were off the truth (by 10 cm or 1 deg or more) and at
// least min_accepted_share of the registrations with a truth were accepted; 1 otherwise.
#include <algorithm>
#include <cstdio>
#include <fstream>
#include <map>
#include <optional>
#include <sstream>
#include <string>
#include <vector>

#include <geometry_msgs/PoseStamped.h>
#include <ros/ros.h>
#include <tf2_eigen/tf2_eigen.h>

#include "cube_scan_matcher/Status.h"
#include "cube_scan_matcher/core/metrics.h"
#include "cube_scan_matcher/core/pose.h"

using namespace cube_scan_matcher;

namespace {

/// Resident set size [MB] of process `pid`, or a negative value when it is gone.
double residentMegabytes(int pid) {
  std::ifstream f("/proc/" + std::to_string(pid) + "/status");
  std::string line;
  while (std::getline(f, line)) {
    if (line.rfind("VmRSS:", 0) == 0) return std::stod(line.substr(6)) / 1024.0;
  }
  return -1.0;
}

/// A registration is right when its increment is within these of the truth (eqs. 7-8).
constexpr double kRightM = 0.10, kRightDeg = 1.0;

struct Monitor {
  std::map<ros::Time, Eigen::Isometry3d> truth;
  std::vector<Status> pending;  // statuses whose truth has not arrived yet
  std::optional<ros::Time> reference;  // stamp of the current reference scan
  int statuses = 0, loops = 0, accepted = 0, first = 0, bad = 0, skipped = 0;
  int accepted_wrong = 0, rejected_right = 0, rejected_wrong = 0, rejected_unregistered = 0, no_truth = 0;
  int scaled_gates = 0;  // registrations gated with bounds scaled for missed scans
  std::map<std::string, int> reasons;
  std::uint32_t dropped_this_loop = 0, dropped_total = 0;
  std::vector<double> latency, inc_es, inc_ea;
  double worst_accepted_es = 0, worst_accepted_ea = 0;

  void onStatus(const Status& s) {
    ++statuses;
    ++reasons[s.reason_text];
    latency.push_back(s.latency);
    if (s.gate_scale > 1.0) ++scaled_gates;
    if (s.time_reset) {  // a new loop of the bag: the matcher reset its counters
      ++loops;
      dropped_total += dropped_this_loop;
      dropped_this_loop = 0;
      reference.reset();
    }
    dropped_this_loop = std::max(dropped_this_loop, s.dropped_scans);
    evaluate(s);
    if (s.reference_updated) reference = s.header.stamp;
  }

  void evaluate(const Status& s) {
    if (s.reason == Status::FIRST_SCAN) return void(++first);
    if (s.reason == Status::BAD_INPUT || s.reason == Status::BAD_REFERENCE) return void(++bad);
    if (s.reason == Status::SKIPPED_NO_TF) return void(++skipped);
    const bool registered = s.J > 0 || s.accepted;
    if (!registered) return void(++rejected_unregistered);
    auto a = reference ? truth.find(*reference) : truth.end();
    auto b = truth.find(s.header.stamp);
    if (a == truth.end() || b == truth.end()) return void(++no_truth);
    Pose6 guess, correction;
    for (int k = 0; k < 6; ++k) {
      guess[k] = s.guess[std::size_t(k)];
      correction[k] = s.correction[std::size_t(k)];
    }
    const Eigen::Isometry3d result = poseToIsometry(guess) * poseToIsometry(correction);
    const PoseError e = poseError(result, a->second.inverse() * b->second);
    const bool right = e.es_m < kRightM && e.ea_deg < kRightDeg;
    if (s.accepted) {
      ++accepted;
      inc_es.push_back(e.es_m);
      inc_ea.push_back(e.ea_deg);
      if (!right) {
        ++accepted_wrong;
        std::printf("soak: accepted but off: scan at %.3f s (loop %d), Es %.3f m, Ea %.2f deg, overlap %.3f, "
                    "gate scale %.1f, guess from %s\n", s.header.stamp.toSec(), loops + 1, e.es_m, e.ea_deg,
                    s.overlap, s.gate_scale, s.odometry_guess ? "odometry" : "identity (no odometry)");
      }
      worst_accepted_es = std::max(worst_accepted_es, e.es_m);
      worst_accepted_ea = std::max(worst_accepted_ea, e.ea_deg);
    } else {
      ++(right ? rejected_wrong : rejected_right);
    }
  }
};

}  // namespace

int main(int argc, char** argv) {
  ros::init(argc, argv, "soak_monitor");
  ros::NodeHandle nh, pnh("~");
  const double duration = pnh.param("duration", 600.0);
  const int pid = pnh.param("pid", 0);
  const std::string ns = pnh.param<std::string>("matcher_ns", "scan_matcher");
  const int max_accepted_wrong = pnh.param("max_accepted_wrong", 0);
  const double min_accepted_share = pnh.param("min_accepted_share", 0.9);
  if (pid <= 0 || residentMegabytes(pid) < 0) {
    std::fprintf(stderr, "soak_monitor: ~pid must be the running matcher's process id, got %d\n", pid);
    return 1;
  }

  Monitor m;
  // Statuses are evaluated in order, each once its truth is there (the bag publishes the truth
  // with the cloud; the status comes after the registration).
  std::size_t done = 0;
  auto drain = [&] {
    for (; done < m.pending.size(); ++done) {
      const Status& s = m.pending[done];
      if (!m.truth.count(s.header.stamp) && (s.J > 0 || s.accepted)) break;
      m.onStatus(s);
    }
    if (done == m.pending.size()) m.pending.clear(), done = 0;
  };
  ros::Subscriber truth_sub = nh.subscribe<geometry_msgs::PoseStamped>(
      "ground_truth", 100, [&](const geometry_msgs::PoseStamped::ConstPtr& msg) {
        tf2::fromMsg(msg->pose, m.truth[msg->header.stamp]);
        drain();
      });
  ros::Subscriber status_sub = nh.subscribe<Status>(ns + "/status", 100, [&](const Status::ConstPtr& msg) {
    m.pending.push_back(*msg);
    drain();
  });

  std::vector<double> rss;  // one sample per second
  const ros::WallTime start = ros::WallTime::now();
  ros::WallTime next_sample = start;
  bool alive = true;
  while (ros::ok() && (ros::WallTime::now() - start).toSec() < duration) {
    ros::spinOnce();
    if (ros::WallTime::now() >= next_sample) {
      const double mb = residentMegabytes(pid);
      if (mb < 0) {
        alive = false;
        break;
      }
      rss.push_back(mb);
      next_sample += ros::WallDuration(1.0);
    }
    ros::WallDuration(0.005).sleep();
  }
  const double elapsed = (ros::WallTime::now() - start).toSec();
  m.dropped_total += m.dropped_this_loop;
  // Statuses still waiting for truth are counted without an evaluation.
  for (std::size_t i = done; i < m.pending.size(); ++i) m.onStatus(m.pending[i]);

  const std::size_t half = rss.size() / 2;
  const double first_max = half ? *std::max_element(rss.begin(), rss.begin() + std::ptrdiff_t(half)) : 0.0;
  const double second_max = half ? *std::max_element(rss.begin() + std::ptrdiff_t(half), rss.end()) : 0.0;
  const double rss_min = rss.empty() ? 0.0 : *std::min_element(rss.begin(), rss.end());
  const bool flat = half > 0 && second_max <= 1.10 * first_max;

  std::ostringstream reasons;
  for (const auto& [name, n] : m.reasons) reasons << " " << name << " " << n;
  std::printf("soak: %.0f s, process %s, %d statuses over %d bag loops (%d drops counted by the queue)\n",
              elapsed, alive ? "alive to the end" : "GONE", m.statuses, m.loops + 1, int(m.dropped_total));
  std::printf("soak: reasons:%s; %d gated with bounds scaled for missed scans\n", reasons.str().c_str(),
              m.scaled_gates);
  std::printf("soak: latency median %.0f ms, p95 %.0f ms, max %.0f ms\n", 1e3 * quantile(m.latency, 0.5),
              1e3 * quantile(m.latency, 0.95), 1e3 * quantile(m.latency, 1.0));
  std::printf("soak: accepted increments vs truth: %d (%d off by >= %.2f m or %.1f deg), Es median %.3f m "
              "max %.3f m, Ea median %.2f deg max %.2f deg\n",
              m.accepted, m.accepted_wrong, kRightM, kRightDeg, quantile(m.inc_es, 0.5),
              m.worst_accepted_es, quantile(m.inc_ea, 0.5), m.worst_accepted_ea);
  std::printf("soak: rejected registrations: %d right (result off by >= %.2f m or %.1f deg), %d wrong "
              "(result within), %d with no result; %d without truth\n",
              m.rejected_right, kRightM, kRightDeg, m.rejected_wrong, m.rejected_unregistered, m.no_truth);
  std::printf("soak: resident memory %.1f-%.1f MB; max first half %.1f MB, second half %.1f MB (%s)\n",
              rss_min, std::max(first_max, second_max), first_max, second_max,
              flat ? "flat: within 10 %" : "GROWING: beyond 10 %");
  const int judged = m.accepted + m.rejected_right + m.rejected_wrong + m.rejected_unregistered;
  const bool right = m.accepted_wrong <= max_accepted_wrong;
  const bool enough = judged > 0 && m.accepted >= min_accepted_share * judged;
  std::printf("soak: %d of %d registrations accepted (%.1f %%, at least %.0f %% needed); %d accepted "
              "off (at most %d allowed)\n",
              m.accepted, judged, judged ? 100.0 * m.accepted / judged : 0.0, 100.0 * min_accepted_share,
              m.accepted_wrong, max_accepted_wrong);
  const bool ok = alive && flat && m.statuses > 0 && right && enough;
  std::printf("soak: %s\n", ok ? "PASSED" : "FAILED");
  return ok ? 0 : 1;
}
