// Which vector instruction set the per-point loop (computeCubeIndices, eqs. 5-6) runs on.
//
// The loop is compiled several times: for AVX-512 and AVX2 on x86-64, and once for the
// build's baseline ("portable": SSE2 on x86-64, NEON on aarch64). The fastest path this CPU
// supports is taken unless the environment variable CSM_SIMD (auto|avx512|avx2|portable) or
// setSimdPath() says otherwise, so every path can be measured on one machine. The choice is
// process-wide (all nodelets of a manager share it). Every path computes the same floats
// (none fuses multiply-adds: see cube_grid.cpp), so results do not depend on it.
#pragma once

#include <optional>
#include <string>
#include <vector>

namespace cube_scan_matcher {

enum class SimdPath { Portable, Avx2, Avx512 };

/// "portable", "avx2", "avx512".
const char* simdPathName(SimdPath path);
/// Parses a name of simdPathName(); "auto" gives nullopt (the best supported path).
/// Throws std::invalid_argument naming the accepted values for anything else.
std::optional<SimdPath> parseSimdPath(const std::string& name);
/// Whether this build has the path and this CPU can run it.
bool simdPathSupported(SimdPath path);
/// The supported paths, fastest first.
std::vector<SimdPath> supportedSimdPaths();
/// The path the per-point loop takes now. On first use it reads CSM_SIMD; a value that is
/// not a path name, or names a path this CPU cannot run, is reported on stderr and the best
/// supported path is taken (a typo in the environment must not stop a robot's manager).
SimdPath activeSimdPath();
/// Forces the path (nullopt = the best supported). Throws std::invalid_argument if this
/// CPU or build cannot run it. Not meant to be called while registrations run.
void setSimdPath(std::optional<SimdPath> path);
/// One line for benchmark headers: the active path and the supported ones, e.g.
/// "avx512 (supported here: avx512 avx2 portable)".
std::string simdReport();

}  // namespace cube_scan_matcher
