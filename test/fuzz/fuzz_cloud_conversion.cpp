// libFuzzer harness: PointCloud2 -> points and point times on arbitrary messages (fields, offsets, types,
// counts, steps, sizes, endianness and data all from the input). CloudError is the documented
// answer to a malformed message.
#include <fuzzer/FuzzedDataProvider.h>

#include <cstddef>
#include <cstdint>
#include <string>

#include "cube_scan_matcher/ros/cloud_conversion.h"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  FuzzedDataProvider in(data, size);
  sensor_msgs::PointCloud2 msg;
  msg.height = in.ConsumeIntegralInRange<std::uint32_t>(0, 64);
  msg.width = in.ConsumeIntegralInRange<std::uint32_t>(0, 4096);
  if (in.ConsumeBool()) {  // sometimes absurd dimensions
    msg.height = in.ConsumeIntegral<std::uint32_t>();
    msg.width = in.ConsumeIntegral<std::uint32_t>();
  }
  msg.is_bigendian = in.ConsumeBool();
  msg.is_dense = in.ConsumeBool();
  msg.point_step = in.ConsumeIntegral<std::uint32_t>() % 128;
  msg.row_step = in.ConsumeBool() ? msg.point_step * msg.width : in.ConsumeIntegral<std::uint32_t>();
  static const char* kNames[] = {"x", "y", "z", "intensity", "ring", "X", "time", ""};
  const int fields = in.ConsumeIntegralInRange<int>(0, 8);
  for (int k = 0; k < fields; ++k) {
    sensor_msgs::PointField f;
    f.name = kNames[in.ConsumeIntegralInRange<int>(0, 7)];
    f.offset = in.ConsumeBool() ? in.ConsumeIntegral<std::uint32_t>()
                                : in.ConsumeIntegralInRange<std::uint32_t>(0, 64);
    f.datatype = in.ConsumeIntegralInRange<std::uint8_t>(0, 9);
    f.count = in.ConsumeIntegralInRange<std::uint32_t>(0, 3);
    msg.fields.push_back(f);
  }
  const std::string bytes = in.ConsumeRemainingBytesAsString();
  msg.data.assign(bytes.begin(), bytes.end());
  Eigen::Isometry3d T = Eigen::Isometry3d::Identity();
  try {
    cube_scan_matcher::fromCloud(msg, T);
  } catch (const cube_scan_matcher::CloudError&) {
  }
  try {
    cube_scan_matcher::readFloatField(msg, "time");  // the de-skew's per-point times
  } catch (const cube_scan_matcher::CloudError&) {
  }
  std::string problem;
  cube_scan_matcher::readIntensity(msg, problem);  // reports, never throws
  return 0;
}
