# The asan preset: AddressSanitizer + UndefinedBehaviorSanitizer on every target.
if(SPH_SANITIZE)
  add_compile_options(-fsanitize=address,undefined -fno-omit-frame-pointer -fno-sanitize-recover=undefined)
  add_link_options(-fsanitize=address,undefined)
endif()

# The fuzz targets (SPH_FUZZ, with SPH_SANITIZE, clang): every target is instrumented for coverage
# (fuzzer-no-link, whose callbacks the sanitizer runtime provides for the ordinary executables); only the
# fuzz targets link libFuzzer's driver (tests/fuzz).
if(SPH_FUZZ)
  if(NOT CMAKE_CXX_COMPILER_ID STREQUAL "Clang")
    message(FATAL_ERROR "SPH_FUZZ needs clang (libFuzzer): configure with the asan preset, which selects clang++")
  endif()
  add_compile_options(-fsanitize=fuzzer-no-link)
endif()
