# sph_add_test(NAME source...): one GoogleTest executable per component, discovered by ctest.
# The tests run in the build root, the folder the compiler ran in: tests find cases/ and tests/data/ through
# __FILE__, which is relative to that folder when ccache rewrites paths (CCACHE_BASEDIR).
include(GoogleTest)
function(sph_add_test name)
  add_executable(${name} ${ARGN})
  target_link_libraries(${name} PRIVATE sph_core sph_test_support GTest::gtest_main)
  gtest_discover_tests(${name} DISCOVERY_TIMEOUT 60 WORKING_DIRECTORY ${CMAKE_BINARY_DIR} PROPERTIES TIMEOUT 600)
endfunction()
