// libFuzzer harness: the core on small arbitrary clouds and arbitrary guesses (NaN, inf and
// huge values included), the way the tools and the nodelet call it: filter, set the reference,
// align. CubeGridError (an empty or absurd reference) is the documented answer to bad input;
// every other outcome must be a result with a status.
#include <fuzzer/FuzzedDataProvider.h>

#include <cstddef>
#include <cstdint>
#include <cstring>

#include "cube_scan_matcher/core/filters.h"
#include "cube_scan_matcher/core/registration.h"

using namespace cube_scan_matcher;

namespace {
// Raw bit patterns, so that NaN, inf, denormals and huge values all occur.
template <typename T, typename Bits>
T raw(FuzzedDataProvider& in) {
  const Bits b = in.ConsumeIntegral<Bits>();
  T v;
  std::memcpy(&v, &b, sizeof v);
  return v;
}
PointArray points(FuzzedDataProvider& in, int n) {
  PointArray p;
  for (int i = 0; i < n && in.remaining_bytes() >= 12; ++i) {
    // Mostly near the origin (so that clouds overlap), sometimes anything at all.
    const bool wild = in.ConsumeIntegralInRange<int>(0, 7) == 0;
    float c[3];
    for (float& v : c) {
      v = wild ? raw<float, std::uint32_t>(in) : in.ConsumeFloatingPointInRange<float>(-5.f, 5.f);
    }
    p.push_back(c[0], c[1], c[2]);
  }
  return p;
}
}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  FuzzedDataProvider in(data, size);
  RegistrationSettings s;  // the shipped mode, with small budgets so that each input is quick
  s.grid.cube_edge = in.ConsumeFloatingPointInRange<double>(0.05, 2.0);
  s.grid.max_cubes = std::uint64_t{1} << 24;
  s.gnmm.max_iterations = in.ConsumeIntegralInRange<int>(1, 30);
  s.search.starts = in.ConsumeIntegralInRange<int>(1, 3);
  s.search.threads = 1;
  s.refine.enabled = in.ConsumeBool();
  s.refine.compass.max_evaluations = 200;
  Pose6 guess;
  for (int k = 0; k < 6; ++k) {
    guess[k] = in.ConsumeBool() ? raw<double, std::uint64_t>(in)
                                : in.ConsumeFloatingPointInRange<double>(-1.0, 1.0);
  }
  const int n_ref = in.ConsumeIntegralInRange<int>(0, 64);
  const PointArray ref = filterPoints(points(in, n_ref), RangeFilterSettings{});
  const PointArray scan = filterPoints(points(in, 64), RangeFilterSettings{});
  CubeRegistration reg(s);
  try {
    reg.setReference(ref);
  } catch (const CubeGridError&) {
    return 0;
  }
  const RegistrationResult r = reg.align(scan, guess);
  if (r.ok() && !r.pose.allFinite()) __builtin_trap();  // an accepted pose must be finite
  reg.score(scan, r.pose);
  return 0;
}
