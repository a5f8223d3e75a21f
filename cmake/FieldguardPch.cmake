# Precompiled headers (FIELDGUARD_PCH, default ON): each multi-file target precompiles the standard library
# and third-party headers its sources parse over and over (GoogleTest, Boost.Asio, Eigen, yaml-cpp,
# spdlog), so that the three builds of tools/test parse them once per target instead of once per file.
# Never a project header: a PCH would then hide which project header a file really depends on, and the
# dependency-direction check reads the #include lines. Never PCL in a target with a file that defines
# PCL_NO_PRECOMPILE (src/app/pcd_writer.cpp): the PCH would be read before that #define.
# One PCH per target, built with that target's own flags (sanitizers, -fsanitize=fuzzer-no-link, defines),
# not shared between targets (REUSE_FROM): the targets' flags differ, and a mismatch is an error or a
# silently ignored PCH. Single-file targets get none: there the PCH is pure extra work.
# Switch it off (-DFIELDGUARD_PCH=OFF) to check include hygiene: every file must still include what it uses.
option(FIELDGUARD_PCH "Precompile the standard and third-party headers of each multi-file target" ON)

# Standard headers that most of our files include.
set(FIELDGUARD_PCH_STD
  <algorithm> <array> <chrono> <cmath> <cstddef> <cstdint> <cstdio> <cstring> <limits> <memory> <numbers>
  <optional> <stdexcept> <string> <string_view> <utility> <variant> <vector>)
# What the test files add to that.
set(FIELDGUARD_PCH_TEST_STD
  <filesystem> <fstream> <functional> <map> <random> <set> <sstream> <thread>)

# fieldguard_precompile(<target> [TEST] [<header>...]): the standard set plus the given third-party headers.
# TEST: a test target, whose files concatenate build paths (FIELDGUARD_TEST_DATA, ...) into strings. With
# a GCC 12 PCH, such a concatenation can raise a false -Warray-bounds inside std::string (seen in
# tests/tools/sim_score_pipeline_test.cpp; the same file with the same headers included as text compiles
# clean), and whether it does depends on the path's length, so on where the tree is cloned. Test targets
# therefore get a PCH from clang only; the libraries' code holds no build path, so what compiles here
# compiles on every clone.
function(fieldguard_precompile target)
  cmake_parse_arguments(ARG "TEST" "" "" ${ARGN})
  if(NOT FIELDGUARD_PCH OR (ARG_TEST AND NOT CMAKE_CXX_COMPILER_ID STREQUAL "Clang"))
    return()
  endif()
  target_precompile_headers(${target} PRIVATE ${FIELDGUARD_PCH_STD} ${ARG_UNPARSED_ARGUMENTS})
endfunction()
