# check_layers_selftest.cmake -- shows that check_layers.cmake can fail: run
# it on tests/layers/bad_tree (a miniature source tree breaking every rule)
# and with a model that links spdlog; it must exit non-zero and name each
# violation.  cmake -DCHECK=<check_layers.cmake> -DFIXTURE=<bad_tree> -P ...
execute_process(
  COMMAND ${CMAKE_COMMAND} -DROOT=${FIXTURE} "-DMODEL_LINKS=Eigen3::Eigen|spdlog::spdlog" -P ${CHECK}
  RESULT_VARIABLE rc OUTPUT_VARIABLE out ERROR_VARIABLE err)
set(out "${out}${err}")
if(rc EQUAL 0)
  message(FATAL_ERROR "check_layers passed a tree that breaks the rules:\n${out}")
endif()
foreach(expected
    "hoist_model links 'spdlog::spdlog'"
    "service/src/bad.cpp includes \"hoist/study/sweep.hpp\", a header of tools/"
    "io/src/bad.cpp includes \"../../tools/replay/timing_report.hpp\" \\(a path into tools/\\)"
    "model/src/bad.cpp includes \"hoist/io/config.hpp\", which is not a model header"
    "service/app/bad.cpp includes \"../../tools/mqtt/include/hoist/mqtt/command.hpp\" \\(a path into tools/\\)"
    "tools/ack/main.cpp includes \"hoist/service/alarms.hpp\", a header of service/"
    "tools/mqtt/src/bad.cpp includes \"../../../service/app/daemon.hpp\" \\(a path into service/\\)"
    "tools/mqtt/src/bad.cpp includes \"shaft_twin.hpp\", a header of service/"
    "tools/dash/main.cpp includes \"hoist/service/twin/twin_core.hpp\", a header of service/"
    "msgs/udpm/bad.cpp includes \"hoist/service/alarms.hpp\", a header of service/"
    "msgs/udpm/bad.cpp includes \"../../tools/replay/timing_report.hpp\" \\(a path into tools/\\)"
    "rt/src/bad.cpp includes \"shaft_twin.hpp\", a header of service/"
    "tools/monitor/main.cpp includes \"hoist/bus/udpm_receiver.hpp\": a tool takes its receive path from hoist/bus/subscriber.hpp"
    "service/core/src/bad.cpp includes \"hoist/service/twin/twin_core.hpp\" of service/twin \\(service/core may include service/{core}\\)"
    "service/core/src/bad.cpp includes \"shaft_twin.hpp\", a header of service/app"
    "service/core/src/bad.cpp includes \"hoist/bus/channels.hpp\": service/core knows nothing of LCM"
    "service/core/src/bad.cpp includes \"hoist/cage_state_t.hpp\": service/core knows nothing of LCM"
    "service/twin/src/bad.cpp includes \"hoist/service/lcm/messages.hpp\" of service/lcm \\(service/twin may include service/{core, twin}\\)"
    "service/twin/src/bad.cpp includes \"lcm/lcm-cpp.hpp\": service/twin knows nothing of LCM"
    "service/cfg/include/hoist/service/config_file.hpp: a public header of service/cfg belongs in include/hoist/service/cfg/"
    "service/twin/src/bad.cpp opens \"namespace hoist::svc\": service/twin's namespace is hoist::service::twin")
  if(NOT out MATCHES "LAYER VIOLATION: ${expected}")
    message(FATAL_ERROR "check_layers did not report: ${expected}\noutput:\n${out}")
  endif()
endforeach()
foreach(ok "hoist/params.hpp\"," "<string>" "<cstdint>" "hoist/contract/alarm_command.hpp" "hoist/mqtt/command.hpp\","
           "\"udpm_sender.hpp\"" "hoist/bus/subscriber.hpp\"" "hoist/service/core/config.hpp\""
           "twin/src/bad.cpp includes \"hoist/service/twin/twin_core.hpp\"" "core/src/bad.cpp opens")
  string(FIND "${out}" "${ok}" pos)
  if(NOT pos EQUAL -1)
    message(FATAL_ERROR "check_layers flagged an allowed include (${ok}):\n${out}")
  endif()
endforeach()
message("check_layers_selftest: OK (21 violations reported, allowed includes not flagged)")
