#include "cube_scan_matcher/core/filters.h"

#include <cmath>
#include <stdexcept>
#include <string>

namespace cube_scan_matcher {

void validate(const RangeFilterSettings& s) {
  if (!(s.min_range >= 0.0) || !std::isfinite(s.min_range)) {
    throw std::invalid_argument("min_range must be finite and >= 0 m, got " +
                                std::to_string(s.min_range));
  }
  if (!(s.max_range > s.min_range)) {
    throw std::invalid_argument("max_range (" + std::to_string(s.max_range) +
                                " m) must be greater than min_range (" +
                                std::to_string(s.min_range) + " m)");
  }
  if (!s.origin.allFinite()) throw std::invalid_argument("filter origin must be finite");
}

FilterStats appendFiltered(const float* x, const float* y, const float* z, std::size_t count,
                           std::size_t stride, const RangeFilterSettings& s, PointArray& out) {
  FilterStats st;
  st.input = count;
  const double min2 = s.min_range * s.min_range;
  const double max2 = s.max_range * s.max_range;
  out.reserve(out.size() + count);
  for (std::size_t i = 0; i < count; ++i) {
    const float px = x[i * stride], py = y[i * stride], pz = z[i * stride];
    if (!std::isfinite(px) || !std::isfinite(py) || !std::isfinite(pz)) {
      ++st.non_finite;
      continue;
    }
    const double dx = px - s.origin.x(), dy = py - s.origin.y(), dz = pz - s.origin.z();
    const double r2 = dx * dx + dy * dy + dz * dz;
    if (r2 < min2 || r2 > max2) {
      ++st.out_of_range;
      continue;
    }
    out.push_back(px, py, pz);
    ++st.kept;
  }
  return st;
}

PointArray filterPoints(const PointArray& in, const RangeFilterSettings& settings,
                        FilterStats* stats) {
  PointArray out;
  FilterStats st = appendFiltered(in.x.data(), in.y.data(), in.z.data(), in.size(), 1, settings,
                                  out);
  if (stats) *stats = st;
  return out;
}

std::vector<std::uint32_t> keptIndices(const PointArray& in, const std::vector<float>& times,
                                       const RangeFilterSettings& settings, FilterStats* stats) {
  if (!times.empty() && times.size() != in.size()) {
    throw std::invalid_argument("keptIndices: " + std::to_string(times.size()) + " times for " +
                                std::to_string(in.size()) + " points");
  }
  std::vector<std::uint32_t> kept;
  kept.reserve(in.size());
  FilterStats st;
  st.input = in.size();
  PointArray one_out;
  for (std::size_t i = 0; i < in.size(); ++i) {
    if (!times.empty() && !std::isfinite(times[i])) {
      ++st.non_finite;
      continue;
    }
    one_out.clear();
    const FilterStats one = appendFiltered(&in.x[i], &in.y[i], &in.z[i], 1, 1, settings, one_out);
    st.non_finite += one.non_finite;
    st.out_of_range += one.out_of_range;
    if (!one_out.empty()) kept.push_back(std::uint32_t(i));
  }
  st.kept = kept.size();
  if (stats) *stats = st;
  return kept;
}

PointArray filterPoints(const PointArray& in, const std::vector<float>& times,
                        const RangeFilterSettings& settings, std::vector<float>& times_out,
                        FilterStats* stats) {
  if (times.size() != in.size()) {
    throw std::invalid_argument("filterPoints: " + std::to_string(times.size()) + " times for " +
                                std::to_string(in.size()) + " points");
  }
  PointArray out;
  FilterStats st;
  st.input = in.size();
  times_out.clear();
  for (std::size_t i = 0; i < in.size(); ++i) {
    if (!std::isfinite(times[i])) {  // a point without a time cannot be placed
      ++st.non_finite;
      continue;
    }
    const std::size_t before = out.size();
    const FilterStats one = appendFiltered(&in.x[i], &in.y[i], &in.z[i], 1, 1, settings, out);
    st.non_finite += one.non_finite;
    st.out_of_range += one.out_of_range;
    if (out.size() > before) times_out.push_back(times[i]);
  }
  st.kept = out.size();
  if (stats) *stats = st;
  return out;
}

}  // namespace cube_scan_matcher
