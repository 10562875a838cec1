# FindRosbagStorage: Debian's ROS 1 bag library (librosbag-storage-dev) as the imported target
# RosbagStorage::RosbagStorage, for lidarloop's bag reader (cpp/lidarloop/io/rosbag.cpp).
#
# Neither file Debian ships for it works outside a ROS workspace: rosbag_storage.pc requires a
# pluginlib.pc that does not exist, and rosbag_storageConfig.cmake (catkin) finds the ROS 2
# pluginlib, whose ament hooks run a Python module Debian does not install. So the headers and
# libraries are found here. rosbag/bag.h includes <pluginlib/class_loader.hpp>, which Debian
# installs one folder deeper (/usr/include/pluginlib/pluginlib), as it does the headers that one
# includes (class_loader, rcpputils, rcutils, ament_index_cpp); their folders are added too.
include(FindPackageHandleStandardArgs)

find_path(RosbagStorage_INCLUDE_DIR rosbag/bag.h)
set(_rosbag_nested_headers
    pluginlib:pluginlib/class_loader.hpp
    class_loader:class_loader/class_loader.hpp
    rcpputils:rcpputils/shared_library.hpp
    rcutils:rcutils/shared_library.h
    ament_index_cpp:ament_index_cpp/get_package_prefix.hpp)
set(_rosbag_include_vars RosbagStorage_INCLUDE_DIR)
foreach(_entry IN LISTS _rosbag_nested_headers)
    string(REPLACE ":" ";" _pair "${_entry}")
    list(GET _pair 0 _folder)
    list(GET _pair 1 _header)
    find_path(RosbagStorage_${_folder}_INCLUDE_DIR ${_header} PATH_SUFFIXES ${_folder})
    list(APPEND _rosbag_include_vars RosbagStorage_${_folder}_INCLUDE_DIR)
endforeach()
find_library(RosbagStorage_LIBRARY rosbag_storage)
find_library(RosbagStorage_rostime_LIBRARY rostime)
find_library(RosbagStorage_serialization_LIBRARY roscpp_serialization)
find_library(RosbagStorage_cpp_common_LIBRARY cpp_common)  # ros::Header of the record headers
find_library(RosbagStorage_console_bridge_LIBRARY console_bridge)  # ROS's log, silenced
find_package(Boost QUIET)  # rosbag's headers include Boost's

find_package_handle_standard_args(RosbagStorage
    REQUIRED_VARS RosbagStorage_LIBRARY RosbagStorage_rostime_LIBRARY
        RosbagStorage_serialization_LIBRARY RosbagStorage_cpp_common_LIBRARY
        RosbagStorage_console_bridge_LIBRARY ${_rosbag_include_vars}
        Boost_INCLUDE_DIRS)

if(RosbagStorage_FOUND AND NOT TARGET RosbagStorage::RosbagStorage)
    set(_rosbag_include_dirs)
    foreach(_var IN LISTS _rosbag_include_vars)
        list(APPEND _rosbag_include_dirs ${${_var}})
    endforeach()
    add_library(RosbagStorage::RosbagStorage UNKNOWN IMPORTED)
    # Imported include folders are SYSTEM: ROS's headers' warnings do not fail a -Werror build.
    set_target_properties(RosbagStorage::RosbagStorage PROPERTIES
        IMPORTED_LOCATION ${RosbagStorage_LIBRARY}
        INTERFACE_INCLUDE_DIRECTORIES "${_rosbag_include_dirs};${Boost_INCLUDE_DIRS}"
        INTERFACE_LINK_LIBRARIES
            "${RosbagStorage_rostime_LIBRARY};${RosbagStorage_serialization_LIBRARY};${RosbagStorage_cpp_common_LIBRARY};${RosbagStorage_console_bridge_LIBRARY}")
endif()
mark_as_advanced(${_rosbag_include_vars} RosbagStorage_LIBRARY RosbagStorage_rostime_LIBRARY
    RosbagStorage_serialization_LIBRARY RosbagStorage_cpp_common_LIBRARY
    RosbagStorage_console_bridge_LIBRARY)
unset(_rosbag_nested_headers)
unset(_rosbag_include_vars)
