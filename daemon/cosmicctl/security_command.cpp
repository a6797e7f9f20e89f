// `cosmicctl security permissions FILE [--sign-with CA_CERT CA_KEY] [--protection KIND]
// [--valid-days N]`: the DDS Security governance and permissions documents of FILE's secure DDS
// segments (cosmic/dds_permissions.hpp), written to the paths the segments name, signed with the
// permissions CA (cosmic/smime_sign.hpp); without the CA, written as plain XML next to them with the
// openssl commands that sign them into place (docs/security.md).
#include <chrono>
#include <ctime>
#include <fstream>
#include <iostream>
#include <memory>
#include <optional>
#include <sstream>
#include <string>
#include <variant>
#include <vector>

#include "commands.hpp"
#include "cosmic/config_loader.hpp"
#include "cosmic/dds_permissions.hpp"
#include "cosmic/dds_security_files.hpp"
#include "cosmic/key_file.hpp"
#include "cosmic/smime_sign.hpp"
#include "document_files.hpp"

namespace cosmicctl {
namespace {

constexpr std::size_t kMaxPemBytes = 1u << 20;  // certificates and keys are small

struct PermissionsArguments {
  std::string file;
  std::vector<std::string> sign_with;  // CA_CERT CA_KEY, or empty
  cosmic::DdsProtection protection = cosmic::DdsProtection::encrypt;
  std::optional<unsigned> valid_days;
};

// A command's failure: what to print and the exit status.
struct Failure {
  std::string message;
  int code = kExitConfigError;
};

cosmic::Result<std::string> read_text(const std::string& path) {
  std::ifstream in(path, std::ios::binary);
  if (!in) return cosmic::Error{"cannot read " + path};
  std::ostringstream text;
  text << in.rdbuf();
  if (text.str().size() > kMaxPemBytes) return cosmic::Error{path + " is larger than a certificate can be"};
  return text.str();
}

// Now and `days` later, as grants write times (UTC).
cosmic::GrantValidity validity_from_now(unsigned days) {
  auto format = [](std::chrono::system_clock::time_point at) {
    const std::time_t t = std::chrono::system_clock::to_time_t(at);
    std::tm parts{};
    gmtime_r(&t, &parts);
    char text[32];
    std::strftime(text, sizeof text, "%Y-%m-%dT%H:%M:%S", &parts);
    return std::string(text);
  };
  const auto now = std::chrono::system_clock::now();
  return {format(now), format(now + std::chrono::hours(24) * days)};
}

// cosmicd's identity on each secure DDS segment: its certificate's subject and validity (or the
// validity --valid-days asks for).
std::variant<std::vector<cosmic::DdsSegmentIdentity>, Failure> identities_of(const cosmic::Config& config,
                                                                             std::optional<unsigned> valid_days) {
  std::vector<cosmic::DdsSegmentIdentity> identities;
  for (const auto& segment : config.segments) {
    if (segment.type != cosmic::SegmentType::dds || !segment.dds.security) continue;
    const std::string& path = segment.dds.security->certificate;
    auto pem = read_text(path);
    if (!pem) return Failure{"segment " + segment.name + ": " + pem.error().text};
    auto facts = cosmic::certificate_facts(pem.value());
    if (!facts) return Failure{"segment " + segment.name + ": certificate " + path + ": " + facts.error().text};
    cosmic::GrantValidity validity{facts.value().not_before, facts.value().not_after};
    if (valid_days) validity = validity_from_now(*valid_days);
    identities.push_back({segment.name, facts.value().subject, validity});
  }
  return identities;
}

// A document to write, and the permissions CAs of the segments that will read it.
struct Target {
  std::string path;                          // where the configuration expects the signed document
  std::string kind;                          // "governance" or "permissions"
  std::string xml;                           // the document
  std::string summary;                       // what it holds, for people
  std::vector<std::string> permissions_cas;  // of the segments that read it
};

std::string separated(const std::vector<std::string>& items, const char* separator) {
  std::string out;
  for (const auto& item : items) out += (out.empty() ? "" : separator) + item;
  return out;
}

std::string grant_summary(const cosmic::DdsGrant& grant) {
  std::string out = "  grant " + grant.name + ": " + grant.subject + ", " + grant.validity.not_before + " to " +
                    grant.validity.not_after + "\n";
  for (const auto& rule : grant.rules) {
    out += "    domain " + std::to_string(rule.domain) + " (" + rule.segment + "): publish " +
           (rule.publish.empty() ? "nothing" : separated(rule.publish, ", ")) + "; subscribe " +
           (rule.subscribe.empty() ? "nothing" : separated(rule.subscribe, ", ")) + "\n";
  }
  return out;
}

std::vector<Target> targets_of(const cosmic::Config& config, const cosmic::DdsAccessDocuments& documents,
                               cosmic::DdsProtection protection) {
  std::vector<Target> targets;
  for (const auto& d : documents.governance) {
    std::vector<std::string> domains;
    for (const auto domain : d.domains) domains.push_back(std::to_string(domain));
    targets.push_back({d.path,
                       "governance",
                       d.xml,
                       "governance " + d.path + ": domain " + separated(domains, ", ") + ", protection " +
                           cosmic::to_string(protection) + "\n",
                       {}});
  }
  for (const auto& d : documents.permissions) {
    std::string summary = "permissions " + d.path + ":\n";
    for (const auto& grant : d.grants) summary += grant_summary(grant);
    targets.push_back({d.path, "permissions", d.xml, summary, {}});
  }
  for (Target& t : targets) {
    for (const auto& segment : config.segments) {
      if (!segment.dds.security) continue;
      const auto& security = *segment.dds.security;
      if ((t.kind == "governance" ? security.governance : security.permissions) == t.path) {
        bool seen = false;
        for (const auto& ca : t.permissions_cas) seen = seen || ca == security.permissions_ca;
        if (!seen) t.permissions_cas.push_back(security.permissions_ca);
      }
    }
  }
  return targets;
}

// A path as a shell word.
std::string shell_word(const std::string& text) {
  const bool plain = !text.empty() && text.find_first_not_of(
                                          "ABCDEFGHIJKLMNOPQRSTUVWXYZabcdefghijklmnopqrstuvwxyz"
                                          "0123456789_/.,:=+-@%") == std::string::npos;
  if (plain) return text;
  std::string out = "'";
  for (const char c : text) out += c == '\'' ? std::string("'\\''") : std::string(1, c);
  return out + "'";
}

// The unsigned document's path: next to the signed one, `.p7s` replaced by `.xml`.
std::string xml_path_of(const std::string& signed_path) {
  const std::string suffix = ".p7s";
  const bool p7s = signed_path.size() > suffix.size() &&
                   signed_path.compare(signed_path.size() - suffix.size(), suffix.size(), suffix) == 0;
  return (p7s ? signed_path.substr(0, signed_path.size() - suffix.size()) : signed_path) + ".xml";
}

// Zeroes a secret's bytes when it goes: the CA's key is in memory only to sign.
struct WipedOnExit {
  std::string& text;
  ~WipedOnExit() {
    volatile char* p = text.data();
    for (std::size_t i = 0; i < text.size(); ++i) p[i] = 0;
  }
};

// Every document signed with the CA, and each checked against the permissions CA of every segment
// that reads it (a CA the segments do not trust would make documents no participant loads).
std::optional<Failure> sign_all(std::vector<Target>& targets, const std::string& ca_path, const std::string& key_path) {
  auto ca = read_text(ca_path);
  if (!ca) return Failure{"--sign-with: " + ca.error().text, kExitUsage};
  auto key = cosmic::read_private_file(key_path, kMaxPemBytes);
  if (!key) return Failure{"--sign-with: CA key: " + key.error().text, kExitUsage};
  const WipedOnExit wipe_key{key.value()};
  for (Target& t : targets) {
    auto signed_text = cosmic::smime_sign_text(t.xml, ca.value(), key.value());
    if (!signed_text) return Failure{"--sign-with: " + signed_text.error().text, kExitUsage};
    for (const auto& permissions_ca : t.permissions_cas) {
      auto trusted = read_text(permissions_ca);
      if (!trusted) return Failure{trusted.error().text};
      if (!cosmic::check_signed_document(trusted.value(), signed_text.value())) {
        return Failure{"--sign-with: " + ca_path + " is not the permissions CA " + permissions_ca +
                           " the configuration names: " + t.path + " would not load (sign with that CA)",
                       kExitUsage};
      }
    }
    t.xml = std::move(signed_text).value();
  }
  return std::nullopt;
}

int run_permissions(const PermissionsArguments& args) {
  cosmic::LoadOptions load_options;
  load_options.security_documents_pending = true;
  const auto loaded = cosmic::load_config_file(args.file, load_options);
  if (!loaded.ok()) {
    for (const auto& error : loaded.errors) std::cerr << error.to_string() << "\n";
    std::cerr << loaded.errors.size() << " error(s) in " << args.file << "\n";
    return kExitConfigError;
  }
  auto identities = identities_of(loaded.config, args.valid_days);
  if (const auto* failure = std::get_if<Failure>(&identities)) {
    std::cerr << "cosmicctl security permissions: " << failure->message << "\n";
    return failure->code;
  }
  const auto documents = cosmic::dds_access_documents(
      loaded.config, std::get<std::vector<cosmic::DdsSegmentIdentity>>(identities), args.protection);
  if (!documents) {
    std::cerr << "cosmicctl security permissions: " << args.file << ": " << documents.error().text << "\n";
    return kExitConfigError;
  }
  for (const auto& note : documents.value().notes) std::cerr << "note: " << note << "\n";
  auto targets = targets_of(loaded.config, documents.value(), args.protection);
  for (std::size_t i = 0; i < targets.size(); ++i) {
    for (std::size_t j = 0; j < i; ++j) {
      if (targets[i].path == targets[j].path) {
        std::cerr << "cosmicctl security permissions: " << targets[i].path
                  << " is named as both governance and permissions; give each document its own file\n";
        return kExitConfigError;
      }
    }
  }
  const bool sign = !args.sign_with.empty();
  if (sign) {
    if (auto failure = sign_all(targets, args.sign_with[0], args.sign_with[1])) {
      std::cerr << "cosmicctl security permissions: " << failure->message << "\n";
      return failure->code;
    }
  }
  std::vector<DocumentFile> files;
  for (const Target& t : targets) files.push_back({sign ? t.path : xml_path_of(t.path), t.xml});
  if (const auto failure = write_documents(files)) {
    std::cerr << "cosmicctl security permissions: " << failure->message << "\n";
    return failure->permission_denied ? kExitNoPermission : kExitRejected;
  }
  if (sign) {
    for (const Target& t : targets) std::cout << t.summary;
    std::cout << "signed by " << args.sign_with[0] << "\n";
    return kExitOk;
  }
  // Unsigned: standard output is a shell script that signs them (its comments say what they hold).
  for (const Target& t : targets) {
    std::istringstream lines(t.summary);
    for (std::string line; std::getline(lines, line);) std::cout << "# " << line << "\n";
  }
  std::cout << "# Sign them with the permissions CA's key (PERMISSIONS_CA_KEY=FILE) into the paths the "
               "configuration names:\n";
  for (const Target& t : targets) {
    std::cout << "openssl smime -sign -text -in " << shell_word(xml_path_of(t.path)) << " -out " << shell_word(t.path)
              << " -signer " << shell_word(t.permissions_cas.front()) << " -inkey \"$PERMISSIONS_CA_KEY\"\n";
  }
  return kExitOk;
}

}  // namespace

CommandRunner add_security_command(CLI::App& app, const GlobalOptions&) {
  auto* security = app.add_subcommand("security", "DDS Security: write a configuration's governance and permissions");
  security->require_subcommand(1);
  auto* command = security->add_subcommand(
      "permissions",
      "Write the governance and permissions documents of FILE's secure DDS segments to the paths they name");
  auto args = std::make_shared<PermissionsArguments>();
  command->add_option("FILE", args->file, "Configuration file (YAML)")->required()->check(CLI::ExistingFile);
  command
      ->add_option("--sign-with", args->sign_with,
                   "Sign with the permissions CA's certificate and key (PEM) and write the signed documents; "
                   "without it, write the XML next to them and print the openssl commands that sign them")
      ->expected(2)
      ->type_name("CA_CERT CA_KEY");
  command
      ->add_option_function<std::string>(
          "--protection",
          [args](const std::string& kind) {
            args->protection = kind == "sign"   ? cosmic::DdsProtection::sign
                               : kind == "none" ? cosmic::DdsProtection::none
                                                : cosmic::DdsProtection::encrypt;
          },
          "What the governance protects: encrypt (default), sign (RTPS messages signed) or none")
      ->check(CLI::IsMember({"encrypt", "sign", "none"}));
  command
      ->add_option("--valid-days", args->valid_days,
                   "Grants valid from now for this many days (default: each segment's certificate's validity)")
      ->check(CLI::Range(1u, 36500u));
  return [command, args]() -> int {
    if (!command->parsed()) return -1;
    return run_permissions(*args);
  };
}

}  // namespace cosmicctl
