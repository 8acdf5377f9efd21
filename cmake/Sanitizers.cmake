# The asan preset: AddressSanitizer + UndefinedBehaviorSanitizer on every target.
if(SPH_SANITIZE)
  add_compile_options(-fsanitize=address,undefined -fno-omit-frame-pointer -fno-sanitize-recover=undefined)
  add_link_options(-fsanitize=address,undefined)
endif()

# The fuzz targets (SPH_FUZZ, with SPH_SANITIZE, clang): the scene fuzzer's coverage feedback comes from the scene
# layer (core/scene: parser, validator, builder), so only those sources and the fuzz targets are instrumented for
# coverage (SPH_FUZZ_COVERAGE, applied in CMakeLists.txt and tests/fuzz); libFuzzer's callbacks in them are served
# by the sanitizer runtime in the ordinary executables. Instrumenting every target instead doubled the time of the
# sanitizer suite (the physics loops carried the comparison tracing).
if(SPH_FUZZ)
  if(NOT CMAKE_CXX_COMPILER_ID STREQUAL "Clang")
    message(FATAL_ERROR "SPH_FUZZ needs clang (libFuzzer): configure with the asan preset, which selects clang++")
  endif()
  set(SPH_FUZZ_COVERAGE -fsanitize=fuzzer-no-link)
endif()
