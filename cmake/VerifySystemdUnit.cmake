# CTest systemd_unit: installs the build into a staging root (DESTDIR) exactly as `cmake --install` would
# on the vehicle computer, then has systemd check the INSTALLED unit there:
#   systemd-analyze verify --root=STAGE  (syntax, ExecStart binary present and executable, dependencies)
#   systemd-analyze security --offline   (exposure score; printed, and held to HARDENING_MAX)
#   systemd-sysusers --dry-run           (the dedicated user's sysusers.d entry parses)
# Any warning counts as a failure: verify exits 0 on unknown keys, so its output must be empty.
# The staging root gets a copy of the host's own systemd units (sysinit.target and friends), as an
# installed system has them. A self-check feeds verify a unit with an unknown key and expects a complaint,
# so this test cannot pass by systemd-analyze silently checking nothing.
# Usage: cmake -DBUILD_DIR=... -DSTAGE=... [-DHARDENING_MAX=2.0] -P VerifySystemdUnit.cmake
cmake_minimum_required(VERSION 3.25)
if(NOT DEFINED HARDENING_MAX)
  set(HARDENING_MAX 2.0)
endif()
find_program(ANALYZE systemd-analyze REQUIRED)

file(REMOVE_RECURSE ${STAGE})
execute_process(COMMAND ${CMAKE_COMMAND} -E env DESTDIR=${STAGE} ${CMAKE_COMMAND} --install ${BUILD_DIR}
                RESULT_VARIABLE rc OUTPUT_VARIABLE out ERROR_VARIABLE out)
if(NOT rc EQUAL 0)
  message(FATAL_ERROR "cmake --install failed:\n${out}")
endif()

file(GLOB_RECURSE units ${STAGE}/*/fieldguard.service)
list(LENGTH units n)
if(NOT n EQUAL 1)
  message(FATAL_ERROR "expected one installed fieldguard.service under ${STAGE}, found: ${units}")
endif()
file(READ ${units} unit_text)
message(STATUS "installed unit: ${units}")

# Everything the unit refers to must have been installed with it.
string(REGEX MATCH "ExecStart=([^ \n]+) run --config ([^ \n]+)" _ "${unit_text}")
set(exec ${CMAKE_MATCH_1})
set(config ${CMAKE_MATCH_2})
foreach(f ${exec} ${config})
  if(NOT EXISTS ${STAGE}${f})
    message(FATAL_ERROR "the unit names ${f}, which the install did not put in place")
  endif()
endforeach()
file(GLOB_RECURSE sysusers ${STAGE}/fieldguard.conf)
list(FILTER sysusers INCLUDE REGEX "/sysusers\\.d/fieldguard\\.conf$")
file(GLOB_RECURSE sysctl ${STAGE}/60-fieldguard.conf)
list(FILTER sysctl INCLUDE REGEX "/sysctl\\.d/60-fieldguard\\.conf$")
if(NOT sysusers OR NOT sysctl)
  message(FATAL_ERROR "sysusers.d or sysctl.d file missing from the install: '${sysusers}' '${sysctl}'")
endif()

# The host's systemd units, so that dependencies (sysinit.target, network-online.target) resolve.
file(MAKE_DIRECTORY ${STAGE}/lib/systemd)
# Likewise /bin/kill, which ExecReload uses and every Debian system has.
file(MAKE_DIRECTORY ${STAGE}/bin)
execute_process(COMMAND cp -a /lib/systemd/system ${STAGE}/lib/systemd/ RESULT_VARIABLE rc1)
execute_process(COMMAND cp -L /bin/kill ${STAGE}/bin/kill RESULT_VARIABLE rc2)
if(NOT rc1 EQUAL 0 OR NOT rc2 EQUAL 0)
  message(FATAL_ERROR "could not copy the host's systemd units and /bin/kill into the staging root")
endif()

function(verify root unit result)
  execute_process(COMMAND ${ANALYZE} verify --root=${root} ${unit}
                  RESULT_VARIABLE rc OUTPUT_VARIABLE out ERROR_VARIABLE out)
  string(STRIP "${out}" out)
  if(rc EQUAL 0 AND out STREQUAL "")
    set(${result} "" PARENT_SCOPE)
  else()
    set(${result} "exit ${rc}: ${out}" PARENT_SCOPE)
  endif()
endfunction()

# Self-check first: an unknown key must be reported.
get_filename_component(unit_dir ${units} DIRECTORY)
file(WRITE ${unit_dir}/fieldguard-selfcheck.service "${unit_text}\n[Service]\nNoSuchKey=1\n")
verify(${STAGE} fieldguard-selfcheck.service complaint)
file(REMOVE ${unit_dir}/fieldguard-selfcheck.service)
if(NOT complaint MATCHES "NoSuchKey")
  message(FATAL_ERROR "systemd-analyze verify did not report an unknown key (${complaint}): the check checks nothing")
endif()

verify(${STAGE} fieldguard.service problems)
if(NOT problems STREQUAL "")
  message(FATAL_ERROR "systemd-analyze verify on the installed unit: ${problems}")
endif()
message(STATUS "systemd-analyze verify: clean")

execute_process(COMMAND ${ANALYZE} security --offline=true --root=${STAGE} --no-pager fieldguard.service
                RESULT_VARIABLE rc OUTPUT_VARIABLE out ERROR_VARIABLE err)
string(REGEX MATCH "Overall exposure level for fieldguard.service: ([0-9.]+)" _ "${out}")
if(NOT CMAKE_MATCH_1)
  message(FATAL_ERROR "systemd-analyze security printed no exposure level:\n${out}\n${err}")
endif()
message(STATUS "systemd-analyze security: exposure ${CMAKE_MATCH_1} (at most ${HARDENING_MAX} allowed)")
if(CMAKE_MATCH_1 GREATER HARDENING_MAX)
  message(FATAL_ERROR "exposure ${CMAKE_MATCH_1} above ${HARDENING_MAX}:\n${out}")
endif()

find_program(SYSUSERS systemd-sysusers)
if(SYSUSERS)
  execute_process(COMMAND ${SYSUSERS} --root=${STAGE} --dry-run ${sysusers}
                  RESULT_VARIABLE rc OUTPUT_VARIABLE out ERROR_VARIABLE out)
  if(NOT rc EQUAL 0 OR out MATCHES "[Ii]nvalid|[Ff]ailed|[Ss]yntax")
    message(FATAL_ERROR "systemd-sysusers rejects ${sysusers}:\n${out}")
  endif()
  string(REPLACE "\n" "; " out "${out}")
  message(STATUS "systemd-sysusers --dry-run: ${out}")
endif()
