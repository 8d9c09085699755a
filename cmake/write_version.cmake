# Writes the version header (cmake -P; run at configure time and at every
# build by the hoist_version_header target): the project version plus, in a
# git checkout, the commit and whether the tree has uncommitted changes.  The
# header is rewritten only when its text changes, so a build without a new
# commit recompiles nothing.
#   -DSRC=<source dir> -DIN=<template> -DOUT=<header> -DHOIST_VERSION=<x.y.z>
set(HOIST_GIT_HASH "")
find_program(_git git)
if(_git AND EXISTS "${SRC}/.git")
  execute_process(COMMAND ${_git} -C "${SRC}" rev-parse --short=10 HEAD
                  OUTPUT_VARIABLE HOIST_GIT_HASH OUTPUT_STRIP_TRAILING_WHITESPACE
                  RESULT_VARIABLE _rc ERROR_QUIET)
  if(NOT _rc EQUAL 0)
    set(HOIST_GIT_HASH "")
  else()
    execute_process(COMMAND ${_git} -C "${SRC}" diff --quiet HEAD -- RESULT_VARIABLE _dirty ERROR_QUIET)
    if(_dirty EQUAL 1)
      set(HOIST_GIT_HASH "${HOIST_GIT_HASH}-modified")
    endif()
  endif()
endif()
if(HOIST_GIT_HASH)
  set(HOIST_VERSION_STRING "${HOIST_VERSION} (git ${HOIST_GIT_HASH})")
else()
  set(HOIST_VERSION_STRING "${HOIST_VERSION}")
endif()
configure_file("${IN}" "${OUT}.new" @ONLY)
execute_process(COMMAND ${CMAKE_COMMAND} -E copy_if_different "${OUT}.new" "${OUT}")
file(REMOVE "${OUT}.new")
