# check_layers.cmake -- the layer rules of docs/architecture.md ("The rules,
# and which are checked"), run as a CTest test (tests/layers/CMakeLists.txt):
#   1. hoist_model links nothing but Eigen (MODEL_LINKS: its LINK_LIBRARIES and
#      INTERFACE_LINK_LIBRARIES, '|'-separated, read at configure time);
#   2. nothing under service/ or io/ includes a header from tools/: no include
#      path naming tools/, and no include that resolves only to a header under
#      tools/ (e.g. "hoist/study/sweep.hpp" or "timing_report.hpp");
#   3. nothing under tools/, msgs/ or rt/ includes a header from service/: no
#      include path into service/ ("../../service/app/daemon.hpp"), and no
#      include that resolves only to a header under service/ (e.g.
#      "hoist/service/core/alarms.hpp", from any library folder service/<lib>/include,
#      or "shaft_twin.hpp").  What the tools share with the daemon is the
#      contract in msgs/contract;
#   4. msgs/, rt/ and history/ include nothing from tools/ either (as rule 2),
#      and history/ nothing from service/ (as rule 3);
#   5. no tool includes "hoist/bus/udpm_receiver.hpp" itself: the choice
#      between our udpm receive path and LCM's is made once, by
#      hoist::bus::Subscriber ("hoist/bus/subscriber.hpp");
#   6. service's own libraries follow their links (core <- cfg, core <-
#      twin <- lcm <- app): each includes the hoist/service/ headers of
#      itself and of what it links, none of service/app, and core and twin
#      nothing of LCM (hoist/bus/, hoist/msg/, <lcm/...>, hoist/<type>_t.hpp);
#   7. in service/, include path = folder = namespace: a public header of
#      service/<lib> is include/hoist/service/<lib>/<name>.hpp, and every
#      file of service/<lib> (and of service/app) opens its namespace as
#      hoist::service::<lib> (`inline`: service's code names the other
#      libraries' types unqualified; the qualified name says the folder).
# Also: model/ includes only its own headers and system/Eigen headers.
#   cmake -DROOT=<source dir> -DMODEL_LINKS='Eigen3::Eigen' -P check_layers.cmake
# Prints "LAYER VIOLATION: ..." for each broken rule and fails.
cmake_minimum_required(VERSION 3.20)
if(NOT DEFINED ROOT OR NOT IS_DIRECTORY "${ROOT}")
  message(FATAL_ERROR "check_layers: -DROOT=<source dir> is required")
endif()
set(_violations 0)
macro(_violation msg)
  message("LAYER VIOLATION: ${msg}")
  math(EXPR _violations "${_violations} + 1")
endmacro()

# ---- rule 1: hoist_model links Eigen only --------------------------------
string(REPLACE "|" ";" _links "${MODEL_LINKS}")
foreach(l IN LISTS _links)
  # $<LINK_ONLY:X> and similar wrappers: judge the target inside.
  string(REGEX REPLACE "^\\$<[A-Z_]+:(.*)>$" "\\1" l "${l}")
  if(l STREQUAL "" OR l MATCHES "^Eigen3::Eigen$")
    continue()
  endif()
  _violation("hoist_model links '${l}' (only Eigen3::Eigen is allowed)")
endforeach()

# ---- the headers of tools/, by every name they can be included as ----------
file(GLOB_RECURSE _tool_headers LIST_DIRECTORIES false RELATIVE "${ROOT}/tools"
     "${ROOT}/tools/*.hpp" "${ROOT}/tools/*.h")
set(_tool_names "")
foreach(h IN LISTS _tool_headers)
  get_filename_component(_name "${h}" NAME)
  list(APPEND _tool_names "${_name}")
  if(h MATCHES "^[^/]+/include/(.+)$")          # tools/<x>/include/hoist/...
    list(APPEND _tool_names "${CMAKE_MATCH_1}")
  endif()
  if(h MATCHES "^[^/]+/(.+)$")                  # relative to tools/<x>/
    list(APPEND _tool_names "${CMAKE_MATCH_1}")
  endif()
endforeach()
list(REMOVE_DUPLICATES _tool_names)

# Include directories a service/ or io/ file may legitimately reach.
file(GLOB _service_incs LIST_DIRECTORIES true "${ROOT}/service/*/include")  # one per library of service/
file(GLOB _msgs_incs LIST_DIRECTORIES true "${ROOT}/msgs/*/include")  # msgs/contract, msgs/udpm
set(_allowed_dirs "${ROOT}/model/include" "${ROOT}/io/include" "${ROOT}/history/include" "${ROOT}/msgs/include" ${_msgs_incs}
                  "${ROOT}/rt/include" "${ROOT}/service/include" ${_service_incs} "${ROOT}/service/app")

function(_includes file out)
  file(STRINGS "${file}" _lines REGEX "^[ \t]*#[ \t]*include[ \t]*[<\"]")
  set(_incs "")
  foreach(line IN LISTS _lines)
    if(line MATCHES "^[ \t]*#[ \t]*include[ \t]*[<\"]([^>\"]+)[>\"]")
      list(APPEND _incs "${CMAKE_MATCH_1}")
    endif()
  endforeach()
  set(${out} "${_incs}" PARENT_SCOPE)
endfunction()

# ---- rules 2 and 4: service/, io/, msgs/ and rt/ include nothing from tools/ --
foreach(layer service io history msgs rt)
  file(GLOB_RECURSE _files LIST_DIRECTORIES false "${ROOT}/${layer}/*.hpp" "${ROOT}/${layer}/*.h"
       "${ROOT}/${layer}/*.cpp")
  foreach(f IN LISTS _files)
    file(RELATIVE_PATH _rel "${ROOT}" "${f}")
    get_filename_component(_dir "${f}" DIRECTORY)
    _includes("${f}" _incs)
    foreach(inc IN LISTS _incs)
      if(inc MATCHES "(^|/)tools/")
        _violation("${_rel} includes \"${inc}\" (a path into tools/)")
        continue()
      endif()
      if(NOT inc IN_LIST _tool_names)
        continue()
      endif()
      set(_found FALSE)
      foreach(d IN LISTS _allowed_dirs _dir)
        if(EXISTS "${d}/${inc}")
          set(_found TRUE)
        endif()
      endforeach()
      if(NOT _found)
        _violation("${_rel} includes \"${inc}\", a header of tools/")
      endif()
    endforeach()
  endforeach()
endforeach()

# ---- rule 3: tools/, msgs/ and rt/ include nothing from service/ ------------
file(GLOB_RECURSE _svc_headers LIST_DIRECTORIES false RELATIVE "${ROOT}/service"
     "${ROOT}/service/*.hpp" "${ROOT}/service/*.h")
set(_svc_names "")
foreach(h IN LISTS _svc_headers)
  get_filename_component(_name "${h}" NAME)
  list(APPEND _svc_names "${_name}")
  if(h MATCHES "^([^/]+/)?include/(.+)$")       # service/<lib>/include/hoist/service/...
    list(APPEND _svc_names "${CMAKE_MATCH_2}")
  endif()
  if(h MATCHES "^[^/]+/(.+)$")                  # relative to service/<x>/
    list(APPEND _svc_names "${CMAKE_MATCH_1}")
  endif()
endforeach()
list(REMOVE_DUPLICATES _svc_names)
# Include directories a tools/ file may legitimately reach: every layer's
# include folder except service's, and the tools' own folders.
file(GLOB _tool_dirs LIST_DIRECTORIES true "${ROOT}/*/include" "${ROOT}/msgs/*/include" "${ROOT}/tools/*"
     "${ROOT}/tools/*/include" "${ROOT}/tools/*/src")
list(FILTER _tool_dirs EXCLUDE REGEX "^${ROOT}/service/")
file(GLOB_RECURSE _files LIST_DIRECTORIES false "${ROOT}/tools/*.hpp" "${ROOT}/tools/*.h" "${ROOT}/tools/*.cpp"
     "${ROOT}/msgs/*.hpp" "${ROOT}/msgs/*.h" "${ROOT}/msgs/*.cpp" "${ROOT}/rt/*.hpp" "${ROOT}/rt/*.h" "${ROOT}/rt/*.cpp"
     "${ROOT}/history/*.hpp" "${ROOT}/history/*.cpp")
foreach(f IN LISTS _files)
  file(RELATIVE_PATH _rel "${ROOT}" "${f}")
  get_filename_component(_dir "${f}" DIRECTORY)
  _includes("${f}" _incs)
  foreach(inc IN LISTS _incs)
    # rule 5: the receive path is chosen in one place
    if(_rel MATCHES "^tools/" AND inc STREQUAL "hoist/bus/udpm_receiver.hpp")
      _violation("${_rel} includes \"${inc}\": a tool takes its receive path from hoist/bus/subscriber.hpp")
    endif()
    if(inc MATCHES "(^|\\.\\./)service/")
      _violation("${_rel} includes \"${inc}\" (a path into service/)")
      continue()
    endif()
    if(NOT inc IN_LIST _svc_names)
      continue()
    endif()
    set(_found FALSE)
    foreach(d IN LISTS _tool_dirs _dir)
      if(EXISTS "${d}/${inc}")
        set(_found TRUE)
      endif()
    endforeach()
    if(NOT _found)
      _violation("${_rel} includes \"${inc}\", a header of service/")
    endif()
  endforeach()
endforeach()

# ---- rule 6: service's own libraries ----------------------------------------
# service/CMakeLists.txt links core <- cfg, core <- twin <- lcm <- app: a
# library includes the hoist/service/ headers of itself and of the
# libraries it links, never a header of service/app; and core and twin (the
# model's shell: "the math knows nothing of LCM") include nothing of LCM:
# no hoist/bus/, hoist/msg/ or <lcm/...>, no generated hoist/<type>_t.hpp.
set(_svc_libs core cfg twin lcm)
set(_svc_may_core core)
set(_svc_may_cfg core cfg)
set(_svc_may_twin core twin)
set(_svc_may_lcm core twin lcm)
file(GLOB _app_headers LIST_DIRECTORIES false RELATIVE "${ROOT}/service/app" "${ROOT}/service/app/*.hpp")
foreach(lib IN LISTS _svc_libs)
  file(GLOB_RECURSE _files LIST_DIRECTORIES false "${ROOT}/service/${lib}/*.hpp" "${ROOT}/service/${lib}/*.cpp")
  foreach(f IN LISTS _files)
    file(RELATIVE_PATH _rel "${ROOT}" "${f}")
    get_filename_component(_dir "${f}" DIRECTORY)
    _includes("${f}" _incs)
    foreach(inc IN LISTS _incs)
      if(inc MATCHES "^hoist/service/")
        foreach(owner IN LISTS _svc_libs)
          if(EXISTS "${ROOT}/service/${owner}/include/${inc}" AND NOT owner IN_LIST _svc_may_${lib})
            string(REPLACE ";" ", " _may "${_svc_may_${lib}}")
            _violation("${_rel} includes \"${inc}\" of service/${owner} (service/${lib} may include service/{${_may}})")
          endif()
        endforeach()
      endif()
      if(inc IN_LIST _app_headers AND NOT EXISTS "${_dir}/${inc}")
        _violation("${_rel} includes \"${inc}\", a header of service/app")
      endif()
      if(lib MATCHES "^(core|twin)$" AND inc MATCHES "^(hoist/bus/|hoist/msg/|lcm/|hoist/[a-z0-9_]+_t\\.hpp$)")
        _violation("${_rel} includes \"${inc}\": service/${lib} knows nothing of LCM")
      endif()
    endforeach()
  endforeach()
endforeach()

# ---- rule 7: include path = folder = namespace in service/ -----------------
foreach(lib IN LISTS _svc_libs ITEMS app)
  file(GLOB_RECURSE _files LIST_DIRECTORIES false "${ROOT}/service/${lib}/*.hpp" "${ROOT}/service/${lib}/*.cpp")
  foreach(f IN LISTS _files)
    file(RELATIVE_PATH _rel "${ROOT}" "${f}")
    if(_rel MATCHES "^service/${lib}/include/" AND NOT _rel MATCHES "^service/${lib}/include/hoist/service/${lib}/")
      _violation("${_rel}: a public header of service/${lib} belongs in include/hoist/service/${lib}/")
    endif()
    file(STRINGS "${f}" _opens REGEX "^namespace hoist[:a-z_ ]*\{")
    foreach(line IN LISTS _opens)
      if(NOT line MATCHES "^namespace hoist::service::(inline )?${lib} \\{")
        string(REGEX REPLACE " *\\{.*" "" line "${line}")
        _violation("${_rel} opens \"${line}\": service/${lib}'s namespace is hoist::service::${lib}")
      endif()
    endforeach()
  endforeach()
endforeach()

# ---- model/ includes only itself (and Eigen / the standard library) --------
file(GLOB_RECURSE _files LIST_DIRECTORIES false "${ROOT}/model/*.hpp" "${ROOT}/model/*.cpp")
foreach(f IN LISTS _files)
  file(RELATIVE_PATH _rel "${ROOT}" "${f}")
  get_filename_component(_dir "${f}" DIRECTORY)
  _includes("${f}" _incs)
  foreach(inc IN LISTS _incs)
    if(inc MATCHES "^hoist/" AND NOT EXISTS "${ROOT}/model/include/${inc}" AND NOT EXISTS "${_dir}/${inc}")
      _violation("${_rel} includes \"${inc}\", which is not a model header")
    endif()
  endforeach()
endforeach()

if(_violations GREATER 0)
  message(FATAL_ERROR "check_layers: ${_violations} layer violation(s); see README.md, Development")
endif()
message("check_layers: OK (hoist_model links: ${MODEL_LINKS}; no tools/ header in service/, io/, msgs/ or rt/; "
        "no service/ header in tools/, msgs/ or rt/; tools receive through hoist/bus/subscriber.hpp; "
        "service's libraries follow their links, core and twin free of LCM; service's include paths and "
        "namespaces say the folder)")
