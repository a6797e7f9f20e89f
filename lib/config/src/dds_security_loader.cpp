// DDS Security files of a DDS segment (dds_security_loader.hpp).
#include "dds_security_loader.hpp"

#include <filesystem>
#include <functional>
#include <string_view>

#include "cosmic/dds_security_files.hpp"
#include "key_file_loader.hpp"
#include "type_file_loader.hpp"

namespace cosmic::config_detail {
namespace {

constexpr std::size_t kMaxSecurityFileBytes = 1u << 20;  // certificates and XML documents are small

struct SecurityFile {
  const char* key;
  std::string path;  // absolute
  std::string text;
  bool read = false;
};

}  // namespace

std::optional<DdsSecuritySpec> parse_dds_security(YamlReader& reader, const YAML::Node& node, const std::string& path,
                                                  std::vector<std::string>& included, bool documents_pending) {
  if (!reader.check_map(
          node, path,
          {"identity_ca", "certificate", "private_key", "permissions_ca", "governance", "permissions", "cost"}))
    return std::nullopt;
  const std::size_t errors_before = reader.error_count();
  SecurityFile files[] = {{"identity_ca", {}, {}},    {"certificate", {}, {}}, {"private_key", {}, {}},
                          {"permissions_ca", {}, {}}, {"governance", {}, {}},  {"permissions", {}, {}}};
  // Fast DDS takes file:// URIs of absolute paths. Without a file name (a text parsed on its own),
  // relative paths are the working directory's.
  std::error_code failed;
  std::filesystem::path base = reader.file().empty() ? std::filesystem::current_path(failed)
                                                     : std::filesystem::absolute(reader.file(), failed).parent_path();
  if (failed) base = std::filesystem::path("/");
  for (SecurityFile& f : files) {
    const std::string at = key(path, f.key);
    if (!has(node, f.key)) {
      reader.error_at(node, at, std::string("missing key '") + f.key + "'",
                      "a file (PEM certificates and key, S/MIME signed XML documents), relative to this file");
      continue;
    }
    const auto name = reader.string(node[f.key], at);
    if (!name) continue;
    f.path = (base / *name).lexically_normal().string();
    const std::string_view which = f.key;
    if (documents_pending && (which == "governance" || which == "permissions")) continue;
    const bool is_key = which == "private_key";
    const std::string error =
        read_regular_file(f.path, f.text, kMaxSecurityFileBytes, is_key ? refuse_unless_private : nullptr);
    if (!error.empty()) {
      reader.error_at(node[f.key], at, "cannot use " + f.path + ": " + error,
                      is_key ? "a PEM private key only its owner may read (chmod 600)" : "a readable file");
      continue;
    }
    f.read = true;
    included.push_back(f.path);
  }
  auto& [identity_ca, certificate, private_key, permissions_ca, governance, permissions] = files;
  auto report = [&](const SecurityFile& f, const Error& e) {
    reader.error_at(node[f.key], key(path, f.key), f.path + ": " + e.text);
  };
  std::string subject;
  // A CA file that holds no certificate is reported once, at its key: what depends on it is not checked.
  if (identity_ca.read) {
    if (auto ok = check_ca_certificate(identity_ca.text); !ok) {
      report(identity_ca, ok.error());
      identity_ca.read = false;
    }
  }
  if (permissions_ca.read) {
    if (auto ok = check_ca_certificate(permissions_ca.text); !ok) {
      report(permissions_ca, ok.error());
      permissions_ca.read = false;
    }
  }
  if (identity_ca.read && certificate.read) {
    auto checked = check_identity_certificate(identity_ca.text, certificate.text);
    if (checked)
      subject = checked.value();
    else
      report(certificate, checked.error());
  }
  if (private_key.read && certificate.read) {
    if (auto ok = check_private_key(private_key.text, certificate.text); !ok) report(private_key, ok.error());
  }
  for (const SecurityFile* document : {&governance, &permissions}) {
    if (!permissions_ca.read || !document->read) continue;
    if (auto ok = check_signed_document(permissions_ca.text, document->text); !ok) report(*document, ok.error());
  }
  std::uint64_t hash = 0;
  for (SecurityFile& f : files) {
    hash = hash * 1099511628211ull ^ std::hash<std::string>{}(f.text);
    // The key's bytes are not kept here: Fast DDS reads the file itself.
    volatile char* p = f.text.data();
    for (std::size_t i = 0; i < f.text.size(); ++i) p[i] = 0;
  }
  std::optional<Nanos> cost;
  if (has(node, "cost")) cost = reader.duration(node["cost"], key(path, "cost"), true);
  if (reader.error_count() != errors_before) return std::nullopt;
  return DdsSecuritySpec{identity_ca.path,
                         certificate.path,
                         private_key.path,
                         permissions_ca.path,
                         governance.path,
                         permissions.path,
                         subject,
                         hash,
                         cost};
}

}  // namespace cosmic::config_detail
