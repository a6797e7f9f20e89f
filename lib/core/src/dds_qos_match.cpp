#include "cosmic/dds_qos_match.hpp"

#include <fnmatch.h>

#include <algorithm>
#include <array>

#include "cosmic/units.hpp"

namespace cosmic {
namespace {

using std::chrono::nanoseconds;

const char* kind_text(DdsReliabilityKind k) { return k == DdsReliabilityKind::reliable ? "RELIABLE" : "BEST_EFFORT"; }

const char* kind_text(DdsDurabilityKind k) {
  static constexpr std::array<const char*, 4> kText = {"VOLATILE", "TRANSIENT_LOCAL", "TRANSIENT", "PERSISTENT"};
  return kText[static_cast<std::size_t>(k)];
}

const char* kind_text(DdsLivelinessKind k) {
  static constexpr std::array<const char*, 3> kText = {"AUTOMATIC", "MANUAL_BY_PARTICIPANT", "MANUAL_BY_TOPIC"};
  return kText[static_cast<std::size_t>(k)];
}

const char* kind_text(DdsOwnershipKind k) { return k == DdsOwnershipKind::exclusive ? "EXCLUSIVE" : "SHARED"; }

const char* kind_text(DdsDestinationOrderKind k) {
  return k == DdsDestinationOrderKind::by_source_timestamp ? "BY_SOURCE_TIMESTAMP" : "BY_RECEPTION_TIMESTAMP";
}

const char* kind_text(DdsPresentationScope k) {
  static constexpr std::array<const char*, 3> kText = {"INSTANCE", "TOPIC", "GROUP"};
  return kText[static_cast<std::size_t>(k)];
}

const char* kind_text(DdsTypeExtensibility k) {
  static constexpr std::array<const char*, 4> kText = {"of unknown extensibility", "final", "appendable", "mutable"};
  return kText[static_cast<std::size_t>(k)];
}

std::string duration_text(const std::optional<nanoseconds>& d) { return d ? format_duration(*d) : "infinite"; }

// Durations where nullopt is infinite: a > b.
bool longer(const std::optional<nanoseconds>& a, const std::optional<nanoseconds>& b) {
  if (!b) return false;
  return !a || *a > *b;
}

std::string presentation_text(const DdsEndpointQos& e) {
  std::string out = kind_text(e.presentation);
  if (e.coherent_access) out += "+coherent";
  if (e.ordered_access) out += "+ordered";
  return out;
}

std::string partitions_text(const std::vector<std::string>& partitions) {
  if (partitions.empty()) return "the default partition";
  std::string out;
  for (const auto& p : partitions) out += (out.empty() ? "'" : ", '") + p + "'";
  return out;
}

// DDS 1.4 section 2.2.3.13: two endpoints share a partition when a name of one matches a name of
// the other, either of which may be a wildcard expression (fnmatch syntax). No partition is "".
bool partitions_meet(const std::vector<std::string>& a, const std::vector<std::string>& b) {
  static const std::vector<std::string> kDefault{""};
  const auto& left = a.empty() ? kDefault : a;
  const auto& right = b.empty() ? kDefault : b;
  for (const auto& x : left) {
    for (const auto& y : right) {
      if (x == y || fnmatch(x.c_str(), y.c_str(), 0) == 0 || fnmatch(y.c_str(), x.c_str(), 0) == 0) return true;
    }
  }
  return false;
}

DdsDataRepresentationId offered_representation(const DdsEndpointQos& writer) {
  return writer.representations.empty() ? DdsDataRepresentationId::xcdr1 : writer.representations.front();
}

std::vector<DdsDataRepresentationId> accepted_representations(const DdsEndpointQos& reader) {
  return reader.representations.empty() ? std::vector{DdsDataRepresentationId::xcdr1} : reader.representations;
}

std::string representations_text(const std::vector<DdsDataRepresentationId>& ids) {
  std::string out;
  for (auto id : ids) out += std::string(out.empty() ? "" : " or ") + to_string(id);
  return ids.size() == 1 ? out + " only" : out;
}

// Words the reasons from our side: the remote endpoint "offers"/"requests" a value, ours
// ("this writer offers" / "this reader requests") the other.
class Wording {
 public:
  Wording(DdsLocalRole role, std::vector<DdsMatchConflict>& out)
      : local_is_writer_(role == DdsLocalRole::writer), out_(out) {}

  // `what` of the writer and of the reader, with why the pair fails.
  void add(DdsMatchPolicy policy, const std::string& what, const std::string& writer_value,
           const std::string& reader_value, const std::string& rule) {
    const std::string& remote_value = local_is_writer_ ? reader_value : writer_value;
    const std::string& local_value = local_is_writer_ ? writer_value : reader_value;
    out_.push_back({policy, std::string(local_is_writer_ ? "requests " : "offers ") + what + " " + remote_value + ", " +
                                (local_is_writer_ ? "this writer offers " : "this reader requests ") + local_value +
                                " (" + rule + ")"});
  }
  // A property both sides have (type name, keys): "its X is A, ours is B".
  void differ(DdsMatchPolicy policy, const std::string& what, const std::string& remote_value,
              const std::string& local_value, const std::string& rule) {
    out_.push_back({policy, "its " + what + " is " + remote_value + ", this " +
                                (local_is_writer_ ? "writer" : "reader") + "'s is " + local_value + " (" + rule + ")"});
  }
  bool local_is_writer() const { return local_is_writer_; }

 private:
  bool local_is_writer_;
  std::vector<DdsMatchConflict>& out_;
};

void check_type(const DdsEndpointQos& local, const DdsEndpointQos& remote, Wording& say) {
  if (local.keyed != remote.keyed) {
    say.differ(DdsMatchPolicy::topic_kind, "topic", remote.keyed ? "keyed" : "keyless",
               local.keyed ? "keyed" : "keyless", "keyed and keyless endpoints never match");
  }
  if (local.type_name != remote.type_name) {
    say.differ(DdsMatchPolicy::type_name, "type", "'" + remote.type_name + "'", "'" + local.type_name + "'",
               "without type information on both sides DDS matches by type name");
  }
  if (local.extensibility != DdsTypeExtensibility::unknown && remote.extensibility != DdsTypeExtensibility::unknown &&
      local.extensibility != remote.extensibility) {
    say.differ(DdsMatchPolicy::type_extensibility, "type's extensibility", kind_text(remote.extensibility),
               kind_text(local.extensibility),
               "XTypes 1.3 7.6.3.4: types of different extensibility are not assignable");
  }
}

void check_representation(const DdsEndpointQos& writer, const DdsEndpointQos& reader, const DdsEndpointQos& local,
                          Wording& say) {
  const DdsDataRepresentationId offered = offered_representation(writer);
  const auto accepted = accepted_representations(reader);
  if (std::find(accepted.begin(), accepted.end(), offered) != accepted.end()) return;
  std::string rule = "XTypes 1.3 7.6.3.1.1: a reader takes only the representations it lists";
  // A far side that speaks XCDR2 only usually does because its type is appendable or mutable
  // (Cyclone DDS allows only XCDR2 for those); ours is final, the likely root cause.
  const auto& remote_ids = say.local_is_writer() ? accepted : std::vector{offered};
  const bool remote_xcdr2_only = remote_ids.size() == 1 && remote_ids.front() == DdsDataRepresentationId::xcdr2;
  if (say.local_is_writer() && !local.unannounced.empty()) {
    rule += "; cosmicd's writer writes " + representations_text(local.unannounced) +
            ", but its DDS library (Fast DDS before 2.13, eProsima/Fast-DDS#3935) does not announce it, so "
            "peers take it for XCDR1: a reader that also accepts XCDR1 matches and gets the samples";
  } else if (remote_xcdr2_only && local.extensibility == DdsTypeExtensibility::final_kind) {
    rule += "; XCDR2 only suggests its type is appendable or mutable, this one is final";
  }
  say.add(DdsMatchPolicy::data_representation, "data representation", to_string(offered),
          representations_text(accepted), rule);
}

void check_qos(const DdsEndpointQos& w, const DdsEndpointQos& r, Wording& say) {
  if (w.reliability < r.reliability) {
    say.add(DdsMatchPolicy::reliability, "reliability", kind_text(w.reliability), kind_text(r.reliability),
            "offered must be at least as reliable as requested");
  }
  if (w.durability < r.durability) {
    say.add(DdsMatchPolicy::durability, "durability", kind_text(w.durability), kind_text(r.durability),
            "offered must be at least as durable as requested");
  }
  if (longer(w.deadline, r.deadline)) {
    say.add(DdsMatchPolicy::deadline, "deadline", duration_text(w.deadline), duration_text(r.deadline),
            "offered period must be <= requested");
  }
  if (w.latency_budget > r.latency_budget) {
    say.add(DdsMatchPolicy::latency_budget, "latency budget", format_duration(w.latency_budget),
            format_duration(r.latency_budget), "offered must be <= requested");
  }
  if (w.liveliness < r.liveliness || longer(w.liveliness_lease, r.liveliness_lease)) {
    say.add(DdsMatchPolicy::liveliness, "liveliness",
            std::string(kind_text(w.liveliness)) + " lease " + duration_text(w.liveliness_lease),
            std::string(kind_text(r.liveliness)) + " lease " + duration_text(r.liveliness_lease),
            "offered kind must be >= requested, offered lease <= requested");
  }
  if (w.ownership != r.ownership) {
    say.add(DdsMatchPolicy::ownership, "ownership", kind_text(w.ownership), kind_text(r.ownership),
            "kinds must be equal");
  }
  if (w.destination_order < r.destination_order) {
    say.add(DdsMatchPolicy::destination_order, "destination order", kind_text(w.destination_order),
            kind_text(r.destination_order), "offered kind must be >= requested");
  }
  if (w.presentation < r.presentation || (r.coherent_access && !w.coherent_access) ||
      (r.ordered_access && !w.ordered_access)) {
    say.add(DdsMatchPolicy::presentation, "presentation", presentation_text(w), presentation_text(r),
            "offered access scope must be >= requested, and coherent/ordered access offered where requested");
  }
  if (!partitions_meet(w.partitions, r.partitions)) {
    say.add(DdsMatchPolicy::partition, "partitions", partitions_text(w.partitions), partitions_text(r.partitions),
            "they must share a partition");
  }
}

}  // namespace

const char* to_string(DdsMatchPolicy policy) {
  static constexpr std::array<const char*, kDdsMatchPolicyCount> kText = {
      "topic_kind",        "type_name",    "type_extensibility", "data_representation", "reliability",
      "durability",        "deadline",     "latency_budget",     "liveliness",          "ownership",
      "destination_order", "presentation", "partition"};
  return kText[static_cast<std::size_t>(policy)];
}

const char* to_string(DdsDataRepresentationId id) {
  switch (id) {
    case DdsDataRepresentationId::xcdr1:
      return "XCDR1";
    case DdsDataRepresentationId::xml:
      return "XML";
    case DdsDataRepresentationId::xcdr2:
      return "XCDR2";
  }
  return "?";
}

std::vector<DdsMatchConflict> dds_match_conflicts(const DdsEndpointQos& local, const DdsEndpointQos& remote,
                                                  DdsLocalRole local_role) {
  std::vector<DdsMatchConflict> out;
  Wording say(local_role, out);
  const DdsEndpointQos& writer = local_role == DdsLocalRole::writer ? local : remote;
  const DdsEndpointQos& reader = local_role == DdsLocalRole::writer ? remote : local;
  check_type(local, remote, say);
  check_representation(writer, reader, local, say);
  check_qos(writer, reader, say);
  return out;
}

}  // namespace cosmic
