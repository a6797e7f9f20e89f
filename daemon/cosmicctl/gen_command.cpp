// `cosmicctl gen FILE --component NAME --output DIR`: a buildable C++ skeleton of one component
// on libcosmic-client (gen_skeleton.hpp lists the files). The user's file NAME_logic.cpp is
// written only when it does not exist yet; the rest is regenerated every time.
#include <filesystem>
#include <fstream>
#include <iostream>
#include <memory>

#include "commands.hpp"
#include "cosmic/build_paths.hpp"
#include "cosmic/config_loader.hpp"
#include "gen_skeleton.hpp"

// Where the skeleton's find_package(cosmic_client) looks first: a cosmicctl in its build tree
// (build_paths::cosmicctl_build_dir, daemon/CMakeLists.txt) hints that tree's libcosmic-client
// (build_paths::client_config_dir); an installed one, the library installed beside it
// (PREFIX/bin/cosmicctl -> PREFIX/COSMIC_CLIENT_INSTALL_CONFIG_DIR, /usr/lib/<triplet>/cmake/cosmic_client
// from the package libcosmic-client-dev), never the tree it was built in.
#ifndef COSMIC_CLIENT_INSTALL_CONFIG_DIR
#define COSMIC_CLIENT_INSTALL_CONFIG_DIR "lib/cmake/cosmic_client"
#endif

namespace cosmicctl {
namespace {

struct GenOptions {
  std::string file;
  std::string component;
  std::string output;
};

bool write_file(const std::filesystem::path& path, const std::string& content) {
  std::ofstream out(path, std::ios::trunc);
  out << content;
  out.close();
  if (!out) std::cerr << "cosmicctl: cannot write " << path.string() << "\n";
  return static_cast<bool>(out);
}

std::string component_names(const cosmic::Config& config) {
  std::string out;
  for (const auto& c : config.components) out += (out.empty() ? "" : ", ") + c.name;
  return out.empty() ? "(the file has no components: section)" : out;
}

std::string client_config_dir() {
  std::error_code ec;
  const auto self = std::filesystem::read_symlink("/proc/self/exe", ec);
  if (ec) return "";
  if (std::filesystem::equivalent(self.parent_path(), cosmic::build_paths::cosmicctl_build_dir, ec)) {
    return cosmic::build_paths::client_config_dir;
  }
  return (self.parent_path().parent_path() / COSMIC_CLIENT_INSTALL_CONFIG_DIR).string();
}

int run_gen(const GenOptions& o) {
  const auto loaded = cosmic::load_config_file(o.file);
  if (!loaded.ok()) {
    for (const auto& error : loaded.errors) std::cerr << error.to_string() << "\n";
    return kExitConfigError;
  }
  const cosmic::ComponentSpec* component = nullptr;
  for (const auto& c : loaded.config.components) {
    if (c.name == o.component) component = &c;
  }
  if (!component) {
    std::cerr << "cosmicctl: no component '" << o.component << "' in " << o.file
              << " (one of: " << component_names(loaded.config) << ")\n";
    return kExitUsage;
  }
  if (const cosmic::Result<void> distinct = check_identifiers(loaded.config, *component); !distinct) {
    std::cerr << o.file << ": " << distinct.error().text << "\n";
    return kExitConfigError;
  }
  std::error_code ec;
  std::filesystem::create_directories(o.output, ec);
  if (ec) {
    std::cerr << "cosmicctl: cannot create " << o.output << ": " << ec.message() << "\n";
    return kExitUnavailable;
  }
  const Skeleton skeleton = generate_skeleton(loaded.config, *component, o.file, client_config_dir());
  for (const auto& [name, content] : skeleton.files) {
    const auto path = std::filesystem::path(o.output) / name;
    if (name == skeleton.logic_file && std::filesystem::exists(path)) {
      std::cerr << "kept " << path.string() << " (yours)\n";
      continue;
    }
    if (!write_file(path, content)) return kExitUnavailable;
    std::cerr << "wrote " << path.string() << "\n";
  }
  std::cerr << "build: cmake -S " << o.output << " -B " << o.output << "/build && cmake --build " << o.output
            << "/build\n";
  return kExitOk;
}

}  // namespace

CommandRunner add_gen_command(CLI::App& app, const GlobalOptions&) {
  auto* command = app.add_subcommand("gen", "Generate the C++ skeleton of one component (libcosmic-client)");
  auto o = std::make_shared<GenOptions>();
  command->add_option("FILE", o->file, "Configuration file (YAML) with a components: section")->required();
  command->add_option("--component", o->component, "Name of the component")->required();
  command->add_option("--output", o->output, "Directory of the generated project")->required();
  return [command, o]() -> int {
    if (!command->parsed()) return -1;
    return run_gen(*o);
  };
}

}  // namespace cosmicctl
