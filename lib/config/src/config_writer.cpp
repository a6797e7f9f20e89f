#include <yaml-cpp/yaml.h>

#include <cstdio>

#include "cosmic/config_loader.hpp"
#include "type_loader.hpp"

namespace cosmic {
namespace {
std::string nanos(Nanos value) { return std::to_string(value.count()) + "ns"; }

// The key file's resolved path, never the key.
void write_secoc(YAML::Emitter& out, const ChannelSpec& channel) {
  if (channel.secoc.empty()) return;
  out << YAML::Key << "secoc" << YAML::Value << YAML::BeginMap;
  for (const SecocSpec& spec : channel.secoc) {
    out << YAML::Key << spec.segment << YAML::Value << YAML::BeginMap;
    out << YAML::Key << "key_file" << YAML::Value << spec.key_file;
    out << YAML::Key << "mac_bits" << YAML::Value << spec.mac_bits;
    out << YAML::Key << "freshness_bits" << YAML::Value << spec.freshness_bits;
    if (spec.data_id) out << YAML::Key << "data_id" << YAML::Value << *spec.data_id;
    if (spec.cost) out << YAML::Key << "cost" << YAML::Value << nanos(*spec.cost);
    out << YAML::EndMap;
  }
  out << YAML::EndMap;
}
}  // namespace

std::string channel_to_yaml(const ChannelSpec& channel) {
  YAML::Emitter out;
  out << YAML::Flow << YAML::BeginMap;
  out << YAML::Key << "name" << YAML::Value << channel.name;
  char subject[24];
  std::snprintf(subject, sizeof subject, "0x%016llx", static_cast<unsigned long long>(channel.subject));
  out << YAML::Key << "subject" << YAML::Value << subject;
  out << YAML::Key << "class" << YAML::Value << to_string(channel.cls);
  if (channel.period) out << YAML::Key << "period" << YAML::Value << nanos(*channel.period);
  if (channel.reaction_time) out << YAML::Key << "reaction_time" << YAML::Value << nanos(*channel.reaction_time);
  out << YAML::Key << "omission_degree" << YAML::Value << channel.omission_degree;
  if (channel.temp_validity) out << YAML::Key << "temp_validity" << YAML::Value << nanos(*channel.temp_validity);
  out << YAML::Key << "payload" << YAML::Value << (std::to_string(channel.payload) + "B");
  if (channel.etag) out << YAML::Key << "etag" << YAML::Value << *channel.etag;
  out << YAML::Key << "encoding" << YAML::Value << (channel.lcm_encoding == LcmEncoding::raw ? "raw" : "envelope");
  out << YAML::Key << "publishers" << YAML::Value << channel.publishers;
  out << YAML::Key << "subscribers" << YAML::Value << channel.subscribers;
  if (!channel.native.empty()) {
    out << YAML::Key << "native" << YAML::Value << YAML::BeginMap;
    for (const NativeBinding& binding : channel.native) {
      out << YAML::Key << binding.segment << YAML::Value << YAML::BeginMap;
      if (binding.can) {
        char id[16];
        std::snprintf(id, sizeof id, "0x%X", static_cast<unsigned>(binding.can->can_id));
        out << YAML::Key << "can_id" << YAML::Value << id << YAML::Key << "extended" << YAML::Value
            << binding.can->extended;
      }
      if (binding.lcm_channel) out << YAML::Key << "channel" << YAML::Value << *binding.lcm_channel;
      if (binding.form != NativeForm::source)
        out << YAML::Key << "representation" << YAML::Value << to_string(binding.form);
      if (binding.dds) {
        out << YAML::Key << "topic" << YAML::Value << binding.dds->topic << YAML::Key << "type" << YAML::Value
            << binding.dds->type << YAML::Key << "representation" << YAML::Value
            << to_string(binding.dds->representation);
      }
      out << YAML::EndMap;
    }
    out << YAML::EndMap;
  }
  if (channel.type) out << YAML::Key << "type" << YAML::Value << config_detail::channel_type_to_yaml(*channel.type);
  if (channel.on_range == RangePolicy::saturate) out << YAML::Key << "on_range" << YAML::Value << "saturate";
  write_secoc(out, channel);
  out << YAML::EndMap;
  return out.c_str();
}

}  // namespace cosmic
