#include "cube_scan_matcher/ros_tools/sweep_evaluator.h"

#include <algorithm>
#include <cstdio>

#include <tf2_eigen/tf2_eigen.h>

#include "cube_scan_matcher/core/metrics.h"
#include "cube_scan_matcher/core/pose.h"

namespace cube_scan_matcher {

SweepEvaluator::SweepEvaluator(ros::NodeHandle& nh, const std::string& truth_topic,
                               const std::string& ns) {
  truth_sub_ = nh.subscribe<geometry_msgs::PoseStamped>(
      truth_topic, 100, [this](const geometry_msgs::PoseStamped::ConstPtr& m) {
        Sweep& s = sweeps_[m->header.stamp];
        tf2::fromMsg(m->pose, s.truth);
        s.has_truth = true;
        update();
      });
  pose_sub_ = nh.subscribe<geometry_msgs::PoseWithCovarianceStamped>(
      ns + "/pose", 100, [this](const geometry_msgs::PoseWithCovarianceStamped::ConstPtr& m) {
        Sweep& s = sweeps_[m->header.stamp];
        tf2::fromMsg(m->pose.pose, s.pose);
        s.has_pose = true;
        update();
      });
  status_sub_ = nh.subscribe<Status>(ns + "/status", 100, [this](const Status::ConstPtr& m) {
    Sweep& s = sweeps_[m->header.stamp];
    s.status = *m;
    s.has_status = true;
    update();
  });
  cloud_sub_ = nh.subscribe<sensor_msgs::PointCloud2>(
      ns + "/registered_cloud", 5, [this](const sensor_msgs::PointCloud2::ConstPtr& m) {
        ++clouds_;
        cloud_points_[m->header.stamp] = m->width * m->height;
      });
}

void SweepEvaluator::update() {
  // Rows are emitted in stamp order, each once its sweep is complete. A sweep the matcher
  // never answered while a later one was (dropped by its queue) gets a "dropped" row, and the
  // next increment is measured from the last sweep that has a pose.
  while (true) {
    const std::size_t next = rows_.size();
    if (sweeps_.size() <= next) return;
    auto it = std::next(sweeps_.begin(), std::ptrdiff_t(next));
    const Sweep& s = it->second;
    SweepRow row;
    row.sweep = int(next);
    row.stamp = it->first;
    if (!(s.has_truth && s.has_pose && s.has_status)) {
      const bool answered_later = std::any_of(std::next(it), sweeps_.end(), [](const auto& kv) {
        return kv.second.has_status && kv.second.has_pose;
      });
      if (!(s.has_truth && !s.has_status && answered_later)) return;
      row.reason = "dropped";
      rows_.push_back(row);
      continue;
    }
    row.reason = s.status.reason_text;
    row.accepted = s.status.accepted;
    row.latency = s.status.latency;
    if (last_posed_) {
      const Sweep& p = sweeps_.at(*last_posed_);
      const Eigen::Isometry3d true_inc = p.truth.inverse() * s.truth;
      Pose6 g;
      for (int k = 0; k < 6; ++k) g[k] = s.status.guess[std::size_t(k)];
      const PoseError eg = poseError(poseToIsometry(g), true_inc);
      const PoseError ei = poseError(p.pose.inverse() * s.pose, true_inc);
      const PoseError ea = poseError(s.pose, s.truth);
      row.guess_es = eg.es_m, row.guess_ea = eg.ea_deg;
      row.inc_es = ei.es_m, row.inc_ea = ei.ea_deg;
      row.acc_es = ea.es_m, row.acc_ea = ea.ea_deg;
    }
    last_posed_ = it->first;
    rows_.push_back(row);
  }
}

std::string SweepEvaluator::header() {
  char buf[256];
  std::snprintf(buf, sizeof buf, "%5s %-12s %9s %9s %9s %9s %9s %9s %8s", "sweep", "status",
                "guess Es", "guess Ea", "inc Es", "inc Ea", "acc Es", "acc Ea", "latency");
  return std::string(buf) + "\n" +
         "                     [m]     [deg]       [m]     [deg]       [m]     [deg]      [s]";
}

std::string SweepEvaluator::format(const SweepRow& r) {
  char buf[256];
  std::snprintf(buf, sizeof buf, "%5d %-12s %9.3f %9.3f %9.3f %9.3f %9.3f %9.3f %8.3f", r.sweep,
                r.reason.substr(0, 12).c_str(), r.guess_es, r.guess_ea, r.inc_es, r.inc_ea,
                r.acc_es, r.acc_ea, r.latency);
  return buf;
}

std::string SweepEvaluator::summary() const {
  std::vector<double> es, ea, lat;
  int ok = 0, accepted = 0;
  int dropped = 0;
  for (const SweepRow& r : rows_) {
    if (r.reason == "dropped") ++dropped;
    if (r.sweep == 0 || r.reason == "dropped") continue;
    es.push_back(r.inc_es);
    ea.push_back(r.inc_ea);
    lat.push_back(r.latency);
    ok += r.inc_es < 0.10 && r.inc_ea < 1.0;
    accepted += r.accepted;
  }
  if (es.empty()) return "summary: no registered sweep";
  const SweepRow& last = *std::find_if(rows_.rbegin(), rows_.rend(),
                                       [](const SweepRow& r) { return r.reason != "dropped"; });
  char buf[512];
  std::snprintf(buf, sizeof buf,
                "summary over %zu increments: Es median %.3f m (max %.3f), Ea median %.3f deg "
                "(max %.3f), success (Es < 0.10 m, Ea < 1 deg) %d/%zu, accepted %d/%zu, final "
                "pose error %.3f m / %.3f deg, latency median %.3f s, %d dropped",
                es.size(), quantile(es, 0.5), *std::max_element(es.begin(), es.end()), quantile(ea, 0.5),
                *std::max_element(ea.begin(), ea.end()), ok, es.size(), accepted, es.size(),
                last.acc_es, last.acc_ea, quantile(lat, 0.5), dropped);
  return buf;
}

}  // namespace cube_scan_matcher
