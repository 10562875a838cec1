# The Open3D registration oracle, lidarloop::open3d_oracle: Open3D's global registration (FPFH +
# RANSAC, then ICP) behind a header in Eigen and lidarloop::core types, for tests and benchmarks
# (sources in tests/cpp/registration/). Defined when LIDARLOOP_WITH_OPEN3D allows it and Open3D
# is found; users check if(TARGET lidarloop::open3d_oracle). No library of lidarloop links it, and
# it is neither installed nor exported.
if(NOT LIDARLOOP_WITH_OPEN3D MATCHES "^(AUTO|ON|OFF)$")
    message(FATAL_ERROR "LIDARLOOP_WITH_OPEN3D is '${LIDARLOOP_WITH_OPEN3D}': use AUTO, ON or OFF")
endif()
if(LIDARLOOP_WITH_OPEN3D STREQUAL "OFF")
    message(STATUS "Open3D registration oracle: off (LIDARLOOP_WITH_OPEN3D=OFF)")
    return()
endif()
set(open3d_required)
if(LIDARLOOP_WITH_OPEN3D STREQUAL "ON")
    set(open3d_required REQUIRED)
endif()
# No version in the call: Debian's Open3DConfigVersion.cmake (ExactVersion) accepts only "0.16.1"
# exactly, so find_package(Open3D 0.16) would reject the installed 0.16.1. Checked below instead.
find_package(Open3D ${open3d_required} QUIET)
# The oracle pins Open3D's OpenMP team to one thread during RANSAC (see open3d_oracle.cpp).
find_package(OpenMP ${open3d_required} QUIET COMPONENTS CXX)
unset(open3d_required)
if(NOT Open3D_FOUND OR NOT OpenMP_CXX_FOUND)
    message(STATUS "Open3D registration oracle: off (Open3D or OpenMP not found)")
    return()
endif()
if(Open3D_VERSION VERSION_LESS 0.16)
    message(FATAL_ERROR "Open3D ${Open3D_VERSION} at ${Open3D_CONFIG}: the oracle needs 0.16 or "
        "later (utility::random::Seed); set LIDARLOOP_WITH_OPEN3D=OFF to build without it")
endif()
message(STATUS "Open3D registration oracle: on (Open3D ${Open3D_VERSION})")

add_library(lidarloop_open3d_oracle STATIC EXCLUDE_FROM_ALL
    ${PROJECT_SOURCE_DIR}/tests/cpp/registration/open3d_oracle.cpp)
add_library(lidarloop::open3d_oracle ALIAS lidarloop_open3d_oracle)
target_include_directories(lidarloop_open3d_oracle PUBLIC ${PROJECT_SOURCE_DIR}/tests/cpp)
# EXCLUDE_FROM_ALL: built only for a test or benchmark that links it.
# Open3D stays PRIVATE: the oracle's header speaks Eigen and lidarloop::core only. Its headers
# come from an imported target, hence SYSTEM: their warnings do not fail our -Werror build.
target_link_libraries(lidarloop_open3d_oracle PUBLIC lidarloop::core
    PRIVATE Open3D::Open3D OpenMP::OpenMP_CXX)
lidarloop_target_defaults(lidarloop_open3d_oracle)
