# cmake --install: the layout of an installed plinth (docs/install.md). Under the prefix:
#   bin/                        the programs
#   share/plinth/               their data: the CAN database, the Modbus map, the gnuplot script,
#                               example scenes and box file, the bundled records
#   lib/systemd/system/         the units (plinth-monitor@.service, plinth-monitor@.socket)
#   lib/sysusers.d/, lib/udev/rules.d/   the service's user, the GPIO chips' group
#   etc/plinth/                 the box's configuration (/etc/plinth for the prefix /usr, as
#                               in the Debian packages: GNUInstallDirs' rule, at install time)
#   include/, lib/.../cmake/plinth/   the freestanding core for find_package(plinth)
# Three components, one Debian package each (cmake/packaging.cmake): monitor (plinth-monitor),
# tools (plinth-tools), dev (libplinth-dev). Installed programs find their data from their own
# location (bin/../share/plinth), never from the source tree.
include(GNUInstallDirs)
include(CMakePackageConfigHelpers)

set(PLINTH_INSTALL_DATADIR ${CMAKE_INSTALL_DATADIR}/plinth)
set(PLINTH_INSTALL_CMAKEDIR ${CMAKE_INSTALL_LIBDIR}/cmake/plinth)

# The box: plinth-monitor, plinth-replay and plinth-commission, its units, its user, its data.
set(PLINTH_MONITOR_COMPONENT_PROGRAMS plinth-monitor plinth-replay plinth-commission)
install(TARGETS ${PLINTH_MONITOR_COMPONENT_PROGRAMS} RUNTIME COMPONENT monitor)
# What cpack's monitor component needs built, alone (tools/image-test.sh: the image's package).
add_custom_target(plinth-monitor-component)
add_dependencies(plinth-monitor-component ${PLINTH_MONITOR_COMPONENT_PROGRAMS})
# The units and the configuration name the install's own folders, decided at install time (a
# Debian package installs the same build with the prefix /usr that `cmake --install` may give
# another): @PLINTH_BINDIR@ is PREFIX/bin; @PLINTH_SYSCONFDIR@ is /etc for the prefix /usr
# (GNUInstallDirs' rule), else PREFIX/etc. DESTDIR is honoured (CPack installs with it).
install(CODE "
  set(plinth_bindir \"\${CMAKE_INSTALL_PREFIX}/${CMAKE_INSTALL_BINDIR}\")
  set(plinth_sysconfdir \"\${CMAKE_INSTALL_PREFIX}/etc\")
  if(CMAKE_INSTALL_PREFIX STREQUAL \"/usr\")
    set(plinth_sysconfdir /etc)
  endif()
  file(MAKE_DIRECTORY \"${CMAKE_BINARY_DIR}/plinth-units\")
  foreach(unit plinth-monitor@.service plinth-monitor@.socket)
    file(READ \"${PROJECT_SOURCE_DIR}/firmware/linux/systemd/\${unit}\" text)
    string(REPLACE @PLINTH_BINDIR@ \"\${plinth_bindir}\" text \"\${text}\")
    string(REPLACE @PLINTH_SYSCONFDIR@ \"\${plinth_sysconfdir}\" text \"\${text}\")
    file(WRITE \"${CMAKE_BINARY_DIR}/plinth-units/\${unit}\" \"\${text}\")
  endforeach()
  file(INSTALL DESTINATION \"\${CMAKE_INSTALL_PREFIX}/lib/systemd/system\" TYPE FILE
       FILES \"${CMAKE_BINARY_DIR}/plinth-units/plinth-monitor@.service\"
             \"${CMAKE_BINARY_DIR}/plinth-units/plinth-monitor@.socket\")
  # An existing box.toml is the site's: kept, as dpkg keeps a conffile.
  if(EXISTS \"\$ENV{DESTDIR}\${plinth_sysconfdir}/plinth/box.toml\")
    message(STATUS \"Kept: \$ENV{DESTDIR}\${plinth_sysconfdir}/plinth/box.toml (the site's)\")
  else()
    file(INSTALL DESTINATION \"\${plinth_sysconfdir}/plinth\" TYPE FILE
         FILES \"${PROJECT_SOURCE_DIR}/firmware/linux/systemd/box.toml\")
  endif()
" COMPONENT monitor)
install(FILES firmware/linux/systemd/plinth-monitor.sysusers
        DESTINATION lib/sysusers.d RENAME plinth-monitor.conf COMPONENT monitor)
install(FILES firmware/linux/systemd/60-plinth-gpio.rules
        DESTINATION lib/udev/rules.d COMPONENT monitor)
install(FILES hal/can_codec/plinth.dbc DESTINATION ${PLINTH_INSTALL_DATADIR} COMPONENT monitor)
# The Modbus register map as a file, once docs/integration.md's map is shipped as one.
file(GLOB modbus_map_files ${PROJECT_SOURCE_DIR}/firmware/linux/modbus*.csv
     ${PROJECT_SOURCE_DIR}/firmware/linux/modbus*.json)
if(modbus_map_files)
  install(FILES ${modbus_map_files} DESTINATION ${PLINTH_INSTALL_DATADIR} COMPONENT monitor)
endif()
install(FILES firmware/monitor.example.toml DESTINATION ${PLINTH_INSTALL_DATADIR}/examples
        RENAME box.toml COMPONENT monitor)
install(DIRECTORY sim/scenes/ DESTINATION ${PLINTH_INSTALL_DATADIR}/scenes COMPONENT monitor
        FILES_MATCHING PATTERN "*.toml")

# plinth-event-plot as installed: the checkout's script with the build's version written in
# (lib/version/describe.cmake, at every build like the programs' own).
set(PLINTH_EVENT_PLOT_SCRIPT ${CMAKE_CURRENT_BINARY_DIR}/generated/plinth-event-plot)
add_custom_target(plinth_event_plot_script ALL
  COMMAND ${CMAKE_COMMAND}
    -DSOURCE_DIR=${PROJECT_SOURCE_DIR}
    -DPROJECT_VERSION=${PROJECT_VERSION}
    -DGIT_EXECUTABLE=${GIT_EXECUTABLE}
    -DGIT_DESCRIPTION=${PLINTH_GIT_DESCRIPTION}
    -DSCRIPT_IN=${PROJECT_SOURCE_DIR}/tools/plinth-event-plot
    -DSCRIPT_OUT=${PLINTH_EVENT_PLOT_SCRIPT}
    -P ${PROJECT_SOURCE_DIR}/lib/version/describe.cmake
  BYPRODUCTS ${PLINTH_EVENT_PLOT_SCRIPT}
  COMMENT "plinth-event-plot: the build's version written in"
  VERBATIM)

# The engineers' tools: the simulator, the sweeps, the evaluation, the accuracy study, the event
# picture; the bundled records they run on.
install(TARGETS plinth-sim plinth-sweep plinth-eval plinth-accuracy RUNTIME COMPONENT tools)
install(PROGRAMS ${PLINTH_EVENT_PLOT_SCRIPT} DESTINATION ${CMAKE_INSTALL_BINDIR} COMPONENT tools)
install(FILES tools/event-plot.gp DESTINATION ${PLINTH_INSTALL_DATADIR} COMPONENT tools)
install(DIRECTORY sim/data/records/ DESTINATION ${PLINTH_INSTALL_DATADIR}/records
        COMPONENT tools)

# The copyright file every Debian package carries.
foreach(pair IN ITEMS monitor:plinth-monitor tools:plinth-tools dev:libplinth-dev)
  string(REPLACE ":" ";" pair "${pair}")
  list(GET pair 0 component)
  list(GET pair 1 package)
  install(FILES LICENSE DESTINATION ${CMAKE_INSTALL_DATAROOTDIR}/doc/${package} RENAME copyright
          COMPONENT ${component})
endforeach()

# The freestanding core for other projects: find_package(plinth) gives plinth::core, with the
# build's compile definitions (PLINTH_REAL, the ensemble's capacity, the forecast). Its private
# build settings (warnings, freestanding flags, build options) are interface targets named in
# the static library's link interface, so they are exported too; they carry no usage
# requirement to a consumer.
set_target_properties(plinth_core PROPERTIES EXPORT_NAME core)
install(TARGETS plinth_core plinth_warnings plinth_freestanding plinth_core_build_options
        EXPORT plinthTargets
        ARCHIVE DESTINATION ${CMAKE_INSTALL_LIBDIR} COMPONENT dev)
install(DIRECTORY lib/core/include/plinth DESTINATION ${CMAKE_INSTALL_INCLUDEDIR} COMPONENT dev)
install(EXPORT plinthTargets NAMESPACE plinth:: DESTINATION ${PLINTH_INSTALL_CMAKEDIR}
        COMPONENT dev)
configure_package_config_file(cmake/plinthConfig.cmake.in
  ${CMAKE_CURRENT_BINARY_DIR}/plinthConfig.cmake INSTALL_DESTINATION ${PLINTH_INSTALL_CMAKEDIR})
write_basic_package_version_file(${CMAKE_CURRENT_BINARY_DIR}/plinthConfigVersion.cmake
  COMPATIBILITY SameMinorVersion)
install(FILES ${CMAKE_CURRENT_BINARY_DIR}/plinthConfig.cmake
              ${CMAKE_CURRENT_BINARY_DIR}/plinthConfigVersion.cmake
        DESTINATION ${PLINTH_INSTALL_CMAKEDIR} COMPONENT dev)
