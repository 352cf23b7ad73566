// The command line of the tools, read one option at a time: each option takes its values from
// the words after it, and every error names the option (std::invalid_argument, which each
// tool's main prints with its usage). One reader, so that every tool treats a missing value, a
// number that is not one and an unknown option alike.
#pragma once

#include <cmath>
#include <cstddef>
#include <functional>
#include <limits>
#include <stdexcept>
#include <string>
#include <type_traits>
#include <vector>

#include "cube_scan_matcher/io/dataset.h"
#include "settings_cli.h"

namespace cube_scan_matcher::tools {

class ArgReader {
 public:
  ArgReader(int argc, char** argv) : args_(argv + 1, argv + argc) {}

  /// True while words remain to be read.
  bool more() const { return i_ < args_.size(); }

  /// -h or --help: consumed, true.
  bool help() {
    if (!is("-h") && !is("--help")) return false;
    ++i_;
    return true;
  }

  /// `name` alone (no value): sets `on`.
  bool flag(const char* name, bool& on) {
    if (!is(name)) return false;
    on = true;
    ++i_;
    return true;
  }

  /// `name VALUE` into `out` (see convert()).
  template <class T>
  bool option(const char* name, T& out) {
    if (!is(name)) return false;
    out = convert<T>(name, value(1));
    i_ += 2;
    return true;
  }

  /// `name VALUE`, handed to `take` (which parses it and may throw std::invalid_argument).
  bool optionWith(const char* name, const std::function<void(const std::string&)>& take) {
    if (!is(name)) return false;
    take(value(1));
    i_ += 2;
    return true;
  }

  /// `name V1 ... Vn`, the n values handed to `take`.
  bool optionWith(const char* name, std::size_t n,
                  const std::function<void(const std::vector<std::string>&)>& take) {
    if (!is(name)) return false;
    std::vector<std::string> values;
    for (std::size_t k = 1; k <= n; ++k) values.push_back(value(k));
    take(values);
    i_ += n + 1;
    return true;
  }

  /// One of the algorithm options every tool that runs the cube method shares (settings_cli.h).
  bool algorithm(RegistrationSettings& settings, RangeFilterSettings& filter) {
    return more() && parseAlgorithmOption(args_, i_, settings, filter);
  }

  /// A word that is not an option (a file, a folder): returned and consumed.
  std::string positional() {
    if (args_[i_].rfind("--", 0) == 0) unknown();
    return args_[i_++];
  }

  /// Throws for the current word: no option of the tool has its name.
  [[noreturn]] void unknown() const { throw std::invalid_argument("unknown option: " + args_[i_]); }

  /// `text` as T: a string as given; a bool from a number (0 is false); an integer type from a
  /// whole number within its range; a floating-point type from any number strtod reads. An
  /// error names `what`.
  template <class T>
  static T convert(const std::string& what, const std::string& text) {
    if constexpr (std::is_same_v<T, std::string>) {
      return text;
    } else if constexpr (std::is_same_v<T, bool>) {
      return io::parseNumber(what, text) != 0.0;
    } else if constexpr (std::is_integral_v<T>) {
      const double v = io::parseNumber(what, text);
      if (v != std::floor(v) || v < double(std::numeric_limits<T>::lowest()) ||
          v > double(std::numeric_limits<T>::max()))
        throw std::invalid_argument(what + ": expected a whole number in [" +
                                    std::to_string(std::numeric_limits<T>::lowest()) + ", " +
                                    std::to_string(std::numeric_limits<T>::max()) + "], got '" +
                                    text + "'");
      return T(v);
    } else {
      static_assert(std::is_floating_point_v<T>, "option(): string, bool, integer or floating");
      return T(io::parseNumber(what, text));
    }
  }

 private:
  bool is(const char* name) const { return more() && args_[i_] == name; }
  const std::string& value(std::size_t k) const {
    if (i_ + k >= args_.size()) throw std::invalid_argument(args_[i_] + ": missing value");
    return args_[i_ + k];
  }

  std::vector<std::string> args_;
  std::size_t i_ = 0;
};

}  // namespace cube_scan_matcher::tools
