# Installation, the exported CMake package and the Debian package.
#
#   cmake --install build [--prefix /usr]            # or: DESTDIR=/scratch cmake --install build --prefix /usr
#   (cd build && cpack -G DEB)                        # build/hoist-twin_<version>_<arch>.deb
#
# What goes where (prefix P, /usr for the .deb):
#   P/bin/                      the programs (hoist-twind, hoist-sim, ..., hoist-lcm-spy)
#   /etc/hoist-twin/example.toml  the commented shaft template (a conffile; HOIST_CONFIG_DIR)
#   P/lib/systemd/system/       hoist-twind@.service (paths filled in at install time)
#   P/share/hoist-twin/lcm/     the .lcm message definitions
#   P/include/hoist/            model headers, generated C++ message headers, hoist/io, hoist/bus
#   P/lib/<multiarch>/          libhoist_model.a, libhoist_io.a
#   P/lib/<multiarch>/cmake/hoist/  hoistConfig.cmake: find_package(hoist) -> hoist::model, hoist::io, hoist::msgs
#   P/share/java/hoist_msgs.jar the Java message classes (lcm-spy, Java clients)
#   P/share/doc/hoist-twin/     README, docs/, examples (demo.toml, read_twin.py)
#   P/share/hoist-twin/dash/web the dashboard's web files, when tools/dash/web exists
include(GNUInstallDirs)
include(CMakePackageConfigHelpers)

set(HOIST_CONFIG_DIR "/etc/hoist-twin" CACHE PATH
    "Directory of the shaft configurations read by hoist-twind@<instance>.service (absolute)")
set(HOIST_SYSTEMD_UNIT_DIR "lib/systemd/system" CACHE STRING
    "Where the systemd unit is installed, relative to the install prefix")
set(HOIST_DOC_SUBDIR "${CMAKE_INSTALL_DATAROOTDIR}/doc/hoist-twin")
set(HOIST_CMAKE_DIR "${CMAKE_INSTALL_LIBDIR}/cmake/hoist")

# ---- programs -------------------------------------------------------------------
set(_hoist_programs hoist-sim hoist-study hoist-twind hoist-replay hoist-log2csv hoist-monitor
                    hoist-alarm-ack hoist-wakeup-latency hoist-timing-test hoist-mqtt)
foreach(p ${_hoist_programs})
  if(TARGET ${p})
    install(TARGETS ${p} RUNTIME DESTINATION ${CMAKE_INSTALL_BINDIR} COMPONENT runtime)
  endif()
endforeach()
if(TARGET hoist_msgs_java)
  # The wrapper finds lcm.jar, jchart2d.jar and ../share/java/hoist_msgs.jar itself.
  install(PROGRAMS ${CMAKE_RUNTIME_OUTPUT_DIRECTORY}/hoist-lcm-spy DESTINATION ${CMAKE_INSTALL_BINDIR}
          COMPONENT runtime)
  install(FILES ${CMAKE_BINARY_DIR}/msgs/hoist_msgs.jar DESTINATION ${CMAKE_INSTALL_DATAROOTDIR}/java
          COMPONENT runtime)
endif()

# ---- LCM types: definitions and generated C++ headers -------------------------------
file(GLOB _hoist_lcm_files ${PROJECT_SOURCE_DIR}/msgs/*.lcm)
install(FILES ${_hoist_lcm_files} DESTINATION ${CMAKE_INSTALL_DATAROOTDIR}/hoist-twin/lcm COMPONENT dev)
install(DIRECTORY ${CMAKE_BINARY_DIR}/msgs/generated/hoist/ DESTINATION ${CMAKE_INSTALL_INCLUDEDIR}/hoist
        COMPONENT dev FILES_MATCHING PATTERN "*.hpp")

# ---- configuration, unit, docs ----------------------------------------------------
install(FILES ${PROJECT_SOURCE_DIR}/service/config/example.toml DESTINATION ${HOIST_CONFIG_DIR} COMPONENT runtime)
# The unit names the installed program and config paths: filled in at install
# time, so `--prefix` and cpack (prefix /usr) both get the right ExecStart.
install(CODE "
  set(HOIST_BIN_DIR \"\${CMAKE_INSTALL_PREFIX}/${CMAKE_INSTALL_BINDIR}\")
  set(HOIST_CONFIG_DIR \"${HOIST_CONFIG_DIR}\")
  set(HOIST_DOC_DIR \"\${CMAKE_INSTALL_PREFIX}/${HOIST_DOC_SUBDIR}\")
  foreach(unit hoist-twind@.service hoist-mqtt@.service)
    configure_file(\"${PROJECT_SOURCE_DIR}/service/systemd/\${unit}.in\"
                   \"${CMAKE_BINARY_DIR}/install/\${unit}\" @ONLY)
    file(INSTALL \"${CMAKE_BINARY_DIR}/install/\${unit}\"
         DESTINATION \"\${CMAKE_INSTALL_PREFIX}/${HOIST_SYSTEMD_UNIT_DIR}\")
  endforeach()
" COMPONENT runtime)
install(FILES ${PROJECT_SOURCE_DIR}/README.md DESTINATION ${HOIST_DOC_SUBDIR} COMPONENT runtime)
install(DIRECTORY ${PROJECT_SOURCE_DIR}/docs/ DESTINATION ${HOIST_DOC_SUBDIR}/docs COMPONENT runtime
        PATTERN "*.json" EXCLUDE PATTERN "*.log" EXCLUDE PATTERN "*.csv" EXCLUDE PATTERN "*.gp" EXCLUDE)
install(FILES ${PROJECT_SOURCE_DIR}/service/config/demo.toml ${PROJECT_SOURCE_DIR}/service/config/example.toml
        DESTINATION ${HOIST_DOC_SUBDIR}/examples COMPONENT runtime)
install(FILES ${PROJECT_SOURCE_DIR}/tools/mqtt/config/example.toml DESTINATION ${HOIST_DOC_SUBDIR}/examples
        RENAME mqtt.toml COMPONENT runtime)
install(PROGRAMS ${PROJECT_SOURCE_DIR}/tools/python/read_twin.py DESTINATION ${HOIST_DOC_SUBDIR}/examples
        COMPONENT runtime)

# ---- the dashboard's web files (tools/dash/web, another branch) -----------------------
# hoist-dash and its page (<prefix>/share/hoist-twin/dash) are installed by tools/dash/CMakeLists.txt.

# ---- the exported CMake package: find_package(hoist) -----------------------------------
# Include directories of the exported targets: the source/build paths for the
# build tree, <prefix>/include once installed.  Set here, so the libraries'
# own CMakeLists stay as they are.
# Both the plain and the SYSTEM include directories (hoist_msgs' generated
# headers are SYSTEM): no build-tree path may reach hoistTargets.cmake.
function(hoist_export_includes target)
  foreach(prop INTERFACE_INCLUDE_DIRECTORIES INTERFACE_SYSTEM_INCLUDE_DIRECTORIES)
    get_target_property(_dirs ${target} ${prop})
    if(NOT _dirs)
      continue()
    endif()
    set(_new "")
    foreach(d ${_dirs})
      if(d MATCHES "^\\$<")
        list(APPEND _new "${d}")
      else()
        list(APPEND _new "$<BUILD_INTERFACE:${d}>")
      endif()
    endforeach()
    # $<INSTALL_PREFIX>: exported as ${_IMPORT_PREFIX} (CMake prefixes a
    # relative INSTALL_INTERFACE path only in INTERFACE_INCLUDE_DIRECTORIES).
    list(APPEND _new "$<INSTALL_INTERFACE:$<INSTALL_PREFIX>/${CMAKE_INSTALL_INCLUDEDIR}>")
    list(REMOVE_DUPLICATES _new)
    set_target_properties(${target} PROPERTIES ${prop} "${_new}")
  endforeach()
endfunction()

set(_hoist_exported "")
foreach(pair "hoist_model:model" "hoist_io:io" "hoist_msgs:msgs" "hoist_lcm:lcm")
  string(REPLACE ":" ";" pair "${pair}")
  list(GET pair 0 t)
  list(GET pair 1 name)
  if(TARGET ${t})
    hoist_export_includes(${t})
    # The headers need C++20 (defaulted operator==, concepts): a downstream
    # project that sets no standard gets it from the target.
    target_compile_features(${t} INTERFACE cxx_std_20)
    set_target_properties(${t} PROPERTIES EXPORT_NAME ${name})
    list(APPEND _hoist_exported ${t})
  endif()
endforeach()
install(TARGETS ${_hoist_exported} EXPORT hoistTargets
        ARCHIVE DESTINATION ${CMAKE_INSTALL_LIBDIR} COMPONENT dev
        LIBRARY DESTINATION ${CMAKE_INSTALL_LIBDIR} COMPONENT dev
        INCLUDES DESTINATION ${CMAKE_INSTALL_INCLUDEDIR})
# Public headers of the exported libraries (every include/ dir of theirs in the source tree).
foreach(t ${_hoist_exported})
  get_target_property(_src ${t} SOURCE_DIR)
  if(EXISTS ${_src}/include/hoist)
    install(DIRECTORY ${_src}/include/hoist/ DESTINATION ${CMAKE_INSTALL_INCLUDEDIR}/hoist COMPONENT dev
            FILES_MATCHING PATTERN "*.hpp" PATTERN "*.h")
  endif()
endforeach()
install(EXPORT hoistTargets NAMESPACE hoist:: DESTINATION ${HOIST_CMAKE_DIR} COMPONENT dev)
configure_package_config_file(${PROJECT_SOURCE_DIR}/cmake/hoistConfig.cmake.in
                              ${CMAKE_BINARY_DIR}/install/hoistConfig.cmake
                              INSTALL_DESTINATION ${HOIST_CMAKE_DIR})
write_basic_package_version_file(${CMAKE_BINARY_DIR}/install/hoistConfigVersion.cmake
                                 VERSION ${PROJECT_VERSION} COMPATIBILITY SameMinorVersion)
install(FILES ${CMAKE_BINARY_DIR}/install/hoistConfig.cmake ${CMAKE_BINARY_DIR}/install/hoistConfigVersion.cmake
        DESTINATION ${HOIST_CMAKE_DIR} COMPONENT dev)

# ---- the Debian package: cpack -G DEB ---------------------------------------------------
set(CPACK_PACKAGE_NAME "hoist-twin")
set(CPACK_PACKAGE_VENDOR "hoist-twin project")
set(CPACK_PACKAGE_CONTACT "hoist-twin maintainers <hoist-twin@localhost>")
set(CPACK_PACKAGE_VERSION ${PROJECT_VERSION})
set(CPACK_PACKAGE_DESCRIPTION_SUMMARY "real-time digital twin of a cable-guided mine-shaft hoist (advisory)")
string(CONCAT CPACK_PACKAGE_DESCRIPTION
    "hoist-twind follows the winder's speed over LCM with the Wang et al. (2016) vibration model\n"
    "and publishes the cage's sway, tilt, guide-sleeve forces and clearance alarms.  One systemd\n"
    "instance per shaft (hoist-twind@<shaft>.service).  Advisory only: never the shaft's protection.")
set(CPACK_GENERATOR "DEB")
# install() runs with the package's prefix (/usr, whatever CMAKE_INSTALL_PREFIX
# is) under a staging DESTDIR, so the unit written at install time names /usr/bin.
set(CPACK_SET_DESTDIR ON)
set(CPACK_INSTALL_PREFIX "/usr")
set(CPACK_PACKAGING_INSTALL_PREFIX "/usr")
set(CPACK_DEBIAN_FILE_NAME DEB-DEFAULT)
set(CPACK_DEBIAN_PACKAGE_SECTION "science")
set(CPACK_DEBIAN_PACKAGE_SHLIBDEPS ON)  # Depends: from the programs' shared libraries (dpkg-shlibdeps)
# lcm-spy (hoist-lcm-spy) needs a JRE and the two jars; find_package(hoist) the -dev packages.
set(CPACK_DEBIAN_PACKAGE_RECOMMENDS "liblcm-java, libjchart2d-java, default-jre-headless | java-runtime-headless")
set(CPACK_DEBIAN_PACKAGE_SUGGESTS
    "liblcm-dev, libeigen3-dev, libtomlplusplus-dev, pkg-config, liblcm-bin, python3")
set(CPACK_DEBIAN_PACKAGE_HOMEPAGE "https://example.invalid/hoist-twin")
# /etc/hoist-twin/example.toml is a conffile; systemd re-reads its units.
configure_file(${PROJECT_SOURCE_DIR}/cmake/debian/conffiles.in ${CMAKE_BINARY_DIR}/debian/conffiles @ONLY)
configure_file(${PROJECT_SOURCE_DIR}/cmake/debian/postinst ${CMAKE_BINARY_DIR}/debian/postinst COPYONLY
               FILE_PERMISSIONS OWNER_READ OWNER_WRITE OWNER_EXECUTE GROUP_READ GROUP_EXECUTE WORLD_READ WORLD_EXECUTE)
configure_file(${PROJECT_SOURCE_DIR}/cmake/debian/postrm ${CMAKE_BINARY_DIR}/debian/postrm COPYONLY
               FILE_PERMISSIONS OWNER_READ OWNER_WRITE OWNER_EXECUTE GROUP_READ GROUP_EXECUTE WORLD_READ WORLD_EXECUTE)
set(CPACK_DEBIAN_PACKAGE_CONTROL_EXTRA
    "${CMAKE_BINARY_DIR}/debian/conffiles;${CMAKE_BINARY_DIR}/debian/postinst;${CMAKE_BINARY_DIR}/debian/postrm")
set(CPACK_DEBIAN_PACKAGE_CONTROL_STRICT_PERMISSION ON)
include(CPack)
