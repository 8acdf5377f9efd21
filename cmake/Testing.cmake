# sph_add_test(NAME source...): one GoogleTest executable per component, discovered by ctest.
include(GoogleTest)
function(sph_add_test name)
  add_executable(${name} ${ARGN})
  target_link_libraries(${name} PRIVATE sph_core sph_test_support GTest::gtest_main)
  gtest_discover_tests(${name} DISCOVERY_TIMEOUT 60 PROPERTIES TIMEOUT 600)
endfunction()
