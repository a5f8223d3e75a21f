# Floating point as written: no a*b+c fused into one FMA where the CPU has it (g++ fuses by default in C++, clang
# within an expression). The same input then gives the same points, boxes and decisions on every build and CPU,
# which the replay comparison between the default and the x86-64-v3 build holds (tools/compare-builds).
add_compile_options(-ffp-contract=off)

# g++ 12 (Debian 12's compiler) breaks that promise in one place: with FMA in the target (-march=x86-64-v3,
# -march=native on any CPU since 2013) and the vectoriser on (-O2 and up), its SLP vectoriser turns a pair
# like {a*b - c*d, a*d + c*b} into one vfmaddsub instruction whatever -ffp-contract says. Our minimum-area
# rectangle's centre is such a pair, and its result then differs in the last bit from the same source built
# for the baseline CPU (ObstacleBoxReference's bit-for-bit checks caught it). The probe below compiles that
# pattern with this build's flags and looks for the fused instruction; only a compiler that emits it gets
# -fno-tree-slp-vectorize (straight-line vectorising off; loops still vectorise). Clang and g++ for the
# baseline CPU never emit it, so their builds are unchanged.
#
# What -ffp-contract cannot govern: Eigen's own packet math calls the FMA intrinsics when the target has FMA
# (Eigen/src/Core/util/ConfigureVectorization.h defines EIGEN_VECTORIZE_FMA from __FMA__), so the fixed-size
# matrix products of deskewing and scan lifting round once where the baseline build rounds twice. Those are
# doubles rounded to float afterwards; docs/development.md gives the measured effect on replay outputs.
if(CMAKE_CXX_COMPILER_ID STREQUAL "GNU")
  set(_probe_dir ${CMAKE_BINARY_DIR}/CMakeFiles/fp-contract-probe)
  file(MAKE_DIRECTORY ${_probe_dir})
  file(WRITE ${_probe_dir}/probe.cpp
       "struct P { double x, y; };\n"
       "P rotate(double cu, double cv, double ux, double uy) { return {cu * ux - cv * uy, cu * uy + cv * ux}; }\n")
  string(TOUPPER "${CMAKE_BUILD_TYPE}" _probe_type)
  separate_arguments(_probe_flags UNIX_COMMAND
                     "${CMAKE_CXX_FLAGS} ${CMAKE_CXX_FLAGS_${_probe_type}} -ffp-contract=off")
  execute_process(COMMAND ${CMAKE_CXX_COMPILER} ${_probe_flags} -S -o - ${_probe_dir}/probe.cpp
                  OUTPUT_VARIABLE _probe_asm ERROR_VARIABLE _probe_err RESULT_VARIABLE _probe_rc)
  if(NOT _probe_rc EQUAL 0)
    message(WARNING "fp-contract probe did not compile (${_probe_err}): builds as is")
  elseif(_probe_asm MATCHES "vfm(addsub|subadd)")
    message(STATUS "g++ fuses multiply-add pairs despite -ffp-contract=off with these flags: "
                   "-fno-tree-slp-vectorize (cmake/FieldguardFpContract.cmake)")
    add_compile_options(-fno-tree-slp-vectorize)
  endif()
endif()
