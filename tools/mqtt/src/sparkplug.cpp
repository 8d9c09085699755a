// The Sparkplug B payload on the wire: see hoist/mqtt/sparkplug.hpp.
#include "hoist/mqtt/sparkplug.hpp"

#include <pb_decode.h>
#include <pb_encode.h>

#include <cstring>
#include <memory>
#include <stdexcept>

#include "hoist/mqtt/sparkplug_node.hpp"
#include "sparkplug_b.pb.h"

namespace hoist::mqtt::sparkplug {

namespace {

using PbPayload = hoist_sparkplug_Payload;
// nanopb's 16-bit field offsets: the decoded payload (max_count metrics of
// sparkplug_b.options) must stay below 64 kB.
static_assert(sizeof(PbPayload) < 65536, "sparkplug_b.options: too many metrics for nanopb's 16-bit offsets");
using PbMetric = hoist_sparkplug_Payload_Metric;

void copyString(char* dst, std::size_t cap, const std::string& s, const char* what) {
  if (s.size() + 1 > cap) throw std::length_error(std::string("Sparkplug ") + what + " too long: " + s);
  std::memcpy(dst, s.data(), s.size());
  dst[s.size()] = '\0';
}

void toPb(const Metric& m, PbMetric& out) {
  out = hoist_sparkplug_Payload_Metric_init_zero;
  if (!m.name.empty()) {
    out.has_name = true;
    copyString(out.name, sizeof out.name, m.name, "metric name");
  }
  out.has_alias = m.has_alias;
  out.alias = m.alias;
  if (m.timestamp_ms) {
    out.has_timestamp = true;
    out.timestamp = m.timestamp_ms;
  }
  out.has_datatype = m.has_type;
  out.datatype = static_cast<std::uint32_t>(m.type);
  if (m.is_historical) {
    out.has_is_historical = true;
    out.is_historical = true;
  }
  if (!m.units.empty()) {
    out.has_properties = true;
    out.properties.keys_count = 1;
    copyString(out.properties.keys[0], sizeof out.properties.keys[0], "engUnit", "property name");
    out.properties.values_count = 1;
    auto& v = out.properties.values[0];
    v.has_type = true;
    v.type = static_cast<std::uint32_t>(DataType::String);
    v.which_value = hoist_sparkplug_Payload_PropertyValue_string_value_tag;
    copyString(v.value.string_value, sizeof v.value.string_value, m.units, "unit");
  }
  if (m.value.is_null) {
    out.has_is_null = true;
    out.is_null = true;
    return;
  }
  switch (m.type) {
    case DataType::Int8:
    case DataType::Int16:
    case DataType::Int32:
    case DataType::UInt8:
    case DataType::UInt16:
    case DataType::UInt32:
      // Sparkplug: signed values in uint32 as their two's complement.
      out.which_value = hoist_sparkplug_Payload_Metric_int_value_tag;
      out.value.int_value = static_cast<std::uint32_t>(static_cast<std::int32_t>(m.value.i));
      break;
    case DataType::Int64:
    case DataType::UInt64:
    case DataType::DateTime:
      out.which_value = hoist_sparkplug_Payload_Metric_long_value_tag;
      out.value.long_value = static_cast<std::uint64_t>(m.value.i);
      break;
    case DataType::Float:
      out.which_value = hoist_sparkplug_Payload_Metric_float_value_tag;
      out.value.float_value = static_cast<float>(m.value.d);
      break;
    case DataType::Double:
      out.which_value = hoist_sparkplug_Payload_Metric_double_value_tag;
      out.value.double_value = m.value.d;
      break;
    case DataType::Boolean:
      out.which_value = hoist_sparkplug_Payload_Metric_boolean_value_tag;
      out.value.boolean_value = m.value.b;
      break;
    case DataType::String:
    case DataType::Text:
      out.which_value = hoist_sparkplug_Payload_Metric_string_value_tag;
      copyString(out.value.string_value, sizeof out.value.string_value, m.value.s, "string value");
      break;
  }
}

Metric fromPb(const PbMetric& in) {
  Metric m;
  if (in.has_name) m.name = in.name;
  m.has_alias = in.has_alias;
  m.alias = in.alias;
  m.timestamp_ms = in.has_timestamp ? in.timestamp : 0;
  m.has_type = in.has_datatype;
  m.type = static_cast<DataType>(in.datatype);
  m.is_historical = in.has_is_historical && in.is_historical;
  if (in.has_properties)
    for (pb_size_t k = 0; k < in.properties.keys_count && k < in.properties.values_count; ++k)
      if (std::strcmp(in.properties.keys[k], "engUnit") == 0 &&
          in.properties.values[k].which_value == hoist_sparkplug_Payload_PropertyValue_string_value_tag)
        m.units = in.properties.values[k].value.string_value;
  m.value.is_null = true;
  if (in.has_is_null && in.is_null) return m;
  switch (in.which_value) {
    case hoist_sparkplug_Payload_Metric_int_value_tag:
      m.value.is_null = false;
      m.value.i = (m.type == DataType::Int8 || m.type == DataType::Int16 || m.type == DataType::Int32)
                      ? static_cast<std::int32_t>(in.value.int_value)
                      : static_cast<std::int64_t>(in.value.int_value);
      m.value.d = static_cast<double>(m.value.i);
      break;
    case hoist_sparkplug_Payload_Metric_long_value_tag:
      m.value.is_null = false;
      m.value.i = static_cast<std::int64_t>(in.value.long_value);
      m.value.d = static_cast<double>(m.value.i);
      break;
    case hoist_sparkplug_Payload_Metric_float_value_tag:
      m.value.is_null = false;
      m.value.d = in.value.float_value;
      break;
    case hoist_sparkplug_Payload_Metric_double_value_tag:
      m.value.is_null = false;
      m.value.d = in.value.double_value;
      break;
    case hoist_sparkplug_Payload_Metric_boolean_value_tag:
      m.value.is_null = false;
      m.value.b = in.value.boolean_value;
      break;
    case hoist_sparkplug_Payload_Metric_string_value_tag:
      m.value.is_null = false;
      m.value.s = in.value.string_value;
      break;
    default:
      break;
  }
  return m;
}

std::string encodePb(const PbPayload& pb) {
  std::size_t size = 0;
  if (!pb_get_encoded_size(&size, hoist_sparkplug_Payload_fields, &pb))
    throw std::length_error("Sparkplug payload: cannot size it");
  std::string out(size, '\0');
  pb_ostream_t os = pb_ostream_from_buffer(reinterpret_cast<pb_byte_t*>(out.data()), out.size());
  if (!pb_encode(&os, hoist_sparkplug_Payload_fields, &pb))
    throw std::length_error(std::string("Sparkplug payload: ") + PB_GET_ERROR(&os));
  out.resize(os.bytes_written);
  return out;
}

/// nullptr with why if it does not decode.
std::unique_ptr<PbPayload> decodePb(const void* data, std::size_t size, std::string& why) {
  auto pb = std::make_unique<PbPayload>();
  *pb = hoist_sparkplug_Payload_init_zero;
  pb_istream_t is = pb_istream_from_buffer(static_cast<const pb_byte_t*>(data), size);
  if (!pb_decode(&is, hoist_sparkplug_Payload_fields, pb.get())) {
    why = std::string("not a Sparkplug B payload: ") + PB_GET_ERROR(&is);
    return nullptr;
  }
  return pb;
}

}  // namespace

bool available() { return true; }

std::string encode(const Payload& p) {
  if (p.metrics.size() > sizeof(PbPayload::metrics) / sizeof(PbPayload::metrics[0]))
    throw std::length_error("Sparkplug payload: too many metrics");
  auto pb = std::make_unique<PbPayload>();
  *pb = hoist_sparkplug_Payload_init_zero;
  pb->has_timestamp = p.timestamp_ms != 0;
  pb->timestamp = p.timestamp_ms;
  pb->has_seq = p.has_seq;
  pb->seq = p.seq;
  pb->metrics_count = static_cast<pb_size_t>(p.metrics.size());
  for (std::size_t i = 0; i < p.metrics.size(); ++i) toPb(p.metrics[i], pb->metrics[i]);
  return encodePb(*pb);
}

std::optional<Payload> decode(const void* data, std::size_t size, std::size_t max_bytes, std::string& why) {
  if (size > max_bytes) {
    why = "oversized: " + std::to_string(size) + " bytes > " + std::to_string(max_bytes);
    return std::nullopt;
  }
  if (!data && size) {
    why = "no data";
    return std::nullopt;
  }
  auto pb = decodePb(data, size, why);
  if (!pb) return std::nullopt;
  Payload p;
  p.timestamp_ms = pb->has_timestamp ? pb->timestamp : 0;
  p.has_seq = pb->has_seq;
  p.seq = pb->seq;
  for (pb_size_t i = 0; i < pb->metrics_count; ++i) p.metrics.push_back(fromPb(pb->metrics[i]));
  return p;
}

std::string stamp(std::string_view payload, std::uint8_t seq, bool historical) {
  std::string why;
  auto pb = decodePb(payload.data(), payload.size(), why);
  if (!pb) return std::string(payload);
  pb->has_seq = true;
  pb->seq = seq;
  if (historical)
    for (pb_size_t i = 0; i < pb->metrics_count; ++i) {
      pb->metrics[i].has_is_historical = true;
      pb->metrics[i].is_historical = true;
    }
  return encodePb(*pb);
}

}  // namespace hoist::mqtt::sparkplug
