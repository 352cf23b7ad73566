// The defaults of cfg/ScanMatcher.cfg (dynamic_reconfigure) must equal the C++ defaults
// (RegistrationSettings{} via NodeParams), so the cfg, the YAML, docs/parameters.md and the code
// agree.
#include <gtest/gtest.h>

#include <fstream>
#include <set>
#include <sstream>
#include <string>
#include <vector>

#include <boost/any.hpp>

#include "cube_scan_matcher/ros/params.h"
#include "cube_scan_matcher/ros/sweep_assembler_nodelet.h"
#include "expect_params.h"

using namespace cube_scan_matcher;

TEST(Params, ReconfigureDefaultsEqualTheCoreDefaults) {
  expectSameLiveParams(ScanMatcherConfig::__getDefault__(), toConfig(NodeParams{}));
}

TEST(Params, AnInvalidCombinationIsRefusedAndLeavesTheParamsUnchanged) {
  NodeParams p;
  ScanMatcherConfig c = toConfig(p);
  c.refine_edge_fraction = 1.5;  // outside (0, 1)
  EXPECT_THROW(applyConfig(c, p), ParamError);
  EXPECT_DOUBLE_EQ(p.matcher.registration.refine.edge_fraction, 0.5);
  c = toConfig(p);
  c.cube_edge = 0.3;
  applyConfig(c, p);
  EXPECT_DOUBLE_EQ(p.matcher.registration.grid.cube_edge, 0.3);
}

namespace {

std::string readFile(const std::string& path) {
  std::ifstream in(path);
  EXPECT_TRUE(in.good()) << path;
  std::stringstream ss;
  ss << in.rdbuf();
  return ss.str();
}

std::vector<std::string> lines(const std::string& text) {
  std::vector<std::string> out;
  std::stringstream ss(text);
  for (std::string line; std::getline(ss, line);) out.push_back(line);
  return out;
}

std::string trim(const std::string& s) {
  const std::size_t a = s.find_first_not_of(' '), b = s.find_last_not_of(' ');
  return a == std::string::npos ? "" : s.substr(a, b - a + 1);
}

/// A cfg parameter's value in `c` as text ("true"/"false") or a number.
struct CfgValue {
  bool is_bool = false, flag = false;
  double number = 0.0;
};
CfgValue valueOf(const ScanMatcherConfig::AbstractParamDescriptionConstPtr& d,
                 const ScanMatcherConfig& c) {
  boost::any v;
  d->getValue(c, v);
  CfgValue out;
  if (d->type == "bool") {
    out.is_bool = true;
    out.flag = boost::any_cast<bool>(v);
  } else if (d->type == "int") {
    out.number = boost::any_cast<int>(v);
  } else {
    out.number = boost::any_cast<double>(v);
  }
  return out;
}

/// Checks a documented default and range ("[lo, hi]", or "bool") against the cfg.
void expectDocumented(const ScanMatcherConfig::AbstractParamDescriptionConstPtr& d,
                      const std::string& where, const std::string& value,
                      const std::string& range) {
  const CfgValue dflt = valueOf(d, ScanMatcherConfig::__getDefault__());
  if (dflt.is_bool) {
    EXPECT_EQ(value, dflt.flag ? "true" : "false") << where << ": default of " << d->name;
    EXPECT_EQ(range, "bool") << where << ": range of " << d->name;
    return;
  }
  EXPECT_DOUBLE_EQ(std::stod(value), dflt.number) << where << ": default of " << d->name;
  const std::size_t comma = range.find(',');
  ASSERT_TRUE(range.size() > 2 && range.front() == '[' && range.back() == ']' &&
              comma != std::string::npos)
      << where << ": range of " << d->name << " is '" << range << "', expected [lo, hi]";
  EXPECT_DOUBLE_EQ(std::stod(range.substr(1, comma - 1)),
                   valueOf(d, ScanMatcherConfig::__getMin__()).number)
      << where << ": minimum of " << d->name;
  EXPECT_DOUBLE_EQ(std::stod(range.substr(comma + 1, range.size() - comma - 2)),
                   valueOf(d, ScanMatcherConfig::__getMax__()).number)
      << where << ": maximum of " << d->name;
}

}  // namespace

// cfg/ScanMatcher.cfg is the one source of the live parameters: config/scan_matcher.yaml and
// docs/parameters.md's parameter table list exactly its parameters, with its defaults and ranges.
TEST(Params, YamlAndReadmeListTheCfgParametersWithItsDefaultsAndRanges) {
  const auto yaml = lines(readFile(CSM_SOURCE_DIR "/config/scan_matcher.yaml"));
  const auto readme = lines(readFile(CSM_SOURCE_DIR "/docs/parameters.md"));
  std::set<std::string> names;
  for (const auto& d : ScanMatcherConfig::__getParamDescriptions__()) {
    names.insert(d->name);
    // YAML: "name: value   # text, [lo, hi]" (or ", bool").
    int found = 0;
    for (const std::string& l : yaml) {
      if (l.rfind(d->name + ":", 0) != 0) continue;
      ++found;
      const std::size_t colon = l.find(':'), hash = l.find('#'), open = l.rfind('[');
      ASSERT_NE(hash, std::string::npos) << l;
      const std::string range = l.size() >= 6 && l.compare(l.size() - 6, 6, ", bool") == 0
                                    ? "bool"
                                    : open == std::string::npos ? "" : trim(l.substr(open));
      expectDocumented(d, "config/scan_matcher.yaml",
                       trim(l.substr(colon + 1, hash - colon - 1)), range);
    }
    EXPECT_EQ(found, 1) << "config/scan_matcher.yaml lines for " << d->name;
    // docs/parameters.md: "| name (live) | unit | default | range | meaning |".
    found = 0;
    for (const std::string& l : readme) {
      if (l.rfind("| " + d->name + " (live) |", 0) != 0) continue;
      ++found;
      std::vector<std::string> cells;
      std::stringstream ss(l);
      for (std::string cell; std::getline(ss, cell, '|');) cells.push_back(trim(cell));
      ASSERT_GE(cells.size(), 6u) << l;
      expectDocumented(d, "docs/parameters.md", cells[3], cells[4]);
    }
    EXPECT_EQ(found, 1) << "docs/parameters.md rows for " << d->name;
  }
  // Nothing documented as live that the cfg does not have.
  for (const std::string& l : readme) {
    const std::size_t live = l.find(" (live) |");
    if (l.rfind("| ", 0) == 0 && live != std::string::npos) {
      EXPECT_EQ(names.count(l.substr(2, live - 2)), 1u)
          << "docs/parameters.md row not in the cfg: " << l;
    }
  }
}

namespace {

/// The top-level keys of a YAML file ("name: value  # ..." at the start of a line).
std::set<std::string> yamlKeys(const std::string& path) {
  std::set<std::string> keys;
  for (const std::string& l : lines(readFile(path))) {
    const std::size_t colon = l.find(':');
    if (l.empty() || l[0] == '#' || l[0] == ' ' || colon == std::string::npos) continue;
    keys.insert(l.substr(0, colon));
  }
  return keys;
}

}  // namespace

// The names the nodelets warn about are those they do not read: each list is exactly its
// shipped YAML's keys (the YAML lists every parameter), so a new parameter cannot be read
// without being known, nor known without being documented; plus num_worker_threads, which the
// stand-alone node's nodelet::Loader reads in the same namespace.
TEST(Params, KnownNamesAreTheYamlKeys) {
  const auto known = [](const std::vector<std::string>& names) {
    std::set<std::string> set(names.begin(), names.end());
    EXPECT_EQ(set.size(), names.size()) << "a name listed twice";
    EXPECT_EQ(set.erase("num_worker_threads"), 1u);
    return set;
  };
  EXPECT_EQ(known(knownParamNames()), yamlKeys(CSM_SOURCE_DIR "/config/scan_matcher.yaml"));
  EXPECT_EQ(known(knownAssemblerParamNames()),
            yamlKeys(CSM_SOURCE_DIR "/config/sweep_assembler.yaml"));
}

TEST(Params, UnknownNamesAreWarnedWithTheClosestKnownName) {
  const auto warnings = unknownParamWarnings(
      {"keyframe_distanse", "base_frame", "tilt_axis", "completely_unrelated_name"},
      knownParamNames());
  ASSERT_EQ(warnings.size(), 3u);
  EXPECT_NE(warnings[0].find("~keyframe_distanse is not a parameter"), std::string::npos);
  EXPECT_NE(warnings[0].find("did you mean ~keyframe_distance?"), std::string::npos);
  EXPECT_NE(warnings[1].find("~tilt_axis"), std::string::npos);  // the assembler's, not ours
  EXPECT_NE(warnings[2].find("docs/parameters.md"), std::string::npos) << warnings[2];
  EXPECT_TRUE(unknownParamWarnings({"cube_edge", "range_min"}, knownParamNames()).empty());
  EXPECT_EQ(editDistance("range_min", "range_max"), 2u);
  EXPECT_EQ(editDistance("", "abc"), 3u);
}
