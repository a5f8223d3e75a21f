# What `cmake --install` puts where. For the Debian layout configure with -DCMAKE_INSTALL_PREFIX=/usr:
#   /usr/bin/fieldguard                      the daemon and its commands
#   /etc/fieldguard/*.yaml                   configuration (GNUInstallDirs maps prefix /usr to /etc)
#   /usr/share/fieldguard/fieldguard.dbc     the CAN database for the steering controller's integrator
#   /usr/lib/systemd/system/fieldguard.service, /usr/lib/sysusers.d/fieldguard.conf,
#   /usr/lib/sysctl.d/60-fieldguard.conf     the unit, its user and its UDP buffer limit
#   /usr/share/doc/fieldguard/README.md
# Under the default prefix /usr/local the same tree lands below /usr/local; systemd also reads units,
# sysusers.d and sysctl.d from /usr/local/lib.
include(GNUInstallDirs)

set(FIELDGUARD_SYSTEMD_UNIT_DIR "${CMAKE_INSTALL_PREFIX}/lib/systemd/system" CACHE PATH
    "Where the systemd unit is installed")
set(FIELDGUARD_SYSTEMD_LIB_DIR "${CMAKE_INSTALL_PREFIX}/lib" CACHE PATH
    "Parent of sysusers.d and sysctl.d")

# The unit names the installed binary and config by absolute path: generated for this prefix.
set(FIELDGUARD_FULL_BINDIR ${CMAKE_INSTALL_FULL_BINDIR})
set(FIELDGUARD_FULL_CONFDIR ${CMAKE_INSTALL_FULL_SYSCONFDIR}/fieldguard)
set(FIELDGUARD_FULL_DOCDIR ${CMAKE_INSTALL_FULL_DATAROOTDIR}/doc/fieldguard)
configure_file(${PROJECT_SOURCE_DIR}/systemd/fieldguard.service.in
               ${PROJECT_BINARY_DIR}/systemd/fieldguard.service @ONLY)

install(TARGETS fieldguard RUNTIME DESTINATION ${CMAKE_INSTALL_BINDIR})
install(FILES config/fieldguard.yaml config/published.yaml DESTINATION ${CMAKE_INSTALL_SYSCONFDIR}/fieldguard)
if(EXISTS ${PROJECT_SOURCE_DIR}/config/fieldguard.dbc)
  install(FILES config/fieldguard.dbc DESTINATION ${CMAKE_INSTALL_DATADIR}/fieldguard)
endif()
install(FILES ${PROJECT_BINARY_DIR}/systemd/fieldguard.service DESTINATION ${FIELDGUARD_SYSTEMD_UNIT_DIR})
install(FILES systemd/fieldguard.sysusers DESTINATION ${FIELDGUARD_SYSTEMD_LIB_DIR}/sysusers.d
        RENAME fieldguard.conf)
install(FILES systemd/fieldguard.sysctl DESTINATION ${FIELDGUARD_SYSTEMD_LIB_DIR}/sysctl.d
        RENAME 60-fieldguard.conf)
install(FILES README.md DESTINATION ${CMAKE_INSTALL_DOCDIR})
