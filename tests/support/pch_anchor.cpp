// The translation unit that builds the test executables' precompiled header (cmake/Testing.cmake).
