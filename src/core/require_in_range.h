// Private to the core: the range check the settings validators share.
#pragma once

#include <sstream>
#include <stdexcept>

namespace cube_scan_matcher {

/// Throws std::invalid_argument "<name> must be in [lo, hi], got <value>" (NaN fails too).
template <typename T>
void requireInRange(const char* name, T value, T lo, T hi) {
  if (!(value >= lo && value <= hi)) {
    std::ostringstream os;
    os << name << " must be in [" << lo << ", " << hi << "], got " << value;
    throw std::invalid_argument(os.str());
  }
}

}  // namespace cube_scan_matcher
