// hoist/history/record_json.hpp -- a TripRecord as JSON, made from the
// schema's field tables (hoist/history/schema.hpp): the outage queue's file
// body and hoist-trips' JSON output.
//
// {"shaft": "...", "trip": N, <every trip column>, "bins": [{<bin columns>}...]}
// Column names as in the database; booleans as true/false; doubles in
// shortest round-trip form, so recordFromJson(recordToJson(r)) == r.
// recordFromJson checks every value (schema.hpp valueError, recordError) and
// throws std::invalid_argument naming the field.
#pragma once

#include <nlohmann/json.hpp>

#include "hoist/trip_record.hpp"

namespace hoist::history {

nlohmann::json recordToJson(const TripRecord& r);
TripRecord recordFromJson(const nlohmann::json& j);

}  // namespace hoist::history
