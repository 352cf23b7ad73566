// Where a sweep of a tilting 2D laser ends: the sweep cutter of SweepAssemblerNodelet.
// ROS-free: it sees one (time, tilt angle) pair per scan line, in arrival order, and
// says per line whether the sweep goes on, ends, or which lines are discarded and why. The
// caller keeps the lines themselves (their points) in a queue in step with pendingLines():
//
//   CutResult r = cutter.addLine(t, angle);
//   if (r.line_kept) queue.push_back(line);
//   take r.closed_lines lines off the queue's front: a sweep (SweepEnded) or dropped (Discarded)
//
// A sweep ends (all times are the lines' stamps, not the wall clock):
//  - at a turning point of the tilt: the angle moves back from its running extreme by more than
//    turn_hysteresis. The sweep ends with the line at the extreme (included); the lines after it
//    already received start the next sweep. Noise smaller than the hysteresis never cuts;
//  - when the line's time is sweep_duration or more after the sweep's first line (if > 0); the
//    line starts the next sweep. This is the only cut without a tilt angle (duration mode);
//  - when the tilt stalls: the angle stays within turn_hysteresis of where it was for
//    stall_timeout. The sweep is closed with the line that shows it (reason Stall). Then, while
//    the angle stays within turn_hysteresis of where it stopped, each line is discarded (reason
//    Stalled, line_kept false): a scanner that stopped tilting sweeps one plane again and again,
//    which is no 3D sweep (its period is undefined and a single plane cannot be registered).
//    The first line that has moved on by more than the hysteresis starts a new sweep;
//  - when the sweep reaches max_lines lines (a bound on memory for a tilt that neither turns
//    nor stalls, e.g. a wrong tilt_axis); the line is the sweep's last (reason MaxLines);
//  - at a gap: a line more than max_line_gap after the previous one. The line starts the next
//    sweep;
//  - when time goes backwards by more than max_line_gap (a bag replayed in a loop, a clock
//    reset): the sweep is closed as at a gap and everything is forgotten (reason TimeBackwards);
//    the line starts afresh. A line at most max_line_gap older than the newest line is late
//    (arrived out of order after a newer one was used): it is discarded (reason LateLine,
//    line_kept false) so that time never goes backwards within a sweep.
// A closed sweep with fewer than min_lines lines is discarded instead (event Discarded with the
// reason that closed it).
#pragma once

#include <cstddef>
#include <deque>
#include <optional>
#include <string>

namespace cube_scan_matcher {

struct SweepCutterSettings {
  /// [rad] the tilt must move back from its extreme by more than this to cut at a turning
  /// point, and move by more than this within stall_timeout not to count as stalled. >= 0
  /// (0 = any reversal cuts). Larger than the peak-to-peak noise of the angle.
  double turn_hysteresis = 0.0175;  // 1 deg
  /// [s] a sweep ends when a line is this long after the sweep's first line; 0 = off (cut at
  /// turning points only). >= 0; without a tilt angle it must be > 0 (the only cut then).
  double sweep_duration = 0.0;
  /// [s] the tilt counts as stalled when it has not moved by more than turn_hysteresis for this
  /// long; 0 = off. >= 0; larger than the dwell at a turning point.
  double stall_timeout = 1.0;
  /// [s] a larger gap between consecutive lines closes the sweep; also how much older than the
  /// newest line a late line may be (older still is time going backwards). > 0.
  double max_line_gap = 0.5;
  /// A closed sweep with fewer lines is discarded. >= 1.
  int min_lines = 10;
  /// A sweep is closed when it has this many lines. >= min_lines.
  int max_lines = 10000;
};

/// Throws std::invalid_argument naming the bad setting.
void validate(const SweepCutterSettings& settings);

enum class CutEvent {
  Continue,    ///< the line was added to the current sweep (or started one); nothing closed.
  SweepEnded,  ///< the oldest closed_lines pending lines are a sweep: publish them.
  Discarded,   ///< the oldest closed_lines pending lines (maybe 0) are dropped, and/or the new
               ///< line itself (line_kept false).
};

/// What closed a sweep or discarded lines.
enum class CutReason {
  None,           ///< (Continue)
  TurningPoint,   ///< the tilt reversed.
  Duration,       ///< sweep_duration elapsed since the sweep's first line.
  Stall,          ///< the tilt stopped moving for stall_timeout: the sweep is closed.
  Stalled,        ///< a line while the tilt stays stalled: the line is discarded.
  MaxLines,       ///< the sweep reached max_lines lines.
  Gap,            ///< more than max_line_gap between two lines.
  TimeBackwards,  ///< time jumped back by more than max_line_gap: the cutter was reset.
  LateLine,       ///< the line is older than the newest line (by at most max_line_gap).
};
std::string toString(CutReason reason);

struct CutResult {
  CutEvent event = CutEvent::Continue;
  CutReason reason = CutReason::None;
  /// SweepEnded / Discarded: how many of the oldest pending lines (counted after the new line
  /// was added, if line_kept) form the sweep or are discarded.
  std::size_t closed_lines = 0;
  /// Whether the new line was added to the pending lines (false: LateLine, Stalled).
  bool line_kept = true;
};

class SweepCutter {
 public:
  /// Throws std::invalid_argument for invalid settings (validate()).
  explicit SweepCutter(const SweepCutterSettings& settings = {});

  /// One line: its time [s] (e.g. the scan's stamp) and, if known, the tilt angle [rad] at that
  /// time (any continuous angle; jumps of 2 pi are unwrapped). Lines without an angle take part
  /// in the duration, gap and time checks only.
  CutResult addLine(double time, std::optional<double> angle);

  /// Forgets everything: pending lines, direction, stall state, the newest time.
  void reset();

  /// Lines received and not yet closed or discarded (the start of the current sweep).
  std::size_t pendingLines() const { return pending_.size(); }
  /// True while lines are discarded because the tilt has stalled.
  bool stalled() const { return stalled_; }
  const SweepCutterSettings& settings() const { return settings_; }

 private:
  struct Line {
    double time;
    std::optional<double> angle;  // unwrapped
  };
  /// Closes the oldest `n` pending lines: SweepEnded if n >= min_lines, else Discarded.
  CutResult close(std::size_t n, CutReason reason);
  /// The turning-point detector fed with line `index` of pending_ at angle `a`; true when the
  /// tilt has moved back from the extreme (extreme_index_) by more than turn_hysteresis.
  bool updateTurn(std::size_t index, double a);
  /// Restarts the detector with a known (+1, -1) or unknown (0) direction and replays the
  /// pending lines' angles into it.
  void restartTurnDetector(int direction);
  double unwrap(double angle);

  SweepCutterSettings settings_;
  std::deque<Line> pending_;
  std::optional<double> newest_time_;
  std::optional<double> last_angle_;  // unwrapped, for the unwrapping of the next
  // Turning points: direction of the tilt (+1, -1, 0 = not yet known), the angle the direction
  // is judged from while unknown, and the extreme so far with its index in pending_.
  int direction_ = 0;
  double reference_angle_ = 0.0;
  bool has_reference_ = false;
  double extreme_angle_ = 0.0;
  std::size_t extreme_index_ = 0;
  // Stall: the angle and time of the last move by more than turn_hysteresis.
  std::optional<double> anchor_angle_;
  double anchor_time_ = 0.0;
  bool stalled_ = false;
};

}  // namespace cube_scan_matcher
