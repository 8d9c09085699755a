# hoist_version: an INTERFACE library giving <hoist/version.hpp> (see
# cmake/write_version.cmake).  Every program links it and prints
#   <program> <hoist::kVersionString>
# for --version.
set(_hv_out ${CMAKE_BINARY_DIR}/generated/hoist/version.hpp)
set(_hv_args -DSRC=${PROJECT_SOURCE_DIR} -DIN=${PROJECT_SOURCE_DIR}/cmake/version.hpp.in
             -DOUT=${_hv_out} -DHOIST_VERSION=${PROJECT_VERSION})
file(MAKE_DIRECTORY ${CMAKE_BINARY_DIR}/generated/hoist)
execute_process(COMMAND ${CMAKE_COMMAND} ${_hv_args} -P ${PROJECT_SOURCE_DIR}/cmake/write_version.cmake)
# The same string for configure-time files (scripts such as hoist-lcm-spy):
file(STRINGS ${_hv_out} _hv_line REGEX "kVersionString")
string(REGEX REPLACE ".*kVersionString\\[\\] = \"([^\"]*)\".*" "\\1" HOIST_VERSION_STRING "${_hv_line}")
add_custom_target(hoist_version_header
  COMMAND ${CMAKE_COMMAND} ${_hv_args} -P ${PROJECT_SOURCE_DIR}/cmake/write_version.cmake
  BYPRODUCTS ${_hv_out}
  COMMENT "version header (project version + git commit)"
  VERBATIM)
add_library(hoist_version INTERFACE)
add_dependencies(hoist_version hoist_version_header)
target_include_directories(hoist_version INTERFACE $<BUILD_INTERFACE:${CMAKE_BINARY_DIR}/generated>)

# Link every program that exists to it (one place, whatever directory defines
# the program).  Called at the end of the top-level CMakeLists.txt.
function(hoist_link_version)
  foreach(t ${ARGN})
    if(TARGET ${t})
      target_link_libraries(${t} PRIVATE hoist_version)
    endif()
  endforeach()
endfunction()
