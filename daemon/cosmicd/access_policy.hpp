// Who may use the control socket: root and members of the read group may read; root and members
// of the admin group may also bind, unbind and reload; root, members of the admin group and of the
// report group (the read group unless one is named) may send FMU runners' reports (fmu_report).
// Decided from SO_PEERCRED per request.
#pragma once

#include <string>

#include "cosmic/control_protocol.hpp"

namespace cosmicd {

struct AccessGroups {
  std::string read_group = "cosmic";
  std::string admin_group = "cosmic-admin";
  std::string report_group;  // empty: the read group
};

cosmic::AccessPolicy make_access_policy(const AccessGroups& groups);
// True when `uid` (or `gid`, its primary group) belongs to the named group.
bool in_group(unsigned uid, unsigned gid, const std::string& group);

}  // namespace cosmicd
