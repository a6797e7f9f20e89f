// DDS Security on a Fast DDS 2.9 participant (docs/security.md): the properties that load the
// builtin plugins (PKI-DH, Access-Permissions, AES-GCM-GMAC) with a DdsSecuritySpec's files. The
// DDS adapter gives them to every participant of a secure segment; a program that joins such a
// segment outside the adapter (scripts/bench's peers) uses the same ones.
#pragma once

#include <fastdds/dds/domain/qos/DomainParticipantQos.hpp>

#include "cosmic/model.hpp"

namespace cosmic {

// Appends the dds.sec.* properties to `qos` (the caller's; the files as file:// URIs of the spec's
// paths, read by Fast DDS when the participant is created). Called on the thread that builds the QoS.
void add_dds_security(const DdsSecuritySpec& security, eprosima::fastdds::dds::DomainParticipantQos& qos);

}  // namespace cosmic
