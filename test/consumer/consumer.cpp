// A downstream package's use of cube_scan_matcher's exported headers and libraries: a
// registration chain from the ROS-free core, and the nodelet's header (which pulls in the
// generated message, service and dynamic_reconfigure headers).
#include <cstdio>

#include "cube_scan_matcher/core/online_matcher.h"
#include "cube_scan_matcher/ros/scan_matcher_nodelet.h"

int main() {
  cube_scan_matcher::OnlineMatcher matcher(cube_scan_matcher::OnlineMatcherSettings{});
  std::printf("csm_consumer: C++ %ld, an OnlineMatcher built\n", static_cast<long>(__cplusplus));
  return 0;
}
