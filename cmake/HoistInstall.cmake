# Installation, the exported CMake package and the Debian package.
#
#   cmake --install build [--prefix /usr]            # or: DESTDIR=/scratch cmake --install build --prefix /usr
#   (cd build && cpack -G DEB)                        # build/hoist-twin_<version>_<arch>.deb and hoist-twin-dev_...
#
# Two packages: hoist-twin (component "runtime", and "Unspecified" for the
# install() calls of subdirectories that name none) and hoist-twin-dev
# (component "dev": headers, static libraries, the CMake package, the .lcm
# files).  Programs are stripped; with a build type that has debug
# information (RelWithDebInfo, Debug) the symbols go to hoist-twin-dbgsym.
#
# What goes where (prefix P, /usr for the .deb):
#   P/bin/                      the programs (hoist-twind, hoist-sim, ..., hoist-lcm-spy)
#   /etc/hoist-twin/example.toml  the commented shaft template (a conffile; HOIST_CONFIG_DIR)
#   /etc/hoist-twin/mqtt/example.toml  the MQTT bridge's template (a conffile); /etc/hoist-twin/dash/
#   P/lib/systemd/system/       hoist-twind@, hoist-mqtt@, hoist-dash@.service (paths filled in at install time)
#   P/share/man/man1/           man pages made from each program's --help (help2man, when installed)
#   P/share/hoist-twin/lcm/     the .lcm message definitions
#   P/include/hoist/            model headers, generated C++ message headers, hoist/io, hoist/bus
#   P/lib/<multiarch>/          libhoist_model.a, libhoist_io.a
#   P/lib/<multiarch>/cmake/hoist/  hoistConfig.cmake: find_package(hoist) -> hoist::model, hoist::io, hoist::msgs
#   P/share/java/hoist-msgs.jar the Java message classes (lcm-spy, Java clients)
#   P/share/doc/hoist-twin/     README, CHANGELOG, docs/, examples (demo.toml, read_twin.py)
#   P/share/hoist-twin/dash/web the dashboard's web files, when tools/dash/web exists
#   P/lib/python3/dist-packages/hoist  the Python module (python/CMakeLists.txt), when HOIST_PYTHON
include(GNUInstallDirs)
include(CMakePackageConfigHelpers)

set(HOIST_CONFIG_DIR "/etc/hoist-twin" CACHE PATH
    "Directory of the shaft configurations read by hoist-twind@<instance>.service (absolute)")
set(HOIST_SYSTEMD_UNIT_DIR "lib/systemd/system" CACHE STRING
    "Where the systemd unit is installed, relative to the install prefix")
set(HOIST_DOC_SUBDIR "${CMAKE_INSTALL_DATAROOTDIR}/doc/hoist-twin")
set(HOIST_CMAKE_DIR "${CMAKE_INSTALL_LIBDIR}/cmake/hoist")

# ---- programs -------------------------------------------------------------------
set(_hoist_programs hoist-sim hoist-estimate hoist-study hoist-twind hoist-replay hoist-log2csv hoist-monitor
                    hoist-alarm-ack hoist-wakeup-latency hoist-timing-test hoist-mqtt hoist-trips)
foreach(p ${_hoist_programs})
  if(TARGET ${p})
    install(TARGETS ${p} RUNTIME DESTINATION ${CMAKE_INSTALL_BINDIR} COMPONENT runtime)
  endif()
endforeach()
if(TARGET hoist_msgs_java)
  # The wrapper finds lcm.jar, jchart2d.jar and ../share/java/hoist_msgs.jar itself.
  install(PROGRAMS ${CMAKE_RUNTIME_OUTPUT_DIRECTORY}/hoist-lcm-spy DESTINATION ${CMAKE_INSTALL_BINDIR}
          COMPONENT runtime)
  # Java policy 2.4 (lintian bad-jar-name): the jar is NAME-VERSION.jar, no '_',
  # with the unversioned NAME.jar a relative symlink to it (what the wrapper
  # and Java clients name).
  install(FILES ${CMAKE_BINARY_DIR}/msgs/hoist_msgs.jar DESTINATION ${CMAKE_INSTALL_DATAROOTDIR}/java
          RENAME hoist-msgs-${PROJECT_VERSION}.jar COMPONENT runtime)
  file(CREATE_LINK hoist-msgs-${PROJECT_VERSION}.jar ${CMAKE_BINARY_DIR}/msgs/hoist-msgs.jar SYMBOLIC)
  install(FILES ${CMAKE_BINARY_DIR}/msgs/hoist-msgs.jar DESTINATION ${CMAKE_INSTALL_DATAROOTDIR}/java
          COMPONENT runtime)
endif()

# ---- LCM types: definitions and generated C++ headers -------------------------------
file(GLOB _hoist_lcm_files ${PROJECT_SOURCE_DIR}/msgs/*.lcm)
install(FILES ${_hoist_lcm_files} DESTINATION ${CMAKE_INSTALL_DATAROOTDIR}/hoist-twin/lcm COMPONENT dev)
install(DIRECTORY ${CMAKE_BINARY_DIR}/msgs/generated/hoist/ DESTINATION ${CMAKE_INSTALL_INCLUDEDIR}/hoist
        COMPONENT dev FILES_MATCHING PATTERN "*.hpp")
# hoist::lcm's generated channel names (msgs/codec: from the `// @channel` annotations).
install(FILES ${HOIST_BUS_GEN_INCLUDE}/hoist/bus/channels.hpp DESTINATION ${CMAKE_INSTALL_INCLUDEDIR}/hoist/bus
        COMPONENT dev)

# ---- configuration, unit, docs ----------------------------------------------------
install(FILES ${PROJECT_SOURCE_DIR}/service/config/example.toml DESTINATION ${HOIST_CONFIG_DIR} COMPONENT runtime)
# The unit names the installed program and config paths: filled in at install
# time, so `--prefix` and cpack (prefix /usr) both get the right ExecStart.
install(CODE "
  set(HOIST_BIN_DIR \"\${CMAKE_INSTALL_PREFIX}/${CMAKE_INSTALL_BINDIR}\")
  set(HOIST_CONFIG_DIR \"${HOIST_CONFIG_DIR}\")
  set(HOIST_DOC_DIR \"\${CMAKE_INSTALL_PREFIX}/${HOIST_DOC_SUBDIR}\")
  foreach(unit hoist-twind@.service hoist-mqtt@.service hoist-dash@.service)
    configure_file(\"${PROJECT_SOURCE_DIR}/service/systemd/\${unit}.in\"
                   \"${CMAKE_BINARY_DIR}/install/\${unit}\" @ONLY)
    file(INSTALL \"${CMAKE_BINARY_DIR}/install/\${unit}\"
         DESTINATION \"\${CMAKE_INSTALL_PREFIX}/${HOIST_SYSTEMD_UNIT_DIR}\")
  endforeach()
" COMPONENT runtime)
# The MQTT bridge's template where hoist-mqtt@.service says (copy it to
# /etc/hoist-twin/mqtt/<instance>.toml), and the dashboard's env directory.
install(FILES ${PROJECT_SOURCE_DIR}/tools/mqtt/config/example.toml DESTINATION ${HOIST_CONFIG_DIR}/mqtt
        COMPONENT runtime)
install(DIRECTORY DESTINATION ${HOIST_CONFIG_DIR}/dash COMPONENT runtime)
install(FILES ${PROJECT_SOURCE_DIR}/README.md ${PROJECT_SOURCE_DIR}/CHANGELOG.md DESTINATION ${HOIST_DOC_SUBDIR} COMPONENT runtime)
# Debian: copyright and changelog in each package's doc directory.
configure_file(${PROJECT_SOURCE_DIR}/cmake/debian/changelog.in ${CMAKE_BINARY_DIR}/debian/changelog @ONLY)
execute_process(COMMAND gzip -9nf ${CMAKE_BINARY_DIR}/debian/changelog)
foreach(pair "hoist-twin:runtime" "hoist-twin-dev:dev")
  string(REPLACE ":" ";" pair "${pair}")
  list(GET pair 0 _pkg)
  list(GET pair 1 _comp)
  install(FILES ${PROJECT_SOURCE_DIR}/cmake/debian/copyright ${CMAKE_BINARY_DIR}/debian/changelog.gz
          DESTINATION ${CMAKE_INSTALL_DATAROOTDIR}/doc/${_pkg} COMPONENT ${_comp})
endforeach()

# ---- man pages: help2man from each program's --help and --version -------------------
find_program(HOIST_HELP2MAN help2man)
if(HOIST_HELP2MAN)
  set(_hoist_man "")
  foreach(p ${_hoist_programs} hoist-dash)
    if(TARGET ${p})
      set(_out ${CMAKE_BINARY_DIR}/man/${p}.1)
      add_custom_command(
        OUTPUT ${_out}.gz
        COMMAND ${CMAKE_COMMAND} -E make_directory ${CMAKE_BINARY_DIR}/man
        COMMAND ${HOIST_HELP2MAN} --no-info --no-discard-stderr --section=1
                "--name=${p}, part of hoist-twin (digital twin of a mine-shaft hoist)" --output=${_out} $<TARGET_FILE:${p}>
        COMMAND gzip -9nf ${_out}
        DEPENDS ${p} VERBATIM)
      list(APPEND _hoist_man ${_out}.gz)
    endif()
  endforeach()
  if(TARGET hoist_msgs_java)  # hoist-lcm-spy: a script generated with the Java classes
    set(_out ${CMAKE_BINARY_DIR}/man/hoist-lcm-spy.1)
    add_custom_command(
      OUTPUT ${_out}.gz
      COMMAND ${CMAKE_COMMAND} -E make_directory ${CMAKE_BINARY_DIR}/man
      COMMAND ${HOIST_HELP2MAN} --no-info --no-discard-stderr --section=1
              "--name=hoist-lcm-spy, part of hoist-twin (digital twin of a mine-shaft hoist)" --output=${_out}
              ${CMAKE_RUNTIME_OUTPUT_DIRECTORY}/hoist-lcm-spy
      COMMAND gzip -9nf ${_out}
      DEPENDS hoist_msgs_java VERBATIM)
    list(APPEND _hoist_man ${_out}.gz)
  endif()
  add_custom_target(hoist_man ALL DEPENDS ${_hoist_man})
  install(FILES ${_hoist_man} DESTINATION ${CMAKE_INSTALL_MANDIR}/man1 COMPONENT runtime)
else()
  message(STATUS "help2man not found: no man pages (apt-get install help2man)")
endif()
install(DIRECTORY ${PROJECT_SOURCE_DIR}/docs/ DESTINATION ${HOIST_DOC_SUBDIR}/docs COMPONENT runtime
        PATTERN ".gitignore" EXCLUDE PATTERN "*.json" EXCLUDE PATTERN "*.log" EXCLUDE PATTERN "*.csv" EXCLUDE PATTERN "*.gp" EXCLUDE)
install(FILES ${PROJECT_SOURCE_DIR}/service/config/demo.toml ${PROJECT_SOURCE_DIR}/service/config/example.toml
        DESTINATION ${HOIST_DOC_SUBDIR}/examples COMPONENT runtime)
install(FILES ${PROJECT_SOURCE_DIR}/tools/mqtt/config/example.toml DESTINATION ${HOIST_DOC_SUBDIR}/examples
        RENAME mqtt.toml COMPONENT runtime)
install(FILES ${PROJECT_SOURCE_DIR}/tools/mqtt/config/mosquitto.conf ${PROJECT_SOURCE_DIR}/tools/mqtt/config/mosquitto-acl.conf
        DESTINATION ${HOIST_DOC_SUBDIR}/examples/mosquitto COMPONENT runtime)
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
set(CPACK_PACKAGE_CONTACT "hoist-twin maintainers <maintainers@hoist-twin.example.org>")
set(CPACK_PACKAGE_VERSION ${PROJECT_VERSION})
set(CPACK_PACKAGE_DESCRIPTION_SUMMARY "real-time digital twin of a cable-guided mine-shaft hoist (advisory)")
string(CONCAT CPACK_PACKAGE_DESCRIPTION
    "hoist-twind follows the winder's speed over LCM with the Wang et al. (2016)\n"
    "vibration model and publishes the cage's sway, tilt, guide-sleeve forces and\n"
    "clearance alarms.  One systemd instance per shaft (hoist-twind@<shaft>), with\n"
    "an MQTT bridge and a dashboard.  Advisory only: never the shaft's protection.")
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
if(HOIST_PYTHON)
  # import hoist (python/): the system's python3 and numpy.
  string(APPEND CPACK_DEBIAN_PACKAGE_RECOMMENDS ", python3, python3-numpy")
endif()
set(CPACK_DEBIAN_PACKAGE_SUGGESTS
    "liblcm-dev, libeigen3-dev, libtomlplusplus-dev, pkg-config, liblcm-bin, python3")
set(CPACK_DEBIAN_PACKAGE_HOMEPAGE "https://example.invalid/hoist-twin")
# /etc/hoist-twin/example.toml is a conffile; systemd re-reads its units.
configure_file(${PROJECT_SOURCE_DIR}/cmake/debian/conffiles.in ${CMAKE_BINARY_DIR}/debian/conffiles @ONLY)
configure_file(${PROJECT_SOURCE_DIR}/cmake/debian/postinst ${CMAKE_BINARY_DIR}/debian/postinst COPYONLY
               FILE_PERMISSIONS OWNER_READ OWNER_WRITE OWNER_EXECUTE GROUP_READ GROUP_EXECUTE WORLD_READ WORLD_EXECUTE)
configure_file(${PROJECT_SOURCE_DIR}/cmake/debian/postrm ${CMAKE_BINARY_DIR}/debian/postrm COPYONLY
               FILE_PERMISSIONS OWNER_READ OWNER_WRITE OWNER_EXECUTE GROUP_READ GROUP_EXECUTE WORLD_READ WORLD_EXECUTE)
configure_file(${PROJECT_SOURCE_DIR}/cmake/debian/prerm ${CMAKE_BINARY_DIR}/debian/prerm COPYONLY
               FILE_PERMISSIONS OWNER_READ OWNER_WRITE OWNER_EXECUTE GROUP_READ GROUP_EXECUTE WORLD_READ WORLD_EXECUTE)
set(CPACK_DEBIAN_PACKAGE_CONTROL_STRICT_PERMISSION ON)

# Components -> packages: runtime (+ Unspecified) -> hoist-twin, dev -> hoist-twin-dev.
set(CPACK_DEB_COMPONENT_INSTALL ON)
set(CPACK_COMPONENTS_GROUPING ONE_PER_GROUP)
set(CPACK_COMPONENTS_ALL runtime Unspecified dev)
set(CPACK_DEBIAN_RUNTIME_PACKAGE_NAME "hoist-twin")
set(CPACK_DEBIAN_RUNTIME_FILE_NAME DEB-DEFAULT)
set(CPACK_DEBIAN_RUNTIME_PACKAGE_SECTION "science")
set(CPACK_DEBIAN_RUNTIME_PACKAGE_CONTROL_EXTRA
    "${CMAKE_BINARY_DIR}/debian/conffiles;${CMAKE_BINARY_DIR}/debian/postinst;${CMAKE_BINARY_DIR}/debian/prerm;${CMAKE_BINARY_DIR}/debian/postrm")
set(CPACK_DEBIAN_DEV_PACKAGE_NAME "hoist-twin-dev")
set(CPACK_DEBIAN_DEV_FILE_NAME DEB-DEFAULT)
set(CPACK_DEBIAN_DEV_PACKAGE_SECTION "libdevel")
set(CPACK_DEBIAN_DEV_PACKAGE_DEPENDS "hoist-twin (= ${PROJECT_VERSION}), liblcm-dev, libeigen3-dev, libtomlplusplus-dev")
set(CPACK_DEBIAN_DEV_PACKAGE_SHLIBDEPS OFF)
string(CONCAT CPACK_DEBIAN_DEV_DESCRIPTION
    "Development files of hoist-twin: the C++20 headers of the hoist model, the\n"
    "generated LCM message types, hoist/io and hoist/bus, libhoist_model.a and\n"
    "libhoist_io.a, and the CMake package (find_package(hoist): hoist::model,\n"
    "hoist::io, hoist::msgs).")
set(CPACK_DEBIAN_RUNTIME_DESCRIPTION "${CPACK_PACKAGE_DESCRIPTION}")
set(CPACK_STRIP_FILES ON)
if(CMAKE_BUILD_TYPE MATCHES "^(RelWithDebInfo|Debug)$")
  set(CPACK_DEBIAN_DEBUGINFO_PACKAGE ON)  # hoist-twin-dbgsym: the symbols stripped from the programs
endif()
include(CPack)
cpack_add_component_group(runtime)
cpack_add_component_group(dev)
cpack_add_component(runtime GROUP runtime)
cpack_add_component(Unspecified GROUP runtime)
cpack_add_component(dev GROUP dev)
