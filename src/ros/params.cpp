#include "cube_scan_matcher/ros/params.h"

#include <cmath>
#include <sstream>

#include <boost/any.hpp>
#include <dynamic_reconfigure/config_tools.h>

#include "cube_scan_matcher/core/pose.h"

namespace cube_scan_matcher {
namespace {

std::string getString(const ros::NodeHandle& pnh, const std::string& name, std::string value) {
  if (pnh.hasParam(name) && !pnh.getParam(name, value)) {
    throw ParamError("parameter ~" + name + " must be a string");
  }
  if (value.empty()) throw ParamError("parameter ~" + name + " must not be empty");
  return value;
}

bool getBool(const ros::NodeHandle& pnh, const std::string& name, bool value) {
  if (pnh.hasParam(name) && !pnh.getParam(name, value)) {
    throw ParamError("parameter ~" + name + " must be true or false");
  }
  return value;
}

/// Live parameters: the config's fields are the parameters of the same name.
void configToSettings(const ScanMatcherConfig& c, OnlineMatcherSettings& m) {
  RegistrationSettings& r = m.registration;
  r.grid.cube_edge = c.cube_edge;
  r.gnmm.vertices = c.vertices;
  r.gnmm.max_iterations = c.iterations;
  const double a = deg2rad(c.bounds_rotation_deg);
  r.gnmm.bounds << c.bounds_translation, c.bounds_translation, c.bounds_translation, a, a, a;
  r.gnmm.seed = std::uint64_t(c.seed);
  r.search.starts = c.starts;
  r.search.retries = c.retries;
  r.search.axis_probe_m = c.axis_probe;
  r.search.axis_probe_gain = c.axis_probe_gain;
  r.search.ambiguous_weak_ratio = c.ambiguous_weak_ratio;
  r.search.ambiguous_max_agreeing = c.ambiguous_max_agreeing;
  r.search.threads = c.threads;
  r.collapse_fraction = c.collapse_fraction;
  r.dense_points = c.dense_points;
  r.refine.enabled = c.refine;
  r.refine.edge_fraction = c.refine_edge_fraction;
  r.refine.grids = c.refine_grids;
  r.refine.candidates = c.refine_candidates;
  r.refine.coarse_weight = c.refine_coarse_weight;
  r.polish.enabled = c.polish;
  r.polish.voxel_fraction = c.polish_voxel_fraction;
  r.polish.kernel = c.polish_kernel;
  m.gate.min_overlap = c.min_overlap;
  m.gate.max_correction_m = c.max_correction_translation;
  m.gate.max_correction_rad = deg2rad(c.max_correction_rotation_deg);
  m.gate.require_polish = c.require_polish;
  m.gate.reject_degenerate = c.reject_degenerate;
  m.gate.reject_ambiguous = c.reject_ambiguous;
  m.gate.max_sigma_m = c.max_sigma_translation;
  m.max_consecutive_rejections = c.max_consecutive_rejections;
  m.keyframes.distance = c.keyframe_distance;
  m.keyframes.angle = deg2rad(c.keyframe_angle_deg);
  m.keyframes.interval = c.keyframe_interval;
  m.keyframes.submap_size = c.submap_keyframes;
  m.constant_velocity = c.constant_velocity;
  m.no_odometry_grid.half_width_m = c.no_odometry_grid_m;
  m.no_odometry_grid.half_yaw = deg2rad(c.no_odometry_grid_yaw_deg);
  m.no_motion_dense_points = c.no_motion_dense_points;
  m.deskew.enabled = c.deskew;
  m.deskew.iterations = c.deskew_iterations;
  m.deskew.max_rms_ratio = c.bent_sweep_rms_ratio;
  m.deskew.min_plane_fraction_ratio = c.bent_sweep_fraction_ratio;
}

/// The unit in a cfg description ("Cube edge E [m] (paper ...)" -> "m"), or "".
std::string unitOf(const std::string& description) {
  const std::size_t open = description.find('['), close = description.find(']', open);
  return open == std::string::npos || close == std::string::npos
             ? std::string()
             : description.substr(open + 1, close - open - 1);
}

/// Reads every parameter of cfg/ScanMatcher.cfg from ~name (default: its value in `c`) and
/// checks it against the cfg's own [min, max]: the cfg is the one source of the live
/// parameters' names, types and ranges.
void readLiveParams(const ros::NodeHandle& pnh, ScanMatcherConfig& c) {
  const ScanMatcherConfig& lo = ScanMatcherConfig::__getMin__();
  const ScanMatcherConfig& hi = ScanMatcherConfig::__getMax__();
  for (const auto& d : ScanMatcherConfig::__getParamDescriptions__()) {
    boost::any value, min, max;
    d->getValue(c, value);
    d->getValue(lo, min);
    d->getValue(hi, max);
    dynamic_reconfigure::Config msg;
    if (d->type == "double") {
      const double v = readParam(pnh, d->name, boost::any_cast<double>(value),
                                 boost::any_cast<double>(min), boost::any_cast<double>(max),
                                 unitOf(d->description));
      dynamic_reconfigure::ConfigTools::appendParameter(msg, d->name, v);
    } else if (d->type == "int") {
      const int v = readParam(pnh, d->name, boost::any_cast<int>(value),
                              boost::any_cast<int>(min), boost::any_cast<int>(max),
                              unitOf(d->description));
      dynamic_reconfigure::ConfigTools::appendParameter(msg, d->name, v);
    } else if (d->type == "bool") {
      const bool v = getBool(pnh, d->name, boost::any_cast<bool>(value));
      dynamic_reconfigure::ConfigTools::appendParameter(msg, d->name, v);
    } else {
      throw ParamError("parameter ~" + d->name + ": unsupported cfg type " + d->type);
    }
    d->fromMessage(msg, c);
  }
}

}  // namespace

ScanMatcherConfig toConfig(const NodeParams& p) {
  ScanMatcherConfig c = ScanMatcherConfig::__getDefault__();
  const RegistrationSettings& r = p.matcher.registration;
  c.cube_edge = r.grid.cube_edge;
  c.vertices = r.gnmm.vertices;
  c.iterations = r.gnmm.max_iterations;
  c.bounds_translation = r.gnmm.bounds[0];
  c.bounds_rotation_deg = rad2deg(r.gnmm.bounds[3]);
  c.seed = int(r.gnmm.seed);
  c.starts = r.search.starts;
  c.retries = r.search.retries;
  c.axis_probe = r.search.axis_probe_m;
  c.axis_probe_gain = r.search.axis_probe_gain;
  c.ambiguous_weak_ratio = r.search.ambiguous_weak_ratio;
  c.ambiguous_max_agreeing = r.search.ambiguous_max_agreeing;
  c.threads = r.search.threads;
  c.collapse_fraction = r.collapse_fraction;
  c.dense_points = r.dense_points;
  c.refine = r.refine.enabled;
  c.refine_edge_fraction = r.refine.edge_fraction;
  c.refine_grids = r.refine.grids;
  c.refine_candidates = r.refine.candidates;
  c.refine_coarse_weight = r.refine.coarse_weight;
  c.polish = r.polish.enabled;
  c.polish_voxel_fraction = r.polish.voxel_fraction;
  c.polish_kernel = r.polish.kernel;
  c.min_overlap = p.matcher.gate.min_overlap;
  c.max_correction_translation = p.matcher.gate.max_correction_m;
  c.max_correction_rotation_deg = rad2deg(p.matcher.gate.max_correction_rad);
  c.require_polish = p.matcher.gate.require_polish;
  c.reject_degenerate = p.matcher.gate.reject_degenerate;
  c.reject_ambiguous = p.matcher.gate.reject_ambiguous;
  c.max_sigma_translation = p.matcher.gate.max_sigma_m;
  c.max_consecutive_rejections = p.matcher.max_consecutive_rejections;
  c.keyframe_distance = p.matcher.keyframes.distance;
  c.keyframe_angle_deg = rad2deg(p.matcher.keyframes.angle);
  c.keyframe_interval = p.matcher.keyframes.interval;
  c.submap_keyframes = p.matcher.keyframes.submap_size;
  c.constant_velocity = p.matcher.constant_velocity;
  c.no_odometry_grid_m = p.matcher.no_odometry_grid.half_width_m;
  c.no_odometry_grid_yaw_deg = rad2deg(p.matcher.no_odometry_grid.half_yaw);
  c.no_motion_dense_points = p.matcher.no_motion_dense_points;
  c.deskew = p.matcher.deskew.enabled;
  c.deskew_iterations = p.matcher.deskew.iterations;
  c.bent_sweep_rms_ratio = p.matcher.deskew.max_rms_ratio;
  c.bent_sweep_fraction_ratio = p.matcher.deskew.min_plane_fraction_ratio;
  return c;
}

const std::vector<std::string>& knownParamNames() {
  static const std::vector<std::string> names = [] {
    std::vector<std::string> n = {
        "base_frame", "odom_frame", "map_frame", "tf_timeout", "time_jump_reset",
        "missing_tf_policy", "role", "odometry_sigma_translation", "odometry_sigma_rotation_deg",
        "reset_continuous", "transform_tolerance", "tf_rate", "queue_size", "path_max_length",
        "range_min", "range_max", "time_field", "max_grid_megabytes", "byte_grid_megabytes",
        "sigma_translation", "sigma_rotation_deg", "registration_sigma_scale", "drift_percent",
        "rejected_sigma_translation", "rejected_sigma_rotation_deg", "min_rate", "max_rate",
        "max_latency",
        // Read in the same namespace by the stand-alone node's nodelet::Loader (its threads).
        "num_worker_threads"};
    for (const auto& d : ScanMatcherConfig::__getParamDescriptions__()) n.push_back(d->name);
    return n;
  }();
  return names;
}

NodeParams loadParams(const ros::NodeHandle& pnh) {
  NodeParams p;
  // Renamed parameters are refused with their new name: the old value must not be lost.
  static const std::pair<const char*, const char*> kRenamed[] = {
      {"bounds_rotation", "bounds_rotation_deg"},
      {"max_correction_rotation", "max_correction_rotation_deg"},
      {"keyframe_angle", "keyframe_angle_deg"},
      {"sigma_rotation", "sigma_rotation_deg"},
      {"odometry_sigma_rotation", "odometry_sigma_rotation_deg"},
      {"rejected_sigma_rotation", "rejected_sigma_rotation_deg"},
      {"min_range", "range_min"},
      {"max_range", "range_max"}};
  for (const auto& [old_name, new_name] : kRenamed) {
    if (pnh.hasParam(old_name)) {
      throw ParamError(std::string("parameter ~") + old_name + " is now called ~" + new_name +
                       " (angles carry _deg in their names, ranges are named as LaserScan's)");
    }
  }
  p.base_frame = getString(pnh, "base_frame", p.base_frame);
  // odom_frame "" = a robot without odometry: no lookup, the motion model predicts each scan.
  if (pnh.hasParam("odom_frame") && !pnh.getParam("odom_frame", p.odom_frame)) {
    throw ParamError("parameter ~odom_frame must be a string (empty = no odometry)");
  }
  p.map_frame = getString(pnh, "map_frame", p.map_frame);
  if (p.map_frame == p.odom_frame || p.map_frame == p.base_frame) {
    throw ParamError("parameter ~map_frame must differ from ~odom_frame and ~base_frame");
  }
  if (p.odom_frame == p.base_frame) {
    throw ParamError("parameter ~odom_frame must differ from ~base_frame (empty = no odometry)");
  }
  p.tf_timeout = readParam(pnh, "tf_timeout", p.tf_timeout, 0.0, 10.0, "s");
  p.time_jump_reset = readParam(pnh, "time_jump_reset", p.time_jump_reset, 0.0, 3600.0, "s");
  const std::string policy = getString(pnh, "missing_tf_policy", "predict");
  if (policy == "identity") {
    throw ParamError(
        "parameter ~missing_tf_policy = 'identity' is now called 'predict' (a scan without "
        "odometry is registered from the motion model's prediction, not from an identity)");
  }
  if (policy != "predict" && policy != "skip") {
    throw ParamError("parameter ~missing_tf_policy = '" + policy + "' must be predict or skip");
  }
  p.skip_without_tf = policy == "skip";
  if (pnh.hasParam("publish_tf")) {
    throw ParamError(
        "parameter ~publish_tf is not read: set ~role to messages (no tf), map_odom (map -> odom "
        "from the registration chain) or anchored (map -> odom tied to the odometry)");
  }
  const std::string role = getString(pnh, "role", "messages");
  if (role == "messages") p.role = NodeParams::Role::Messages;
  else if (role == "map_odom") p.role = NodeParams::Role::MapOdom;
  else if (role == "anchored") p.role = NodeParams::Role::Anchored;
  else throw ParamError("parameter ~role = '" + role + "' must be messages, map_odom or anchored");
  if (!p.hasOdometry() && p.role != NodeParams::Role::Messages) {
    throw ParamError("parameter ~role = '" + role +
                     "' needs odometry (it sends map -> odom): with ~odom_frame empty (no "
                     "odometry) only role messages is possible");
  }
  if (!p.hasOdometry() && p.skip_without_tf) {
    throw ParamError(
        "parameter ~missing_tf_policy = 'skip' with ~odom_frame empty (no odometry) would drop "
        "every scan: use predict");
  }
  p.reset_continuous = getBool(pnh, "reset_continuous", p.reset_continuous);
  p.anchor.odometry_sigma_m = readParam(pnh, "odometry_sigma_translation",
                                        p.anchor.odometry_sigma_m, 1e-3, 1e3, "m");
  p.anchor.odometry_sigma_rad = deg2rad(readParam(pnh, "odometry_sigma_rotation_deg",
                                                  rad2deg(p.anchor.odometry_sigma_rad), 1e-3,
                                                  180.0, "deg"));
  p.transform_tolerance =
      readParam(pnh, "transform_tolerance", p.transform_tolerance, 0.0, 10.0, "s");
  p.tf_rate = readParam(pnh, "tf_rate", p.tf_rate, 0.1, 1000.0, "Hz");
  p.queue_size = readParam(pnh, "queue_size", p.queue_size, 1, 100);
  p.path_max_length = readParam(pnh, "path_max_length", p.path_max_length, 1, 1000000);
  p.filter.min_range = readParam(pnh, "range_min", p.filter.min_range, 0.0, 1e4, "m");
  const double range_max = readParam(pnh, "range_max", 0.0, 0.0, 1e6, "m (0 = no limit)");
  p.filter.max_range = range_max > 0.0 ? range_max : 1e9;
  if (p.filter.max_range <= p.filter.min_range) {
    throw ParamError("parameter ~range_max must exceed ~range_min (or be 0 = no limit)");
  }
  if (pnh.hasParam("time_field") && !pnh.getParam("time_field", p.time_field)) {
    throw ParamError("parameter ~time_field must be a string (empty = no point times)");
  }
  p.chain.sigma_m = readParam(pnh, "sigma_translation", p.chain.sigma_m, 1e-6, 100.0, "m");
  p.chain.sigma_rad =
      deg2rad(readParam(pnh, "sigma_rotation_deg", rad2deg(p.chain.sigma_rad), 1e-6, 180.0, "deg"));
  if (pnh.hasParam("rejected_sigma_scale")) {
    throw ParamError(
        "parameter ~rejected_sigma_scale is not read: set ~rejected_sigma_translation [m] and "
        "~rejected_sigma_rotation_deg [deg], the odometry's error over one increment");
  }
  p.chain.registration_scale = readParam(pnh, "registration_sigma_scale",
                                         p.chain.registration_scale, 1e-3, 1.0);
  p.chain.drift_fraction =
      readParam(pnh, "drift_percent", 100.0 * p.chain.drift_fraction, 0.0, 100.0, "%") / 100.0;
  p.chain.rejected_sigma_m = readParam(pnh, "rejected_sigma_translation", p.chain.rejected_sigma_m,
                                       1e-6, 100.0, "m");
  p.chain.rejected_sigma_rad =
      deg2rad(readParam(pnh, "rejected_sigma_rotation_deg", rad2deg(p.chain.rejected_sigma_rad), 1e-6,
                        180.0, "deg"));
  p.min_rate = readParam(pnh, "min_rate", p.min_rate, 0.0, 1000.0, "Hz");
  p.max_rate = readParam(pnh, "max_rate", p.max_rate, 0.0, 1e6, "Hz");
  if (p.max_rate <= p.min_rate) throw ParamError("parameter ~max_rate must exceed ~min_rate");
  p.max_latency = readParam(pnh, "max_latency", p.max_latency, 1e-3, 1000.0, "s");
  const double megabytes = readParam(pnh, "max_grid_megabytes", 256.0, 1.0, 256.0, "MB");
  p.matcher.registration.grid.max_cubes = std::uint64_t(megabytes * 8.0 * 1024.0 * 1024.0);
  const double byte_megabytes = readParam(pnh, "byte_grid_megabytes", 4.0, 0.0, 256.0, "MB");
  p.matcher.registration.grid.max_byte_cubes = std::uint64_t(byte_megabytes * 1024.0 * 1024.0);

  // Live parameters: names, types and ranges from cfg/ScanMatcher.cfg, defaults from the code.
  ScanMatcherConfig c = toConfig(p);
  readLiveParams(pnh, c);
  applyConfig(c, p);
  return p;
}

void applyConfig(const ScanMatcherConfig& config, NodeParams& params) {
  OnlineMatcherSettings m = params.matcher;
  configToSettings(config, m);
  try {
    validate(m);
  } catch (const std::invalid_argument& e) {
    throw ParamError(std::string("invalid parameters: ") + e.what());
  }
  params.matcher = m;
}

}  // namespace cube_scan_matcher
