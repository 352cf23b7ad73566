// Command-line options shared by the tools that run the cube method (one parser, one help text).
#pragma once

#include <string>
#include <utility>
#include <vector>

#include "cube_scan_matcher/core/filters.h"
#include "cube_scan_matcher/core/registration.h"
#include "cube_scan_matcher/io/dataset.h"

namespace cube_scan_matcher::tools {

/// Help lines for the algorithm options (unit and default of each).
std::string algorithmOptionsHelp();

/// If args[i] is an algorithm option, consumes it (and its values), updates `settings` or
/// `filter`, advances i past it and returns true. Throws std::invalid_argument on a bad value.
bool parseAlgorithmOption(const std::vector<std::string>& args, std::size_t& i,
                          RegistrationSettings& settings, RangeFilterSettings& filter);

/// One header line for benchmark output: the CPU model (from /proc/cpuinfo where it exists)
/// and the SIMD path the per-point loop runs on, so that every quoted time says which ran.
std::string machineReport();

/// "a,b,,c" -> {"a", "b", "c"} (empty items dropped).
std::vector<std::string> splitList(const std::string& s);

/// "a:b" -> {"a", "b"} at the first colon; throws std::invalid_argument naming `option` and
/// the expected `form` (e.g. "MODE:N") when there is none.
std::pair<std::string, std::string> splitPair(const std::string& option, const std::string& value,
                                              const std::string& form);

}  // namespace cube_scan_matcher::tools
