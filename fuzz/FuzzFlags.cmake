# Flags of the fuzz build (-DAUVRL_FUZZ=ON, clang, a build directory of its own: build-fuzz/).
# Every library of ours and the fuzz targets are compiled with libFuzzer's coverage
# instrumentation, AddressSanitizer and UndefinedBehaviorSanitizer; UB aborts (no recovery),
# so that a fuzzer reports it as a crash (fuzz/CMakeLists.txt exempts a few numeric units that
# no input reaches unchecked). Included by the top-level CMakeLists.txt before any
# target is defined.
if(NOT CMAKE_CXX_COMPILER_ID MATCHES "Clang")
  message(FATAL_ERROR "AUVRL_FUZZ needs clang (configure with -DCMAKE_CXX_COMPILER=clang++ "
                      "-DCMAKE_C_COMPILER=clang, in a build directory of its own)")
endif()
set(AUVRL_FUZZ_SANITIZERS -fsanitize=address,undefined -fno-sanitize-recover=undefined
                          -fno-omit-frame-pointer)
# -O1: fast enough to fuzz, and far cheaper to compile than -O2 with the sanitizers.
# -gline-tables-only: stack traces with files and lines (all a finding needs) at a fraction of
# -g's compile time and object size in the Eigen-heavy units.
add_compile_options(-O1 -gline-tables-only -fsanitize=fuzzer-no-link ${AUVRL_FUZZ_SANITIZERS})
add_link_options(${AUVRL_FUZZ_SANITIZERS})
# Our sources silence GCC-only warnings by pragma (GCC 12 false positives in Eigen's AVX-512
# code); clang does not know those groups. Everything else of -Wall -Wextra -Wpedantic -Werror
# applies to our code under clang as under GCC.
add_compile_options(-Wno-unknown-warning-option)
