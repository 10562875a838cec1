# lidarloop_target_defaults(<target>): language standard, warnings and sanitizers for our targets.
function(lidarloop_target_defaults target)
    target_compile_features(${target} PUBLIC cxx_std_20)
    set_target_properties(${target} PROPERTIES CXX_EXTENSIONS OFF POSITION_INDEPENDENT_CODE ON)
    target_compile_options(${target} PRIVATE -Wall -Wextra -Wpedantic -Wshadow -Wconversion
        -Wno-sign-conversion $<$<BOOL:${LIDARLOOP_WERROR}>:-Werror>)
    # GCC 12 reports false -Wrestrict positives inside libstdc++'s std::string operator+ at -O3
    # (GCC bug 105329); the warning says nothing about our code there.
    if(CMAKE_CXX_COMPILER_ID STREQUAL "GNU" AND CMAKE_CXX_COMPILER_VERSION VERSION_LESS 13)
        target_compile_options(${target} PRIVATE -Wno-restrict)
    endif()
    if(LIDARLOOP_SANITIZE OR LIDARLOOP_BUILD_FUZZERS)
        target_compile_options(${target} PRIVATE -fsanitize=address,undefined
            -fno-sanitize-recover=all -fno-omit-frame-pointer)
        # GCC's manual warns that sanitizers raise the rate of false -Wmaybe-uninitialized
        # reports (seen here in std::variant copies at -O2); the normal build keeps the warning.
        if(CMAKE_CXX_COMPILER_ID STREQUAL "GNU")
            target_compile_options(${target} PRIVATE -Wno-maybe-uninitialized)
        endif()
        target_link_options(${target} PUBLIC -fsanitize=address,undefined)
    endif()
endfunction()

# lidarloop_fuzz_coverage(<target>): libFuzzer's coverage in the target (LIDARLOOP_BUILD_FUZZERS,
# clang): the fuzzers' copy of the readers (lidarloop_io_fuzz) and the harnesses only. The code
# they call is checked by the sanitizers but not coverage-guided: the tests keep sanitizer speed.
function(lidarloop_fuzz_coverage target)
    if(LIDARLOOP_BUILD_FUZZERS)
        target_compile_options(${target} PRIVATE -fsanitize=fuzzer-no-link)
    endif()
endfunction()

# lidarloop_add_library(<name> SOURCES ... PUBLIC_DEPS ... PRIVATE_DEPS ...): one folder, one
# target lidarloop_<name>, exported as lidarloop::<name>.
function(lidarloop_add_library name)
    cmake_parse_arguments(ARG "" "" "SOURCES;PUBLIC_DEPS;PRIVATE_DEPS" ${ARGN})
    set(target lidarloop_${name})
    add_library(${target} ${ARG_SOURCES})
    add_library(lidarloop::${name} ALIAS ${target})
    set_target_properties(${target} PROPERTIES EXPORT_NAME ${name} OUTPUT_NAME lidarloop_${name})
    target_include_directories(${target} PUBLIC
        $<BUILD_INTERFACE:${PROJECT_SOURCE_DIR}/cpp> $<INSTALL_INTERFACE:${CMAKE_INSTALL_INCLUDEDIR}>)
    target_link_libraries(${target} PUBLIC ${ARG_PUBLIC_DEPS} PRIVATE ${ARG_PRIVATE_DEPS})
    lidarloop_target_defaults(${target})
    if(LIDARLOOP_UNITY_LIBRARIES)
        lidarloop_unity_build(${target})
        # GCC takes a file included by the batch for a header, and warns of every member whose
        # type is in the .cpp's anonymous namespace; file by file it says nothing.
        if(CMAKE_CXX_COMPILER_ID STREQUAL "GNU")
            target_compile_options(${target} PRIVATE -Wno-subobject-linkage)
        endif()
    endif()
    install(TARGETS ${target} EXPORT lidarloopTargets
        ARCHIVE DESTINATION ${CMAKE_INSTALL_LIBDIR} LIBRARY DESTINATION ${CMAKE_INSTALL_LIBDIR})
    # Public headers only: detail/ holds the module's internal helpers.
    install(DIRECTORY ${CMAKE_CURRENT_SOURCE_DIR}/ DESTINATION ${CMAKE_INSTALL_INCLUDEDIR}/lidarloop/${name}
        FILES_MATCHING PATTERN "*.hpp" PATTERN "detail" EXCLUDE)
endfunction()

# lidarloop_unity_build(<target>): compile the target's files in batches of 8 (LIDARLOOP_UNITY_BUILD);
# 8 keeps both cores busy and a batch's recompile short. Files with their own compile options or
# definitions are left out by CMake. The libraries stay file by file, what ships, unless
# LIDARLOOP_UNITY_LIBRARIES (the test builds).
function(lidarloop_unity_build target)
    if(LIDARLOOP_UNITY_BUILD)
        set_target_properties(${target} PROPERTIES UNITY_BUILD ON UNITY_BUILD_BATCH_SIZE 8)
    endif()
endfunction()

# lidarloop_test_optimization(<target>): a test program's own code optimised as
# LIDARLOOP_TEST_OPTIMIZATION says (given after the build type's flags, so it wins).
function(lidarloop_test_optimization target)
    if(LIDARLOOP_TEST_OPTIMIZATION)
        target_compile_options(${target} PRIVATE ${LIDARLOOP_TEST_OPTIMIZATION})
    endif()
endfunction()
