# The Debian packages: `cpack -G DEB` in the build directory writes, as Debian splits a project,
#   cosmic-gateway_VERSION_ARCH.deb         cosmicd, cosmicctl, cosmic-fmu, the units, sysusers file,
#                                           example configuration (a conffile), manual pages, bash
#                                           completions
#   libcosmic-client0_VERSION_ARCH.deb      libcosmic-client.so.0 (the runtime library of components)
#   libcosmic-client-dev_VERSION_ARCH.deb   headers, libcosmic-client.so, cosmic-client.pc, the CMake
#                                           package cosmic_client: what building a component needs
#   python3-cosmic_VERSION_ARCH.deb         the Python package cosmic (/usr/lib/python3/dist-packages)
# and for each package with binaries a PACKAGE-dbgsym_VERSION_ARCH.ddeb with their debug symbols
# (/usr/lib/debug/.build-id): the binaries in the .debs are stripped. Depends: dpkg-shlibdeps for
# the libraries the binaries load, plus the ones written below. Build with
# -DCMAKE_BUILD_TYPE=RelWithDebInfo: the dbgsym packages get what the build has.
# The install components are named in CMakeLists.txt, daemon/, lib/client and lib/python.
set(CPACK_PACKAGE_NAME cosmic-gateway)
set(CPACK_PACKAGE_CONTACT "cosmic-gateway developers <dev@cosmic-gateway.invalid>")
set(CPACK_PACKAGE_DESCRIPTION_SUMMARY "Event-channel gateway between CAN, DDS and LCM with admission control")
set(CPACK_GENERATOR DEB)
set(CPACK_PACKAGING_INSTALL_PREFIX /usr)
set(CPACK_DEB_COMPONENT_INSTALL ON)
set(CPACK_DEBIAN_FILE_NAME DEB-DEFAULT)
set(CPACK_DEBIAN_PACKAGE_SHLIBDEPS ON)
set(CPACK_DEBIAN_DEBUGINFO_PACKAGE ON)
set(CPACK_DEBIAN_PACKAGE_CONTROL_STRICT_PERMISSION ON)
set(CPACK_DEBIAN_PACKAGE_SECTION net)
set(COSMIC_DEB_EXACT "(= ${PROJECT_VERSION})")

# cosmic-gateway: maintainer scripts in systemd/debian (they honour DPKG_ROOT).
set(CPACK_COMPONENTS_ALL gateway)
set(CPACK_DEBIAN_GATEWAY_PACKAGE_NAME cosmic-gateway)
set(CPACK_COMPONENT_GATEWAY_DESCRIPTION "${CPACK_PACKAGE_DESCRIPTION_SUMMARY}
 cosmicd forwards COSMIC event channels between SocketCAN buses, Fast DDS domains and LCM
 multicast groups, with admission and QoS-mismatch checks on every binding; cosmicctl inspects
 and steers it, checks configurations offline and generates component skeletons; cosmic-fmu runs
 a co-simulation FMU (FMI 2.0 or 3.0) of the configuration as a component on its channels, one
 per instance of the unit cosmic-fmu@.service.")
set(CPACK_DEBIAN_GATEWAY_PACKAGE_CONTROL_EXTRA
  "${PROJECT_SOURCE_DIR}/systemd/debian/postinst;${PROJECT_SOURCE_DIR}/systemd/debian/prerm;${PROJECT_SOURCE_DIR}/systemd/debian/postrm;${PROJECT_SOURCE_DIR}/systemd/debian/conffiles")

if(TARGET cosmic_client_shared)
  # libcosmic-client0: named after the SONAME (libcosmic-client.so.0); shlibs file for the
  # packages of components built against it; ldconfig runs from a trigger.
  list(APPEND CPACK_COMPONENTS_ALL libclient dev)
  set(CPACK_DEBIAN_LIBCLIENT_PACKAGE_NAME libcosmic-client0)
  set(CPACK_DEBIAN_LIBCLIENT_PACKAGE_SECTION libs)
  # CPack's own shlibs switch is for every package at once and warns about the Python extension
  # (a module, no SONAME), so the library's package carries a shlibs file and the ldconfig trigger
  # (as debhelper writes them) of its own.
  set(COSMIC_DEB_CONTROL_DIR ${CMAKE_BINARY_DIR}/debian-libcosmic-client0)
  file(WRITE ${COSMIC_DEB_CONTROL_DIR}/shlibs "libcosmic-client 0 libcosmic-client0 (>= ${PROJECT_VERSION})\n")
  file(WRITE ${COSMIC_DEB_CONTROL_DIR}/triggers "# ld.so's cache learns libcosmic-client.so.0\nactivate-noawait ldconfig\n")
  set(CPACK_DEBIAN_LIBCLIENT_PACKAGE_CONTROL_EXTRA "${COSMIC_DEB_CONTROL_DIR}/shlibs;${COSMIC_DEB_CONTROL_DIR}/triggers")
  set(CPACK_COMPONENT_LIBCLIENT_DESCRIPTION "COSMIC event channels for components (libcosmic-client)
 The component API of cosmic-gateway: announce, publish, subscribe and get_event on COSMIC event
 channels over DDS, LCM and SocketCAN, in the gateway's own wire formats.")
  set(CPACK_DEBIAN_DEV_PACKAGE_NAME libcosmic-client-dev)
  set(CPACK_DEBIAN_DEV_PACKAGE_SECTION libdevel)
  set(CPACK_DEBIAN_DEV_PACKAGE_DEPENDS "libcosmic-client0 ${COSMIC_DEB_EXACT}")
  set(CPACK_DEBIAN_DEV_PACKAGE_SUGGESTS "cmake, pkg-config, cosmic-gateway")
  set(CPACK_COMPONENT_DEV_DESCRIPTION "COSMIC event channels for components (development files)
 Headers (cosmic/client.h for C, cosmic/client.hpp for C++20), the CMake package cosmic_client
 (target cosmic::client) and the pkg-config file cosmic-client.pc. cosmicctl gen (package
 cosmic-gateway) writes component skeletons that build against them.")
endif()

if(TARGET cosmic_python)
  # The extension is built for one interpreter's ABI (cpython-3XY): that python3, no other.
  list(APPEND CPACK_COMPONENTS_ALL python)
  set(CPACK_DEBIAN_PYTHON_PACKAGE_NAME python3-cosmic)
  set(CPACK_DEBIAN_PYTHON_PACKAGE_SECTION python)
  string(REGEX MATCH "^([0-9]+)\\.([0-9]+)$" _ ${COSMIC_PYTHON_VERSION})
  math(EXPR next_minor "${CMAKE_MATCH_2} + 1")
  set(CPACK_DEBIAN_PYTHON_PACKAGE_DEPENDS "python3 (>= ${COSMIC_PYTHON_VERSION}~), python3 (<< ${CMAKE_MATCH_1}.${next_minor})")
  set(CPACK_DEBIAN_PYTHON_PACKAGE_SUGGESTS "python3-numpy, cosmic-gateway")
  set(CPACK_COMPONENT_PYTHON_DESCRIPTION "COSMIC event channels for components (Python 3)
 The Python package cosmic over libcosmic-client: a context-managed client per segment, announce,
 publish of buffer-protocol objects (numpy arrays without a copy), subscribe with callbacks,
 get_event for fixed-step loops, check_channel against a running cosmicd.")
endif()

include(CPack)
