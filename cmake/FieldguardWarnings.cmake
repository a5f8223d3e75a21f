# Warnings are errors on our own targets only (never on third-party headers, which come in as SYSTEM).
# Not -Wnull-dereference: GCC 12 reports it from Boost.Asio's scheduler after inlining, where system-header
# suppression does not reach, and it cannot be silenced per header.
# -Werror only where we choose the compiler (CI, the `dev` preset): a user's build with a newer compiler must not
# fail on a warning that compiler has learnt since.
option(FIELDGUARD_WERROR "Treat warnings as errors (CI and the dev preset turn it on)" OFF)
add_library(fieldguard_warnings INTERFACE)
target_compile_options(fieldguard_warnings INTERFACE
  -Wall -Wextra -Wpedantic -Wconversion -Wsign-conversion -Wshadow -Wnon-virtual-dtor
  -Wold-style-cast -Woverloaded-virtual -Wdouble-promotion -Wformat=2
  $<$<BOOL:${FIELDGUARD_WERROR}>:-Werror>)
# g++ 12 at -O3 (Release) reports -Wrestrict, -Wstringop-overflow and -Warray-bounds inside libstdc++'s
# char_traits::copy when a std::string is built with operator+ (GCC bugs 105329 and 105651, fixed in g++ 13):
# places of ours all over, none a real overflow. With -march=native on an AVX-512 CPU it adds the same kind of
# report as -Wstringop-overread inside std::copy's memmove when a byte vector is appended to another
# (tests/drivers/xsens_*_test.cpp: "reading 1 or more bytes from a region of size 0" of a range it cannot know
# to be empty). Off for exactly that compiler and build type; -O2 builds and clang keep the checks.
if(CMAKE_CXX_COMPILER_ID STREQUAL "GNU" AND CMAKE_CXX_COMPILER_VERSION VERSION_LESS 13)
  target_compile_options(fieldguard_warnings INTERFACE
    $<$<CONFIG:Release>:-Wno-restrict -Wno-stringop-overflow -Wno-stringop-overread -Wno-array-bounds>)
endif()
