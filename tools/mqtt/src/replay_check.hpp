// replay_check.hpp -- what the bridge would publish now, as a check on
// every record read back from the store-and-forward journal (issue 33: a
// planted journal with valid CRCs was replayed with the bridge's credentials
// to any topic).  Private to tools/mqtt; used by bridge.cpp for MqttLink.
//
// A record passes only if it is one of:
//   JSON mode:  hoist/<shaft>/{cage,health,forecast,estimate,cmd/result} not retained,
//               hoist/<shaft>/alarm/<KIND> retained (KIND [A-Z0-9_]{1,32}),
//               the bridge's own health topic, not retained;
//   Sparkplug:  spBv1.0/<group>/DDATA/<edge>/<device of a shaft>, spBv1.0/<group>/NDATA/<edge>,
//               not retained, with the Sparkplug flag; or the bridge's health (JSON);
// where <shaft> is a shaft the directory binds now.  So never a command
// topic (cmd/ack), never STATE, never $SYS, never another client's tree.
#pragma once

#include <string>

#include "hoist/mqtt/config.hpp"
#include "hoist/mqtt/outbox.hpp"
#include "shaft_directory.hpp"

namespace hoist::mqtt {

/// "" if `m` is a message the bridge would publish now, else why not.
/// `dir` is read only; `health_topic` is the bridge's own health topic.
std::string replayRefusal(const OutMsg& m, const BridgeConfig& cfg, const ShaftDirectory& dir,
                          const std::string& health_topic);

}  // namespace hoist::mqtt
