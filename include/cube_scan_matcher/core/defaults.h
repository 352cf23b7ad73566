// The package's default settings: one place, used by the tools, the nodelet and the docs.
#pragma once

#include "cube_scan_matcher/core/registration.h"

namespace cube_scan_matcher {

/// Default mode (beyond the paper, measured in BENCHMARK.md); RegistrationSettings::paper()
/// keeps the paper's fixed mode.
inline RegistrationSettings defaultSettings() {
  RegistrationSettings s = RegistrationSettings::paper(0.5);
  return s;
}

}  // namespace cube_scan_matcher
