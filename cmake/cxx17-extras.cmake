# Run by a consumer's find_package(catkin COMPONENTS cube_scan_matcher): this package's
# headers use C++17 (std::optional), while GCC 9 (ROS Noetic on Ubuntu 20.04) compiles C++14
# unless told otherwise, and catkin cannot export a compile feature. A consumer that has not
# chosen a standard gets C++17; one that chose an older one is told why its build will fail.
if(NOT DEFINED CMAKE_CXX_STANDARD)
  set(CMAKE_CXX_STANDARD 17)
  set(CMAKE_CXX_STANDARD_REQUIRED ON)
elseif(CMAKE_CXX_STANDARD LESS 17 OR CMAKE_CXX_STANDARD EQUAL 98)
  message(WARNING "cube_scan_matcher's headers need C++17, but CMAKE_CXX_STANDARD is "
                  "${CMAKE_CXX_STANDARD}: set it to 17 before find_package(catkin ...)")
endif()
