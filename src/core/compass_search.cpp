#include "cube_scan_matcher/core/compass_search.h"

#include <stdexcept>
#include <string>

#include "second_thread.h"

namespace cube_scan_matcher {

void validate(const CompassSettings& s) {
  if (!((s.initial_step.array() > 0.0).all() && s.initial_step.allFinite()))
    throw std::invalid_argument("compass initial_step must all be finite and > 0");
  if (s.levels < 1 || s.levels > 30)
    throw std::invalid_argument("compass levels must be in [1, 30], got " + std::to_string(s.levels));
  if (s.max_evaluations < 1 || s.max_evaluations > 10000000)
    throw std::invalid_argument("compass max_evaluations must be in [1, 1e7], got " +
                                std::to_string(s.max_evaluations));
}

namespace {

constexpr int kDirections = 12;  // -step, +step along each of the 6 parameters

/// Where the poll stands. The 12 directions are polled in a cycle and a level ends after 12
/// failures in a row: every point around the current best has then been polled. The point the
/// last move came from is a known failure (its value is below the best) and is not evaluated
/// again. The same moves as restarting the poll at direction 0 after each pass, without
/// re-polling the directions that already failed around the same best.
struct Poll {
  int level = 0;
  int d = 0;          // the direction polled next
  int failures = 0;   // failures in a row at this level
  int back = -1;      // the direction leading back to the point the last move left
  Vector6d step;

  /// Moves past the known failure and to the next level as needed; false when the search is
  /// over.
  bool settle(int levels) {
    for (;;) {
      if (failures >= kDirections) {
        if (++level >= levels) return false;
        step *= 0.5;
        d = 0, failures = 0, back = -1;
      } else if (d == back) {
        ++failures;
        d = (d + 1) % kDirections;
      } else {
        return true;
      }
    }
  }
  Vector6d point(const Vector6d& best) const {
    Vector6d q = best;
    q[d / 2] += (d % 2 ? 1.0 : -1.0) * step[d / 2];
    return q;
  }
  /// The poll after the point of direction d failed.
  void failed() {
    ++failures;
    d = (d + 1) % kDirections;
  }
};

/// Takes the value v of the point q that poll p proposed: a move when it beats the best.
void take(CompassResult& r, Poll& p, const Vector6d& q, double v) {
  ++r.evaluations;
  if (v > r.best_value) {
    r.best = q;
    r.best_value = v;
    ++r.moves;
    p.failures = 0;
    p.back = p.d ^ 1;
    p.d = (p.d + 1) % kDirections;
  } else {
    p.failed();
  }
}

CompassResult start(const Objective6& f, const Vector6d& initial, const CompassSettings& s,
                    Poll& p) {
  validate(s);
  CompassResult r;
  r.best = initial;
  r.best_value = r.initial_value = f(initial);
  r.evaluations = 1;
  p.step = s.initial_step;
  return r;
}

}  // namespace

CompassResult compassMaximize(const Objective6& f,
                              const Vector6d& initial, const CompassSettings& s) {
  Poll p;
  CompassResult r = start(f, initial, s, p);
  while (p.settle(s.levels) && r.evaluations < s.max_evaluations) {
    const Vector6d q = p.point(r.best);
    take(r, p, q, f(q));
  }
  return r;
}

CompassResult compassMaximizePaired(const Objective6& f0, const Objective6& f1,
                                    const Vector6d& initial, const CompassSettings& s) {
  Poll p;
  CompassResult r = start(f0, initial, s, p);
  Vector6d q1;       // the second thread's point and value: declared before the thread, so
  double v1 = 0.0;   // that they outlive a job still running when an exception unwinds
  SecondThread helper;
  while (p.settle(s.levels) && r.evaluations < s.max_evaluations) {
    const Vector6d q0 = p.point(r.best);
    // The point the poll proposes next if q0 fails (the best stays where it is).
    Poll next = p;
    next.failed();
    const bool pair = next.settle(s.levels) && r.evaluations + 1 < s.max_evaluations;
    if (pair) {
      q1 = next.point(r.best);
      helper.post([&] { v1 = f1(q1); });
    }
    const double v0 = f0(q0);
    if (pair) helper.wait();
    const bool moved = v0 > r.best_value;
    take(r, p, q0, v0);
    if (!pair) continue;
    if (moved) {
      ++r.speculated;  // q1 was polled around the old best: not used
      continue;
    }
    p = next;  // where take() left the poll after q0's failure, settled
    take(r, p, q1, v1);
  }
  return r;
}

}  // namespace cube_scan_matcher
