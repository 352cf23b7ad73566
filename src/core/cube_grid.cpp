#include "cube_scan_matcher/core/cube_grid.h"

#include <algorithm>
#include <atomic>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <limits>
#include <sstream>

#include "cube_scan_matcher/core/simd_path.h"
#include "simd_clones.h"
#include "reuse_memory.h"

namespace cube_scan_matcher {

void validate(const CubeGridSettings& s) {
  if (!(s.cube_edge > 0.0 && s.cube_edge <= 100.0)) {
    throw std::invalid_argument("cube_edge must be in (0, 100] m, got " +
                                std::to_string(s.cube_edge));
  }
  if (s.max_cubes < 1 || s.max_cubes > (std::uint64_t{1} << 31)) {
    throw std::invalid_argument("max_cubes must be in [1, 2^31], got " +
                                std::to_string(s.max_cubes));
  }
  if (s.max_byte_cubes > (std::uint64_t{1} << 28)) {
    throw std::invalid_argument("max_byte_cubes must be in [0, 2^28], got " +
                                std::to_string(s.max_byte_cubes));
  }
  if (!(s.origin_shift >= 0.0 && s.origin_shift < 1.0)) {
    throw std::invalid_argument("origin_shift must be in [0, 1), got " +
                                std::to_string(s.origin_shift));
  }
}

namespace {
GridAffine makeAffine(const Eigen::Matrix3f& r, const Eigen::Vector3f& t,
                      const Eigen::Vector3d& min, double edge) {
  const float inv_e = float(1.0 / edge);
  GridAffine g;
  for (int i = 0; i < 3; ++i) {
    for (int j = 0; j < 3; ++j) g.a[i][j] = r(i, j) * inv_e;
    // +0.5 turns floor() into round() of eq. (6).
    g.b[i] = float((double(t[i]) - min[i]) / edge + 0.5);
  }
  return g;
}
}  // namespace

GridAffine CubeGrid::affine(const Eigen::Matrix3f& rotation,
                            const Eigen::Vector3f& translation) const {
  return makeAffine(rotation, translation, min_, edge_);
}

// The hot loop. The body is written once, inlined into one function per instruction set
// (x86-64: AVX-512F, AVX2 and the baseline; elsewhere, e.g. aarch64 with NEON as its
// baseline, only the baseline: simd_clones.h) and picked through simd_path.h. `omp simd` (with
// -fopenmp-simd, no OpenMP runtime) makes GCC vectorise each copy at -O2. This file is built
// with -ffp-contract=off (CMakeLists.txt): no copy fuses a multiply and an add into an FMA
// (the AVX-512 one did, AVX-512F having FMA of its own), so every copy rounds the same
// multiplies and adds and the indices are identical on every path (test_cube_grid.cpp).
namespace {
inline __attribute__((always_inline)) void cubeIndicesBody(
    const GridAffine& g, const Eigen::Vector3f& dims, const float* x, const float* y,
    const float* z, std::size_t n, std::int32_t outside, std::int32_t* idx) {
  const float nx = dims.x(), ny = dims.y(), nz = dims.z();
  // Unsigned arithmetic: the index of a clamped outside point may wrap (it is discarded), an
  // inside index is < v <= 2^31 and fits an int32.
  const std::uint32_t sx = std::uint32_t(nx), sxy = sx * std::uint32_t(ny);
  const float a00 = g.a[0][0], a01 = g.a[0][1], a02 = g.a[0][2], b0 = g.b[0];
  const float a10 = g.a[1][0], a11 = g.a[1][1], a12 = g.a[1][2], b1 = g.b[1];
  const float a20 = g.a[2][0], a21 = g.a[2][1], a22 = g.a[2][2], b2 = g.b[2];
#pragma omp simd
  for (std::size_t i = 0; i < n; ++i) {
    const float px = x[i], py = y[i], pz = z[i];
    const float ax = a00 * px + a01 * py + a02 * pz + b0;
    const float ay = a10 * px + a11 * py + a12 * pz + b1;
    const float az = a20 * px + a21 * py + a22 * pz + b2;
    const bool inside = (ax >= 0.f) & (ax < nx) & (ay >= 0.f) & (ay < ny) & (az >= 0.f) & (az < nz);
    // Clamp before the conversion so that it is defined for every input, NaN included
    // (std::max(0.f, NaN) is 0: the comparison with NaN is false); a >= 0 there, so truncation
    // is floor. A NaN coordinate is never inside (the comparisons above are false).
    const std::uint32_t ix = std::uint32_t(std::int32_t(std::min(std::max(0.f, ax), nx)));
    const std::uint32_t iy = std::uint32_t(std::int32_t(std::min(std::max(0.f, ay), ny)));
    const std::uint32_t iz = std::uint32_t(std::int32_t(std::min(std::max(0.f, az), nz)));
    idx[i] = inside ? std::int32_t(ix + iy * sx + iz * sxy) : outside;
  }
}

// The same in two steps, for grids that share a rotation: u = A p once per block (the sums
// in the order of cubeIndicesBody, without b), then per grid a = s u + b. For s a power of two
// s u rounds like (s A) p term by term, so the indices are those of cubeIndicesBody with
// a = s A (barring subnormal products).
inline __attribute__((always_inline)) void rotateBody(const float (&a)[3][3], const float* x,
                                                      const float* y, const float* z,
                                                      std::size_t n, float* ux, float* uy,
                                                      float* uz) {
  const float a00 = a[0][0], a01 = a[0][1], a02 = a[0][2];
  const float a10 = a[1][0], a11 = a[1][1], a12 = a[1][2];
  const float a20 = a[2][0], a21 = a[2][1], a22 = a[2][2];
#pragma omp simd
  for (std::size_t i = 0; i < n; ++i) {
    const float px = x[i], py = y[i], pz = z[i];
    ux[i] = a00 * px + a01 * py + a02 * pz;
    uy[i] = a10 * px + a11 * py + a12 * pz;
    uz[i] = a20 * px + a21 * py + a22 * pz;
  }
}

inline __attribute__((always_inline)) void indicesFromRotatedBody(
    float s, const float (&b)[3], const Eigen::Vector3f& dims, const float* ux, const float* uy,
    const float* uz, std::size_t n, std::int32_t outside, std::int32_t* idx) {
  const float nx = dims.x(), ny = dims.y(), nz = dims.z();
  const std::uint32_t sx = std::uint32_t(nx), sxy = sx * std::uint32_t(ny);
  const float b0 = b[0], b1 = b[1], b2 = b[2];
#pragma omp simd
  for (std::size_t i = 0; i < n; ++i) {
    const float ax = s * ux[i] + b0, ay = s * uy[i] + b1, az = s * uz[i] + b2;
    // As in cubeIndicesBody: the in-grid test, then a clamp that defines the conversion.
    const bool inside = (ax >= 0.f) & (ax < nx) & (ay >= 0.f) & (ay < ny) & (az >= 0.f) & (az < nz);
    const std::uint32_t ix = std::uint32_t(std::int32_t(std::min(std::max(0.f, ax), nx)));
    const std::uint32_t iy = std::uint32_t(std::int32_t(std::min(std::max(0.f, ay), ny)));
    const std::uint32_t iz = std::uint32_t(std::int32_t(std::min(std::max(0.f, az), nz)));
    idx[i] = inside ? std::int32_t(ix + iy * sx + iz * sxy) : outside;
  }
}

CSM_SIMD_CLONES(cubeIndices,
                (const GridAffine& g, const Eigen::Vector3f& dims, const float* x,
                 const float* y, const float* z, std::size_t n, std::int32_t outside,
                 std::int32_t* idx),
                (g, dims, x, y, z, n, outside, idx))
CSM_SIMD_CLONES(rotate,
                (const float (&a)[3][3], const float* x, const float* y, const float* z,
                 std::size_t n, float* ux, float* uy, float* uz),
                (a, x, y, z, n, ux, uy, uz))
CSM_SIMD_CLONES(indicesFromRotated,
                (float s, const float (&b)[3], const Eigen::Vector3f& dims, const float* ux,
                 const float* uy, const float* uz, std::size_t n, std::int32_t outside,
                 std::int32_t* idx),
                (s, b, dims, ux, uy, uz, n, outside, idx))

/// Every path, fastest first.
constexpr SimdPath kAllPaths[] = {SimdPath::Avx512, SimdPath::Avx2, SimdPath::Portable};

SimdPath bestSupported() { return supportedSimdPaths().front(); }

// The path on first use: CSM_SIMD if it names a path this CPU runs, else the best.
SimdPath initialPath() {
  const SimdPath best = bestSupported();
  const char* env = std::getenv("CSM_SIMD");
  if (!env || !*env) return best;
  try {
    const std::optional<SimdPath> want = parseSimdPath(env);
    if (!want) return best;
    if (simdPathSupported(*want)) return *want;
    std::fprintf(stderr, "cube_scan_matcher: CSM_SIMD=%s: this CPU or build cannot run it; using %s\n",
                 env, simdPathName(best));
  } catch (const std::invalid_argument& e) {
    std::fprintf(stderr, "cube_scan_matcher: CSM_SIMD: %s; using %s\n", e.what(),
                 simdPathName(best));
  }
  return best;
}

/// The active path; its copy of a loop is picked once per block of points (CSM_PICK_CLONE).
std::atomic<SimdPath>& activePath() {
  static std::atomic<SimdPath> path(initialPath());
  return path;
}
}  // namespace

const char* simdPathName(SimdPath path) {
  switch (path) {
    case SimdPath::Avx512: return "avx512";
    case SimdPath::Avx2: return "avx2";
    case SimdPath::Portable: break;
  }
  return "portable";
}

std::optional<SimdPath> parseSimdPath(const std::string& name) {
  if (name == "auto") return std::nullopt;
  for (SimdPath p : kAllPaths) {
    if (name == simdPathName(p)) return p;
  }
  throw std::invalid_argument("unknown SIMD path '" + name +
                              "' (expected auto, avx512, avx2 or portable)");
}

bool simdPathSupported(SimdPath path) {
  if (path == SimdPath::Portable) return true;
#ifdef CSM_HAVE_X86_PATHS
  __builtin_cpu_init();
  if (path == SimdPath::Avx512) return __builtin_cpu_supports("avx512f");
  if (path == SimdPath::Avx2) return __builtin_cpu_supports("avx2");
#endif
  return false;
}

std::vector<SimdPath> supportedSimdPaths() {
  std::vector<SimdPath> out;
  for (SimdPath p : kAllPaths) {
    if (simdPathSupported(p)) out.push_back(p);
  }
  return out;
}

SimdPath activeSimdPath() { return activePath().load(std::memory_order_relaxed); }

void setSimdPath(std::optional<SimdPath> path) {
  const SimdPath p = path ? *path : bestSupported();
  if (!simdPathSupported(p)) {
    throw std::invalid_argument(std::string("SIMD path ") + simdPathName(p) +
                                " is not supported by this CPU or build");
  }
  activePath().store(p, std::memory_order_relaxed);
}

std::string simdReport() {
  std::string s = simdPathName(activeSimdPath());
  s += " (supported here:";
  for (SimdPath p : supportedSimdPaths()) s += std::string(" ") + simdPathName(p);
  return s + ")";
}

void computeCubeIndices(const GridAffine& g, const Eigen::Vector3f& dims, const float* x,
                        const float* y, const float* z, std::size_t n, std::int32_t outside,
                        std::int32_t* idx) {
  CSM_PICK_CLONE(cubeIndices, activeSimdPath())(g, dims, x, y, z, n, outside, idx);
}

void rotatePoints(const float (&a)[3][3], const float* x, const float* y, const float* z,
                  std::size_t n, float* ux, float* uy, float* uz) {
  CSM_PICK_CLONE(rotate, activeSimdPath())(a, x, y, z, n, ux, uy, uz);
}

void cubeIndicesFromRotated(float s, const float (&b)[3], const Eigen::Vector3f& dims,
                            const float* ux, const float* uy, const float* uz, std::size_t n,
                            std::int32_t outside, std::int32_t* idx) {
  CSM_PICK_CLONE(indicesFromRotated, activeSimdPath())(s, b, dims, ux, uy, uz, n, outside, idx);
}

CubeGrid CubeGrid::build(const PointArray& ref, const CubeGridSettings& settings) {
  CubeGrid g;
  g.rebuild(ref, settings);
  return g;
}

void CubeGrid::rebuild(const PointArray& ref, const CubeGridSettings& settings) {
  validate(settings);
  // Empty until it is complete: an error leaves no half-built grid. V is zeroed through L, in
  // O(l) and not O(v): the rest of it is zero already, and its memory (written before) serves
  // the new grid.
  for (const std::int32_t c : list_) bits_[std::size_t(c) >> 6] = 0;
  list_.clear();
  dims_.setZero();
  dims_f_.setZero();
  if (ref.empty()) {
    throw CubeGridError(CubeGridError::Code::EmptyReference,
                        "reference scan has no points after filtering");
  }
  const double edge = settings.cube_edge;
  Eigen::Vector3d lo = Eigen::Vector3d::Constant(std::numeric_limits<double>::infinity());
  Eigen::Vector3d hi = -lo;
  for (std::size_t i = 0; i < ref.size(); ++i) {
    const Eigen::Vector3d p(ref.x[i], ref.y[i], ref.z[i]);
    if (!p.allFinite()) {
      throw CubeGridError(CubeGridError::Code::NonFiniteReference,
                          "reference point " + std::to_string(i) + " is NaN or inf");
    }
    lo = lo.cwiseMin(p);
    hi = hi.cwiseMax(p);
  }
  lo.array() -= settings.origin_shift * edge;
  // Nx = round((xmax - xmin)/E) + 1 (eq. 4 plus the inclusive upper bound). Checked in double
  // before anything is allocated, so an absurd extent is an error and not a bad_alloc.
  const Eigen::Vector3d n = ((hi - lo) / edge).array().round() + 1.0;
  const double v = n.x() * n.y() * n.z();
  if (!(v <= double(settings.max_cubes))) {
    std::ostringstream os;
    os << "cube grid too large: reference extent " << (hi - lo).x() << " x " << (hi - lo).y()
       << " x " << (hi - lo).z() << " m at E = " << edge << " m needs " << v
       << " cubes, above max_cubes = " << settings.max_cubes
       << " (raise max_cubes or cube_edge, or lower max_range)";
    throw CubeGridError(CubeGridError::Code::TooManyCubes, os.str());
  }
  // The float kernel decides the index of every point, so the dims are taken from it too:
  // +1 cube of slack guarantees that float rounding of the max corner stays inside.
  const GridAffine id = makeAffine(Eigen::Matrix3f::Identity(), Eigen::Vector3f::Zero(), lo, edge);
  Eigen::Vector3i dims;
  for (int k = 0; k < 3; ++k) {
    const float top = float(hi[k]) * id.a[k][k] + id.b[k];
    dims[k] = std::max(int(n[k]), int(std::floor(top)) + 1);
  }
  if (double(dims.x()) * dims.y() * dims.z() > double(settings.max_cubes)) {
    throw CubeGridError(CubeGridError::Code::TooManyCubes,
                        "cube grid too large after rounding; raise max_cubes or cube_edge");
  }
  edge_ = edge;
  max_byte_cubes_ = settings.max_byte_cubes;
  min_ = lo;
  max_ = hi;
  dims_ = dims;
  dims_f_ = dims_.cast<float>();
  reserveForRebuild(bits_, (cubeCount() + 63) / 64);
  bits_.resize((cubeCount() + 63) / 64, 0);  // all zero: only growth is written
  // Indices a block at a time (no index array the size of the scan to allocate).
  constexpr std::size_t kBlock = 1024;
  std::int32_t idx[kBlock];
  for (std::size_t begin = 0; begin < ref.size(); begin += kBlock) {
    const std::size_t m = std::min(kBlock, ref.size() - begin);
    computeCubeIndices(id, dims_f_, ref.x.data() + begin, ref.y.data() + begin,
                       ref.z.data() + begin, m, -1, idx);
    for (std::size_t k = 0; k < m; ++k) {
      const std::int32_t i = idx[k];
      if (i < 0) continue;  // cannot happen for points inside their own box; kept for safety
      std::uint64_t& w = bits_[std::size_t(i) >> 6];
      const std::uint64_t bit = std::uint64_t{1} << (i & 63);
      if (!(w & bit)) {
        w |= bit;
        list_.push_back(i);
      }
    }
  }
}

std::int64_t CubeGrid::index(const Eigen::Vector3f& p) const {
  const GridAffine id = affine(Eigen::Matrix3f::Identity(), Eigen::Vector3f::Zero());
  std::int32_t out;
  computeCubeIndices(id, dims_f_, &p.x(), &p.y(), &p.z(), 1, -1, &out);
  return out;
}

}  // namespace cube_scan_matcher
