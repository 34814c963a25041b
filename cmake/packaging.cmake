# The Debian packages (CPack DEB), one per install component (cmake/install.cmake):
#   plinth-monitor  the box: plinth-monitor, plinth-replay, the units, the user, the data
#   plinth-tools    plinth-sim, plinth-sweep, plinth-eval, plinth-accuracy, plinth-event-plot
#   libplinth-dev   the freestanding core's headers, static library and CMake package
# Built by the workflow presets package and package-arm64 into build/package/ (docs/install.md).
# Depends are written here for Debian 12, not computed: the test package_deb_contents checks
# them against dpkg-shlibdeps on the built programs and against tools/install-deps.sh --runtime.
set(CPACK_GENERATOR DEB)
set(CPACK_PACKAGE_NAME plinth)
set(CPACK_PACKAGE_VERSION ${PROJECT_VERSION})
set(CPACK_PACKAGE_VENDOR "plinth")
set(CPACK_PACKAGE_CONTACT "plinth maintainers <plinth@users.noreply.github.com>")
set(CPACK_PACKAGE_DESCRIPTION_SUMMARY "earthquake early warning for statues on isolated bases")
set(CPACK_PACKAGE_HOMEPAGE_URL "https://github.com/plinth/plinth")
set(CPACK_PACKAGING_INSTALL_PREFIX /usr)
set(CPACK_DEB_COMPONENT_INSTALL ON)
set(CPACK_COMPONENTS_ALL monitor tools dev)
set(CPACK_DEBIAN_FILE_NAME DEB-DEFAULT)
set(CPACK_DEBIAN_PACKAGE_SECTION misc)
set(CPACK_DEBIAN_PACKAGE_PRIORITY optional)
# The target's architecture, not the build machine's (dpkg --print-architecture): a cross build
# for arm64 makes arm64 packages.
if(CMAKE_SYSTEM_PROCESSOR MATCHES "^(aarch64|arm64)$")
  set(CPACK_DEBIAN_PACKAGE_ARCHITECTURE arm64)
elseif(CMAKE_SYSTEM_PROCESSOR MATCHES "^(x86_64|AMD64)$")
  set(CPACK_DEBIAN_PACKAGE_ARCHITECTURE amd64)
endif()
# Maintainer scripts and conffiles are installed with the modes dpkg expects.
set(CPACK_DEBIAN_PACKAGE_CONTROL_STRICT_PERMISSION TRUE)

# The C++ runtime and the shared libraries the programs link (Debian 12's packages).
set(plinth_cxx_runtime "libc6 (>= 2.34), libgcc-s1 (>= 3.0), libstdc++6 (>= 12)")
set(PLINTH_MONITOR_DEPENDS "${plinth_cxx_runtime}, libgpiod2 (>= 1.6), libmosquitto1 (>= 2.0), libsystemd0 (>= 252), libtomlplusplus3 (>= 3.3), systemd")

set(CPACK_DEBIAN_MONITOR_PACKAGE_NAME plinth-monitor)
set(CPACK_DEBIAN_MONITOR_PACKAGE_DEPENDS "${PLINTH_MONITOR_DEPENDS}")
# plinth-commission draws its report's picture with gnuplot (docs/commissioning.md); without it
# the report says so and has no picture.
set(CPACK_DEBIAN_MONITOR_PACKAGE_RECOMMENDS "gnuplot-nox | gnuplot")
set(CPACK_DEBIAN_MONITOR_PACKAGE_SUGGESTS "can-utils, mbpoll, mosquitto-clients")
set(CPACK_COMPONENT_MONITOR_DESCRIPTION "plinth's monitor box: the statue's earthquake early warning
 plinth-monitor estimates the phase of motion and the overturning risk of a statue on its
 isolation base from accelerometers on a CAN bus, and raises alarms on CAN, relays, Modbus TCP
 and MQTT; plinth-commission checks the sensors on site against the box file before the box is
 trusted; plinth-replay sends recorded earthquakes on a bus. A systemd unit per CAN interface
 (plinth-monitor@can0), its Modbus socket unit, the service's user, and the data: the CAN
 database, example scenes and box configuration.")
set(plinth_debian ${CMAKE_CURRENT_LIST_DIR}/debian)
set(CPACK_DEBIAN_MONITOR_PACKAGE_CONTROL_EXTRA
  ${plinth_debian}/plinth-monitor/conffiles ${plinth_debian}/plinth-monitor/postinst
  ${plinth_debian}/plinth-monitor/prerm ${plinth_debian}/plinth-monitor/postrm)

set(CPACK_DEBIAN_TOOLS_PACKAGE_NAME plinth-tools)
set(CPACK_DEBIAN_TOOLS_PACKAGE_DEPENDS
  "${plinth_cxx_runtime}, libtomlplusplus3 (>= 3.3), plinth-monitor (= ${PROJECT_VERSION}), python3 (>= 3.11), gnuplot-nox | gnuplot")
set(CPACK_COMPONENT_TOOLS_DESCRIPTION "plinth's engineering tools
 plinth-sim simulates the block on its isolated base under a record; plinth-sweep maps the PGA
 of each kind of motion against a parameter; plinth-eval measures the warning against the
 solver's truth; plinth-accuracy compares the steppers; plinth-event-plot draws a capture of
 the monitor's event recorder. With the bundled earthquake records.")

set(CPACK_DEBIAN_DEV_PACKAGE_NAME libplinth-dev)
set(CPACK_DEBIAN_DEV_PACKAGE_SECTION libdevel)
set(CPACK_DEBIAN_DEV_PACKAGE_DEPENDS "libeigen3-dev (>= 3.4)")
set(CPACK_COMPONENT_DEV_DESCRIPTION "plinth's freestanding core: headers and static library
 The model of a rigid block on an oscillating base (no heap, no exceptions, no RTTI), for
 another project: find_package(plinth) gives the imported target plinth::core.")

# A Debian revision given to cpack (-D CPACK_DEBIAN_PACKAGE_RELEASE=N) is carried into
# plinth-tools' exact Depends on plinth-monitor (tests/integration/image_vm.py upgrades to one).
set(CPACK_PROJECT_CONFIG_FILE ${CMAKE_CURRENT_LIST_DIR}/cpack-project.cmake)

include(CPack)
