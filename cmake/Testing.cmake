# sph_add_test(NAME source...): one GoogleTest executable per component, discovered by ctest.
# The tests run in the build root, the folder the compiler ran in: tests find cases/ and tests/data/ through
# __FILE__, which is relative to that folder when ccache rewrites paths (CCACHE_BASEDIR).
#
# Build time (CI builds everything from scratch, twice): every test file parses the same heavy headers (the standard
# library, GoogleTest, Eigen, nlohmann-json and the solver's own), about 9 s of a test file's 20 s at -O3. They are
# precompiled once (sph_test_pch) and reused by every test executable. And test files are compiled at -O1: the solver
# they test is the library, which keeps the preset's flags; only the tests' own code (set-ups, brute-force twins) is
# less optimised. Together: 20 s -> 12 s a test file (gcc 12, measured on test_watchdog.cpp).
include(GoogleTest)
set(SPH_TEST_PCH_HEADERS <algorithm> <array> <cmath> <cstdint> <cstring> <filesystem> <functional> <limits> <map>
    <memory> <optional> <sstream> <string> <unordered_map> <vector> <gtest/gtest.h> <Eigen/Core> <Eigen/Geometry>
    <nlohmann/json.hpp> "${PROJECT_SOURCE_DIR}/core/simulation.hpp" "${PROJECT_SOURCE_DIR}/core/scene/scene.hpp"
    "${PROJECT_SOURCE_DIR}/core/refinement/refinement_stage.hpp")
set(SPH_TEST_OPT "$<$<OR:$<CONFIG:Release>,$<CONFIG:RelWithDebInfo>>:-O1>")
# GCC 12 at -O1 reports copying a disengaged std::optional<Eigen::Vector> (SolverSettings::gravity after reset()) as
# a read of uninitialised storage; its weaker flow analysis at -O1 is the known false positive of -Wmaybe-uninitialized.
if(CMAKE_CXX_COMPILER_ID STREQUAL "GNU")
  list(APPEND SPH_TEST_OPT -Wno-maybe-uninitialized)
endif()
add_library(sph_test_pch OBJECT "${PROJECT_SOURCE_DIR}/tests/support/pch_anchor.cpp")
target_link_libraries(sph_test_pch PRIVATE sph_core GTest::gtest)
target_include_directories(sph_test_pch PRIVATE ${PROJECT_SOURCE_DIR})
target_compile_options(sph_test_pch PRIVATE ${SPH_TEST_OPT})
target_precompile_headers(sph_test_pch PRIVATE ${SPH_TEST_PCH_HEADERS})

# `NO_PCH` for a test compiled with definitions of its own (the precompiled header must see the same ones).
function(sph_add_test name)
  cmake_parse_arguments(ARG "NO_PCH" "" "" ${ARGN})
  add_executable(${name} ${ARG_UNPARSED_ARGUMENTS})
  target_link_libraries(${name} PRIVATE sph_core sph_test_support GTest::gtest_main)
  target_compile_options(${name} PRIVATE ${SPH_TEST_OPT})
  if(NOT ARG_NO_PCH)
    target_precompile_headers(${name} REUSE_FROM sph_test_pch)
  endif()
  gtest_discover_tests(${name} DISCOVERY_TIMEOUT 60 WORKING_DIRECTORY ${CMAKE_BINARY_DIR} PROPERTIES TIMEOUT 600)
endfunction()
