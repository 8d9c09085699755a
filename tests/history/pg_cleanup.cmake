# pg_cleanup.cmake -- CTest fixture cleanup after the postgres tests: stops
# and removes every test server still listed in WORK/pg-servers/ (a test that
# crashed or was killed by ctest's timeout never ran PgServer's destructor).
#   cmake -DWORK=<tests work dir> -P pg_cleanup.cmake
file(GLOB _listed "${WORK}/pg-servers/hoist-pg-*")
foreach(f IN LISTS _listed)
  file(STRINGS "${f}" _dir LIMIT_COUNT 1)
  if(_dir MATCHES "^/tmp/hoist-pg-[A-Za-z0-9]+$" AND EXISTS "${_dir}/data/postmaster.pid")
    file(GLOB _ctl "/usr/lib/postgresql/*/bin/pg_ctl")
    list(GET _ctl -1 _ctl)
    execute_process(COMMAND id -u OUTPUT_VARIABLE _uid OUTPUT_STRIP_TRAILING_WHITESPACE)
    if(_uid STREQUAL "0")
      execute_process(COMMAND runuser -u postgres -- "${_ctl}" -D "${_dir}/data" -m immediate -w stop)
    else()
      execute_process(COMMAND "${_ctl}" -D "${_dir}/data" -m immediate -w stop)
    endif()
    message("pg_cleanup: stopped the server left in ${_dir}")
  endif()
  if(_dir MATCHES "^/tmp/hoist-pg-[A-Za-z0-9]+$")
    file(REMOVE_RECURSE "${_dir}")
  endif()
  file(REMOVE "${f}")
endforeach()
