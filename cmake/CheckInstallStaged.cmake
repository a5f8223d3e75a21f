# CTest install_staged: `cmake --install BUILD --prefix STAGE/prefix` and `DESTDIR=STAGE/destdir cmake --install
# BUILD` each put every file under their stage and nothing anywhere else (every destination is relative to the
# prefix), and the tree holds what a vehicle computer needs: the binary, the configs, the DBC, the unit, the
# sysusers and sysctl files.
# Usage: cmake -DBUILD_DIR=... -DSTAGE=... -P CheckInstallStaged.cmake
cmake_minimum_required(VERSION 3.25)
file(REMOVE_RECURSE ${STAGE})

# `root`: where every file must be; `destdir`: what the manifest's paths are relative to on disk ("" for --prefix,
# whose manifest lists the real paths; the stage for DESTDIR, whose manifest lists the paths without it).
function(install_into label root destdir)
  execute_process(COMMAND ${ARGN} RESULT_VARIABLE rc OUTPUT_VARIABLE out ERROR_VARIABLE out)
  if(NOT rc EQUAL 0)
    message(FATAL_ERROR "${label}: cmake --install failed:\n${out}")
  endif()
  file(STRINGS ${BUILD_DIR}/install_manifest.txt installed)
  list(LENGTH installed n)
  if(n LESS 7)
    message(FATAL_ERROR "${label}: only ${n} files installed:\n${installed}")
  endif()
  foreach(f IN LISTS installed)
    set(f "${destdir}${f}")
    string(FIND "${f}" "${root}/" at)
    if(NOT at EQUAL 0)
      message(FATAL_ERROR "${label}: ${f} was installed outside ${root}")
    endif()
    if(NOT EXISTS "${f}")
      message(FATAL_ERROR "${label}: ${f} is in the manifest but not on disk")
    endif()
  endforeach()
  foreach(want bin/fieldguard /fieldguard/fieldguard.yaml /fieldguard/published.yaml /fieldguard/fieldguard.dbc
          /fieldguard.service sysusers.d/fieldguard.conf sysctl.d/60-fieldguard.conf)
    string(FIND "${installed}" "${want}" at)
    if(at EQUAL -1)
      message(FATAL_ERROR "${label}: nothing installed as ...${want}:\n${installed}")
    endif()
  endforeach()
  # Nothing but what the manifest lists is in the stage (the manifest is the whole install).
  file(GLOB_RECURSE on_disk LIST_DIRECTORIES false ${root}/*)
  list(LENGTH on_disk m)
  if(NOT m EQUAL n)
    message(FATAL_ERROR "${label}: ${m} files under ${root}, ${n} in the manifest")
  endif()
  message(STATUS "${label}: ${n} files, all under ${root}")
endfunction()

install_into("--prefix" ${STAGE}/prefix "" ${CMAKE_COMMAND} --install ${BUILD_DIR} --prefix ${STAGE}/prefix)
install_into("DESTDIR" ${STAGE}/destdir ${STAGE}/destdir ${CMAKE_COMMAND} -E env DESTDIR=${STAGE}/destdir
             ${CMAKE_COMMAND} --install ${BUILD_DIR})
