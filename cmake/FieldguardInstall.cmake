# What `cmake --install` puts where. For the Debian layout configure with -DCMAKE_INSTALL_PREFIX=/usr
# -DCMAKE_INSTALL_SYSCONFDIR=/etc (as debhelper does; the package installs with DESTDIR):
#   /usr/bin/fieldguard                      the daemon and its commands
#   /etc/fieldguard/*.yaml                   configuration
#   /usr/share/fieldguard/fieldguard.dbc     the CAN database for the steering controller's integrator
#   /usr/lib/systemd/system/fieldguard.service, /usr/lib/sysusers.d/fieldguard.conf,
#   /usr/lib/sysctl.d/60-fieldguard.conf     the unit, its user and its UDP buffer limit
#   /usr/share/doc/fieldguard/README.md
# Under the default prefix /usr/local the same tree lands below /usr/local; systemd also reads units,
# sysusers.d and sysctl.d from /usr/local/lib.
include(GNUInstallDirs)

# Every destination is relative to the prefix, so that `cmake --install build --prefix STAGE` and `DESTDIR=STAGE`
# both put the whole tree under STAGE (a test checks it). systemd's directories come from its pkg-config file
# where there is one, with its prefixes set to ours and then taken off again: Debian 12's says
# /lib/systemd/system, /usr/lib/sysusers.d and /usr/lib/sysctl.d, which under the prefix /usr are
# lib/systemd/system (/usr/lib and /lib are one directory on a merged-/usr system), lib/sysusers.d, lib/sysctl.d.
function(fieldguard_systemd_dir out variable fallback)
  set(_dir ${fallback})
  find_program(FIELDGUARD_PKG_CONFIG pkg-config)
  if(FIELDGUARD_PKG_CONFIG)
    set(_token "/fieldguard-prefix")
    execute_process(
      COMMAND ${FIELDGUARD_PKG_CONFIG} --define-variable=prefix=${_token} --define-variable=root_prefix=${_token}
              --define-variable=rootprefix=${_token} --variable=${variable} systemd
      OUTPUT_VARIABLE _found OUTPUT_STRIP_TRAILING_WHITESPACE RESULT_VARIABLE _rc ERROR_QUIET)
    if(_rc EQUAL 0 AND _found MATCHES "^${_token}/(.+)$")
      set(_dir ${CMAKE_MATCH_1})
    endif()
  endif()
  set(${out} ${_dir} PARENT_SCOPE)
endfunction()
fieldguard_systemd_dir(_unit_dir systemdsystemunitdir lib/systemd/system)
fieldguard_systemd_dir(_sysusers_dir sysusersdir lib/sysusers.d)
fieldguard_systemd_dir(_sysctl_dir sysctldir lib/sysctl.d)
set(FIELDGUARD_SYSTEMD_UNIT_DIR ${_unit_dir} CACHE STRING
    "Where the systemd unit is installed (relative: under the install prefix)")
set(FIELDGUARD_SYSUSERS_DIR ${_sysusers_dir} CACHE STRING "sysusers.d (relative: under the install prefix)")
set(FIELDGUARD_SYSCTL_DIR ${_sysctl_dir} CACHE STRING "sysctl.d (relative: under the install prefix)")

# The unit names the installed binary and config by absolute path: generated for this prefix.
set(FIELDGUARD_FULL_BINDIR ${CMAKE_INSTALL_FULL_BINDIR})
# Where the configuration really lands: GNUInstallDirs' FULL_SYSCONFDIR says /etc for the prefix /usr, but a
# relative `etc` installs to /usr/etc; the unit must name the file that is there.
if(IS_ABSOLUTE "${CMAKE_INSTALL_SYSCONFDIR}")
  set(FIELDGUARD_FULL_CONFDIR ${CMAKE_INSTALL_SYSCONFDIR}/fieldguard)
else()
  set(FIELDGUARD_FULL_CONFDIR ${CMAKE_INSTALL_PREFIX}/${CMAKE_INSTALL_SYSCONFDIR}/fieldguard)
endif()
set(FIELDGUARD_FULL_DOCDIR ${CMAKE_INSTALL_FULL_DATAROOTDIR}/doc/fieldguard)
configure_file(${PROJECT_SOURCE_DIR}/systemd/fieldguard.service.in
               ${PROJECT_BINARY_DIR}/systemd/fieldguard.service @ONLY)

install(TARGETS fieldguard RUNTIME DESTINATION ${CMAKE_INSTALL_BINDIR})
install(FILES config/fieldguard.yaml config/published.yaml DESTINATION ${CMAKE_INSTALL_SYSCONFDIR}/fieldguard)
if(EXISTS ${PROJECT_SOURCE_DIR}/config/fieldguard.dbc)
  install(FILES config/fieldguard.dbc DESTINATION ${CMAKE_INSTALL_DATADIR}/fieldguard)
endif()
install(FILES ${PROJECT_BINARY_DIR}/systemd/fieldguard.service DESTINATION ${FIELDGUARD_SYSTEMD_UNIT_DIR})
install(FILES systemd/fieldguard.sysusers DESTINATION ${FIELDGUARD_SYSUSERS_DIR} RENAME fieldguard.conf)
install(FILES systemd/fieldguard.sysctl DESTINATION ${FIELDGUARD_SYSCTL_DIR} RENAME 60-fieldguard.conf)
install(FILES README.md DESTINATION ${CMAKE_INSTALL_DOCDIR})
