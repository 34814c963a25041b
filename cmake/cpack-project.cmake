# Read by cpack for each generator (CPACK_PROJECT_CONFIG_FILE, cmake/packaging.cmake), after
# CPackConfig.cmake and cpack's -D options. A Debian revision, for a package rebuilt from the
# same upstream version (cpack -D CPACK_DEBIAN_PACKAGE_RELEASE=2: version 0.1.0-2, a newer
# package to apt): plinth-tools then needs plinth-monitor of that same full version.
if(CPACK_DEBIAN_PACKAGE_RELEASE)
  string(REPLACE "plinth-monitor (= ${CPACK_PACKAGE_VERSION})"
    "plinth-monitor (= ${CPACK_PACKAGE_VERSION}-${CPACK_DEBIAN_PACKAGE_RELEASE})"
    CPACK_DEBIAN_TOOLS_PACKAGE_DEPENDS "${CPACK_DEBIAN_TOOLS_PACKAGE_DEPENDS}")
endif()
