#include "access_policy.hpp"

#include <grp.h>
#include <pwd.h>

#include <vector>

namespace cosmicd {

bool in_group(unsigned uid, unsigned gid, const std::string& group) {
  const ::group* entry = ::getgrnam(group.c_str());
  if (entry == nullptr) return false;
  const gid_t wanted = entry->gr_gid;
  if (gid == wanted) return true;
  const ::passwd* user = ::getpwuid(uid);
  if (user == nullptr) return false;
  int count = 64;
  std::vector<gid_t> groups(static_cast<std::size_t>(count));
  if (::getgrouplist(user->pw_name, user->pw_gid, groups.data(), &count) < 0) {
    groups.resize(static_cast<std::size_t>(count));
    if (::getgrouplist(user->pw_name, user->pw_gid, groups.data(), &count) < 0) return false;
  }
  for (int i = 0; i < count; ++i) {
    if (groups[static_cast<std::size_t>(i)] == wanted) return true;
  }
  return false;
}

cosmic::AccessPolicy make_access_policy(const AccessGroups& groups) {
  cosmic::AccessPolicy policy;
  policy.may_modify = [groups](const cosmic::PeerCredentials& peer) {
    return peer.uid == 0 || in_group(peer.uid, peer.gid, groups.admin_group);
  };
  policy.may_read = [groups](const cosmic::PeerCredentials& peer) {
    return peer.uid == 0 || in_group(peer.uid, peer.gid, groups.read_group) ||
           in_group(peer.uid, peer.gid, groups.admin_group);
  };
  const std::string reporters = groups.report_group.empty() ? groups.read_group : groups.report_group;
  policy.may_report = [groups, reporters](const cosmic::PeerCredentials& peer) {
    return peer.uid == 0 || in_group(peer.uid, peer.gid, reporters) || in_group(peer.uid, peer.gid, groups.admin_group);
  };
  return policy;
}

}  // namespace cosmicd
