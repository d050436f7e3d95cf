# RESOCT_BUILD_FUZZ: libFuzzer builds of the fuzz/ targets. Included before any library is
# defined, because coverage instrumentation and the sanitizers must cover resoct::core itself,
# not only the fuzz entry points. Clang only (libFuzzer ships with clang: Debian clang-14 and
# libclang-rt-14-dev). The replay executables in fuzz/ need none of this and build with any
# compiler whenever the tests are built.
option(RESOCT_BUILD_FUZZ "Build the libFuzzer targets in fuzz/ (clang; ASan + UBSan)" OFF)
set(RESOCT_FUZZ_SECONDS 60 CACHE STRING "Seconds each libFuzzer target runs in ctest label fuzz")
set(RESOCT_FUZZ_RUNS 0 CACHE STRING
    "Executions after which each libFuzzer target stops in ctest label fuzz (0: time only)")

if(RESOCT_BUILD_FUZZ)
  if(NOT CMAKE_CXX_COMPILER_ID STREQUAL "Clang")
    message(FATAL_ERROR "RESOCT_BUILD_FUZZ=ON needs clang (libFuzzer), e.g. "
                        "CC=clang CXX=clang++ cmake -DRESOCT_BUILD_FUZZ=ON ...; see scripts/fuzz.sh")
  endif()
  # fuzzer-no-link instruments every object for coverage; only the fuzz executables link the
  # libFuzzer driver (-fsanitize=fuzzer in fuzz/CMakeLists.txt). Recovery is off so that any
  # undefined behaviour is a crash libFuzzer reports and saves.
  add_compile_options(-fsanitize=address,undefined,fuzzer-no-link -fno-sanitize-recover=all
                      -fno-omit-frame-pointer -g)
  add_link_options(-fsanitize=address,undefined)
endif()
