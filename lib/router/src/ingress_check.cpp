#include "cosmic/ingress_check.hpp"

namespace cosmic {

const char* to_string(IngressFault fault) {
  switch (fault) {
    case IngressFault::none:
      return "none";
    case IngressFault::negative_age:
      return "negative_age";
    case IngressFault::age_beyond_bound:
      return "age_beyond_bound";
    case IngressFault::foreign_subject:
      return "foreign_subject";
    case IngressFault::own_origin:
      return "own_origin";
    case IngressFault::hop_limit:
      return "hop_limit";
    case IngressFault::oversize:
      return "oversize";
  }
  return "?";
}

DropReason drop_reason(IngressFault fault) {
  switch (fault) {
    case IngressFault::oversize:
      return DropReason::oversize;
    case IngressFault::own_origin:
    case IngressFault::hop_limit:
      return DropReason::duplicate;
    case IngressFault::none:
    case IngressFault::negative_age:
    case IngressFault::age_beyond_bound:
    case IngressFault::foreign_subject:
      break;
  }
  return DropReason::invalid;
}

IngressFault ingress_check(const InboundEvent& event, const ChannelSpec& spec, const GatewayIdentity& self) {
  const EventHeader& h = event.header;
  if (event.payload.size() > spec.payload) return IngressFault::oversize;
  if (h.subject != spec.subject) return IngressFault::foreign_subject;
  // Origin 0 marks a native source; the router gives it this gateway's id on the way out.
  if (h.origin != 0 && h.origin == self.id) return IngressFault::own_origin;
  if (h.hop_count >= kMaxHops) return IngressFault::hop_limit;
  if (h.age_ns < 0) return IngressFault::negative_age;
  if (h.age_ns > kMaxIngressAgeNs) return IngressFault::age_beyond_bound;
  return IngressFault::none;
}

}  // namespace cosmic
